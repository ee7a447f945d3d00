"""Convolutions of mirror-symmetric fields on their irreducible block: the DCT-I and the
"even" transform per mirrored axis, :class:`MirrorConvolver` and the kernel's spectrum
:func:`mirror_spectrum`.  The transforms are the seam's (:mod:`tengsim.backend.fft`).
"""
from __future__ import annotations

import threading

import numpy as np

from tengsim.backend import fast_len
from tengsim.backend import fft as _bf
from tengsim.backend import threads as _threads
from tengsim.backend import workers as _workers
from tengsim.kernels.convolve import _IntoConvolver, _use_direct


# --- mirror-symmetric fields: convolutions on the irreducible block ----------------------------------
# A field even about the centre pixel of an axis is held as its block x_0 … x_c (x_0 on the mirror
# line).  Per axis, one of four transforms (``modes``):
#   "dct1": free (zero-padded) axis, mirrored.  The even extension of the block, zero-padded to
#           M + 1 ≥ 2c + 1 values, has period 2M; its DFT is the (unnormalised) DCT-I of length M + 1.
#           A linear convolution of the even field with an even kernel is the period-2M circular one
#           as long as the kernel's offsets |i − j| ≤ 2c ≤ M do not wrap: no aliasing.  The inverse
#           DCT-I is the DCT-I / 2M (folded into the spectrum).  pocketfft's DCT-I is an rfft of length
#           2M; with M = 2h and h > c (the input is zero beyond c, the output is read up to c only)
#           it splits into half-length transforms (0.73 of the time of one line at h = 192; the
#           whole convolution 1.11–1.18× faster for h ≥ 54, slower below ~40: ``SPLIT_MIN``):
#             forward  Y[0::2] = DCT-I_{h+1}(x[:h+1]),   Y[1::2] = DCT-III_h(x[:h])
#             inverse  w[:h]   = DCT-I_{h+1}(Y[0::2])[:h] + DCT-II_h(Y[1::2])
#           (pair n with M − n in the DCT-I sum); the direct path keeps the spectrum in this split
#           order, [even k | odd k], along each such axis.
#   "even": periodic axis of odd period n = 2c + 1, mirrored.  The DFT of an even real sequence is
#           real and even, P_k = x_0 + 2 Σ_j x_j cos(2πjk/n), k = 0 … c (a DCT-V, which pocketfft does
#           not have): computed by an FFT of the unfolded sequence, two lines per complex FFT, and its
#           inverse is the same map / n (folded into the spectrum).
#   "pad":  free axis, not mirrored: rfft zero-padded to ``length``, cropped back (as PaddedConvolver).
#   "periodic": periodic axis, not mirrored: rfft of length n.
# The real transforms (the mirrored axes) run first, on the block only: a mirrored axis transforms
# only the block's lines (about half of the full grid's), and the spectrum is real.
MIRROR_MODES = ("dct1", "even", "pad", "periodic")


def mirror_dct1_len(m: int) -> int:
    """The DCT-I length L = 2h + 1 for a block of ``m`` = c + 1 values: h >= m FFT-friendly, so that
    M = 2h >= 2c + 2 (no aliasing, and the split transforms of :class:`MirrorConvolver` apply)."""
    return 2 * fast_len(m) + 1


def _split(a, k):
    """Along axis k: [a[0::2] | a[1::2]] (the direct path's order of a DCT-I spectrum)."""
    ev, od = (a[0::2], a[1::2]) if k == 0 else (a[:, 0::2], a[:, 1::2])
    return np.concatenate([ev, od], axis=k)


def _unsplit(a, k):
    h = (a.shape[k] - 1) // 2
    out = np.empty_like(a)
    if k == 0:
        out[0::2], out[1::2] = a[: h + 1], a[h + 1:]
    else:
        out[:, 0::2], out[:, 1::2] = a[:, : h + 1], a[:, h + 1:]
    return out


def _ix(k, s):
    """Index with slice ``s`` on axis k (2-D)."""
    return (s, slice(None)) if k == 0 else (slice(None), s)


def _unfold0(a, axis):
    """[x_0, …, x_c, x_c, …, x_1] along ``axis``: the even sequence with its origin at index 0."""
    tail = np.flip(np.take(a, np.arange(1, a.shape[axis]), axis=axis), axis=axis)
    return np.concatenate([a, tail], axis=axis)


def _crop(a, axis, n):
    return a[:n] if axis == 0 else a[:, :n]


class MirrorConvolver(_IntoConvolver):
    """w = K p on the irreducible block of a mirror-symmetric field (see the modes above).

    ``shape``: the block (m0, m1); ``modes``: per axis, one of :data:`MIRROR_MODES` (at least one axis
    "dct1" or "even"); ``lengths``: per axis, the DCT-I length L ("dct1"), the full period n = 2m − 1
    ("even"), the padded length ("pad"), the period ("periodic"); ``spectrum``: real, of the transformed
    shape (L, m, length // 2 + 1 per mode), the inverse transforms' normalisation folded in.
    On scipy's pocketfft binding with per-thread buffers where possible (checked against the public
    ``scipy.fft`` once, as the other convolvers), else on the public functions.
    """

    #: the split DCT-I pays off from this half-length h on (CPU time, 2-axis: 0.77× at h = 20, 0.96× at
    #: 40, 1.11× at 54, 1.14–1.18× at 72–200; one axis 1.0–1.07×); below it its extra calls cost more
    SPLIT_MIN = 50

    def __init__(self, shape, modes, lengths, spectrum, split=None):
        self.shape, self.modes, self.lengths = tuple(shape), tuple(modes), tuple(int(n) for n in lengths)
        if any(m not in MIRROR_MODES for m in self.modes) or not any(m in ("dct1", "even") for m in self.modes):
            raise ValueError(f"bad mirror modes {self.modes!r}")
        spectrum = np.asarray(spectrum, dtype=float)
        dct = [k for k, m in enumerate(self.modes) if m == "dct1"]
        for k in dct:
            if self.lengths[k] % 2 == 0 or (self.lengths[k] - 1) // 2 < self.shape[k]:
                raise ValueError(f"DCT-I length {self.lengths[k]} must be 2h + 1 with h >= {self.shape[k]}")
        if split is None:
            split = bool(dct) and min(self.lengths[k] for k in dct) // 2 >= self.SPLIT_MIN
        self.split = bool(split)
        if self.split:
            for k in dct:
                spectrum = _split(spectrum, k)
        self.spectrum = np.ascontiguousarray(spectrum)  # DCT-I axes in split order if self.split
        self.real_axes = [k for k in (1, 0) if self.modes[k] in ("dct1", "even")]  # forward order
        self.cplx = next((k for k in (0, 1) if self.modes[k] in ("pad", "periodic")), None)
        full = tuple(self.lengths[k] if self.modes[k] != "dct1" else 2 * (self.lengths[k] - 1) for k in (0, 1))
        # threads by the size of one call's transform: the whole padded field for the DCT-I paths, one
        # chunk of lines for the "even" ones (1029²: 65 × 1029 values, 1 thread; 4097²: 257 × 4097, all)
        self.threads = _threads(full if "even" not in self.modes else (self._lines, max(self.lengths)))
        self._tls = threading.local()
        self._direct = _use_direct(self, self.shape)

    # the public path: plain scipy.fft calls, one axis at a time
    def _real_public(self, a, k, forward):
        w = _workers(a.shape)
        if self.modes[k] == "dct1":
            b = _bf.scipy_dct(a, type=1, n=self.lengths[k] if forward else None, axis=k, workers=w)
            return b if forward else _crop(b, k, self.shape[k])
        return _bf.rfft(_unfold0(a, k), axis=k, workers=w).real

    def _apply_public(self, p):
        a = np.asarray(p, dtype=float)
        for k in self.real_axes:
            a = self._real_public(a, k, True)
        j = self.cplx
        if j is not None:
            a = _bf.rfft(a, n=self.lengths[j], axis=j, workers=_workers(a.shape))
        spec = self.spectrum
        for k, m in enumerate(self.modes):
            if m == "dct1" and self.split:
                spec = _unsplit(spec, k)
        a = a * spec
        if j is not None:  # unnormalised, as the direct path: 1/n is in the spectrum
            a = _bf.irfft(a, n=self.lengths[j], axis=j, norm="forward", workers=_workers(a.shape))
            a = _crop(a, j, self.shape[j])
        for k in reversed(self.real_axes):
            a = self._real_public(a, k, False)
        return np.ascontiguousarray(a)

    # the direct path
    def _buffers(self):
        b = getattr(self._tls, "b", None)
        if b is None:
            b = self._tls.b = self._make_buffers()
        return b

    def _make_buffers(self):
        m0, m1 = self.shape
        L0, L1 = self.lengths
        if self.modes == ("dct1", "dct1") and not self.split:
            return (np.zeros((L0, L1)),)
        if self.modes == ("dct1", "dct1"):
            h0, h1 = L0 // 2, L1 // 2
            return np.zeros((m0, h1 + 1)), np.zeros((h0 + 1, L1)), np.empty((L0, L1))
        if self.cplx is not None:
            j, k = self.cplx, 1 - self.cplx
            if self.modes[k] == "dct1" and not self.split:
                cs = [L0, L1]
                cs[j] = self.lengths[j] // 2 + 1
                return np.zeros((L0, L1)), np.empty(tuple(cs), complex)
            if self.modes[k] == "dct1":
                zs = [0, 0]  # the block zero-padded to h + 1 along k
                zs[k], zs[j] = self.lengths[k] // 2 + 1, self.shape[j]
                rs = (L0, L1)  # real work array: DCT-I length along k, transform length along j
                cs = list(rs)
                cs[j] = self.lengths[j] // 2 + 1
                return np.zeros(tuple(zs)), np.zeros(rs), np.empty(tuple(cs), complex)
        # "even" axes: lines transformed in chunks of ``_lines`` (flat buffers reshaped per chunk)
        nmax = max(self.lengths[k] for k in (0, 1))
        ch = self._lines
        hj = self.lengths[self.cplx] // 2 + 1 if self.cplx is not None else 0
        return np.empty((ch + 1) // 2 * nmax, complex), np.empty(ch * hj, complex)

    @property
    def _lines(self) -> int:
        """Lines per chunk of the "even" transforms: an eighth of the block's lines on large grids (the
        kernel then keeps little beyond its spectrum: the block-sized intermediate is the output array
        itself), but not under ~64 k values a chunk (whole on small grids: fewer calls); balanced."""
        most = max(self.shape)
        lines = min(most, max(8, -(-most // 8), (1 << 16) // max(self.lengths)))
        return -(-most // -(-most // lines))

    def _apply_unsplit(self, p, out, t):
        """The plain DCT-I of length L along the "dct1" axes (fewer calls: faster on small grids)."""
        m0, m1 = self.shape
        if self.modes == ("dct1", "dct1"):
            (W,) = self._buffers()
            W[:m0, :m1] = p
            W[:m0, m1:] = 0.0
            W[m0:] = 0.0
            _bf.dct(W[:m0], 1, 1, W[:m0], t)
            _bf.dct(W, 1, 0, W, t)
            W *= self.spectrum
            _bf.dct(W, 1, 0, W, t)
            _bf.dct(W[:m0], 1, 1, W[:m0], t)
            w = W[:m0, :m1]
        else:
            j, k = self.cplx, 1 - self.cplx
            R, C = self._buffers()
            R.fill(0.0)
            R[:m0, :m1] = p
            Rk = R[_ix(j, slice(0, self.shape[j]))]  # the lines that hold data
            _bf.dct(Rk, 1, k, Rk, t)
            _bf.r2c(R, j, C, t)
            C *= self.spectrum
            _bf.c2r(C, j, self.lengths[j], 0, R, t)
            _bf.dct(Rk, 1, k, Rk, t)
            w = R[:m0, :m1]
        if out is None:
            return w.copy()
        np.copyto(out, w)
        return out

    @staticmethod
    def _dct1_fwd(x, k, y, t):
        """y ← the DCT-I (split order) along k of x, zero beyond its first h values (x: h + 1 along k)."""
        h = x.shape[k] - 1
        _bf.dct(x, 1, k, y[_ix(k, slice(0, h + 1))], t)
        _bf.dct(x[_ix(k, slice(0, h))], 3, k, y[_ix(k, slice(h + 1, None))], t)

    @staticmethod
    def _dct1_inv(y, k, m, out, t):
        """The first m values along k of the DCT-I of y (split order), into ``out`` (new if None);
        y is overwritten."""
        h = (y.shape[k] - 1) // 2
        ev, od = y[_ix(k, slice(0, h + 1))], y[_ix(k, slice(h + 1, None))]
        _bf.dct(ev, 1, k, ev, t)
        _bf.dct(od, 2, k, od, t)
        return np.add(ev[_ix(k, slice(0, m))], od[_ix(k, slice(0, m))], out=out)

    def _even(self, src, k, dst, t, spec=None):
        """dst ← the even transform along k of src (the DFT of the unfolded lines, real), times ``spec``
        if given; line chunk by line chunk, so src may be dst.  Two lines a, b share one complex FFT:
        both even and real, FFT(a + ib) = A + iB with A, B real (cheaper than two real FFTs:
        pocketfft's r2c gains little over c2c)."""
        Z, _ = self._buffers()
        o, m = 1 - k, src.shape[k]
        n, ch = 2 * m - 1, self._lines
        for s0 in range(0, src.shape[o], ch):
            w = min(ch, src.shape[o] - s0)
            wa = (w + 1) // 2  # lines s0 … s0 + wa − 1 in the real parts, the rest in the imaginary
            a, b = _ix(o, slice(s0, s0 + wa)), _ix(o, slice(s0 + wa, s0 + w))
            z = Z[: n * wa].reshape((n, wa) if k == 0 else (wa, n))
            zm = z[_ix(k, slice(0, m))]
            zm.real = src[a]
            if w - wa < wa:
                zm.imag[_ix(o, slice(w - wa, wa))] = 0.0
            zm.imag[_ix(o, slice(0, w - wa))] = src[b]
            z[_ix(k, slice(m, n))] = z[_ix(k, slice(m - 1, 0, -1))]
            _bf.c2c(z, k, True, 0, z, t)
            if spec is None:
                dst[a] = zm.real
                dst[b] = zm.imag[_ix(o, slice(0, w - wa))]
            else:
                np.multiply(zm.real, spec[a], out=dst[a])
                np.multiply(zm.imag[_ix(o, slice(0, w - wa))], spec[b], out=dst[b])
        return dst

    def _even_spec_even(self, a, k, t):
        """a ← the even transform along k of (the even transform along k of a) × spectrum, in place: the two
        passes of :meth:`_even` along one axis fused per line chunk (the chunk's transform stays in the buffer
        between them: the same values as the two passes, without storing and packing them again)."""
        Z, _ = self._buffers()
        spec = self.spectrum
        o, m = 1 - k, a.shape[k]
        n, ch = 2 * m - 1, self._lines
        for s0 in range(0, a.shape[o], ch):
            w = min(ch, a.shape[o] - s0)
            wa = (w + 1) // 2
            nb = w - wa
            sa, sb = _ix(o, slice(s0, s0 + wa)), _ix(o, slice(s0 + wa, s0 + w))
            z = Z[: n * wa].reshape((n, wa) if k == 0 else (wa, n))
            zm = z[_ix(k, slice(0, m))]
            zr, zi = zm.real, zm.imag
            ib = zi[_ix(o, slice(0, nb))]
            zr[...] = a[sa]
            if nb < wa:
                zi[_ix(o, slice(nb, wa))] = 0.0
            ib[...] = a[sb]
            head, tail = z[_ix(k, slice(m, n))], z[_ix(k, slice(m - 1, 0, -1))]
            head[...] = tail
            _bf.c2c(z, k, True, 0, z, t)
            np.multiply(zr, spec[sa], out=zr)
            np.multiply(ib, spec[sb], out=ib)
            if nb < wa:
                zi[_ix(o, slice(nb, wa))] = 0.0
            head[...] = tail
            _bf.c2c(z, k, True, 0, z, t)
            a[sa] = zr
            a[sb] = ib
        return a

    def _periodic_lines(self, a, j, t):
        """a ← irfft(rfft(a) · spectrum) along the periodic axis j, in place, line chunk by chunk."""
        _, E = self._buffers()
        o, n, ch = 1 - j, self.lengths[j], self._lines
        hj = n // 2 + 1
        for s0 in range(0, a.shape[o], ch):
            w = min(ch, a.shape[o] - s0)
            sl = _ix(o, slice(s0, s0 + w))
            e = E[: hj * w].reshape((hj, w) if j == 0 else (w, hj))
            _bf.r2c(a[sl], j, e, t)
            e *= self.spectrum[sl]
            _bf.c2r(e, j, n, 0, a[sl], t)
        return a

    def _apply_direct(self, p, out=None):
        """K p into ``out`` (a new array when None): never a view of a buffer."""
        t = self.threads
        m0, m1 = self.shape
        p = np.asarray(p, dtype=float)
        if "dct1" in self.modes and not self.split:
            return self._apply_unsplit(p, out, t)
        if self.modes == ("dct1", "dct1"):
            X, Z, W = self._buffers()
            X[:, :m1] = p  # (X, Z: zero beyond the block, kept so)
            self._dct1_fwd(X, 1, Z[:m0], t)
            self._dct1_fwd(Z, 0, W, t)
            W *= self.spectrum
            self._dct1_inv(W, 0, m0, Z[:m0], t)
            return self._dct1_inv(Z[:m0], 1, m1, out, t)
        if self.cplx is not None:
            j, k = self.cplx, 1 - self.cplx
            nj, n = self.shape[j], self.lengths[j]
            if self.modes[k] == "dct1":
                Zb, R, C = self._buffers()
                Zb[_ix(k, slice(0, self.shape[k]))] = p
                R[_ix(j, slice(nj, None))] = 0.0
                Rk = R[_ix(j, slice(0, nj))]  # the lines that hold data
                self._dct1_fwd(Zb, k, Rk, t)
                _bf.r2c(R, j, C, t)
                C *= self.spectrum
                _bf.c2r(C, j, n, 0, R, t)
                return self._dct1_inv(Rk, k, self.shape[k], out, t)
            out = np.empty(self.shape) if out is None else out
            self._even(p, k, out, t)
            self._periodic_lines(out, j, t)
            return self._even(out, k, out, t)
        out = np.empty(self.shape) if out is None else out
        self._even(p, 1, out, t)
        self._even_spec_even(out, 0, t)
        return self._even(out, 1, out, t)



def mirror_spectrum(coeff, modes):
    """The (real) transform of an even kernel ``coeff`` for :class:`MirrorConvolver`: DCT-I along the
    "dct1" axes, the real part of the rfft along the others (``coeff`` even there: its rfft is real),
    unnormalised."""
    a = np.asarray(coeff, dtype=float)
    for k, m in enumerate(modes):
        if m == "dct1":
            a = _bf.scipy_dct(a, type=1, axis=k)
        elif m in ("pad", "periodic"):
            a = _bf.rfft(a, axis=k).real
        else:
            raise ValueError(f"mirror_spectrum: no transform for mode {m!r}")
    return np.ascontiguousarray(a)
