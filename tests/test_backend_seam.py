"""The one seam for arrays and FFTs (issue 28): no Fourier transform of src/tengsim outside
tengsim.backend, and the seam's allocators and lengths do what they say."""
import io
import tokenize
from pathlib import Path

import numpy as np
import pytest
from conftest import registered

SRC = Path(__file__).resolve().parents[1] / "src" / "tengsim"
SEAM = SRC / "backend"


def fft_uses(text: str) -> list[str]:
    """Code (not comments or strings) naming np.fft, numpy.fft, scipy.fft or pocketfft, or importing
    fft from numpy or scipy: "line: code" for each."""
    toks = [t for t in tokenize.generate_tokens(io.StringIO(text).readline)
            if t.type in (tokenize.NAME, tokenize.OP)]
    hits = []
    for i, t in enumerate(toks):
        name = t.string
        if t.type == tokenize.NAME and "pocketfft" in name:
            hits.append(t)
        elif (name in ("np", "numpy", "scipy") and i + 2 < len(toks) and toks[i + 1].string == "."
              and toks[i + 2].string == "fft"):
            hits.append(t)
        elif (name == "from" and i + 3 < len(toks) and toks[i + 1].string in ("numpy", "scipy")
              and toks[i + 2].string == "import" and toks[i + 3].string == "fft"):
            hits.append(t)
    return [f"{t.start[0]}: {t.line.strip()}" for t in hits]


def test_no_fft_outside_the_backend():
    bad = {}
    for path in sorted(SRC.rglob("*.py")):
        if SEAM in path.parents:
            continue
        found = fft_uses(path.read_text(encoding="utf-8"))
        if found:
            bad[str(path.relative_to(SRC))] = found
    assert not bad, f"FFTs outside tengsim.backend: {bad}"


@pytest.mark.parametrize("code", ["import numpy as np\nx = np.fft.rfft2(a)\n",
                                  "import scipy.fft as f\n", "from scipy import fft\n",
                                  "from scipy.fft._pocketfft import pypocketfft as pp\n",
                                  "y = numpy.fft.fftfreq(4)\n"])
def test_the_grep_catches_each_form(code):
    assert fft_uses(code)


def test_the_grep_ignores_comments_and_strings():
    assert not fft_uses('# np.fft is only called in the seam\ns = "scipy.fft"\n')


def test_the_seam_is_where_the_transforms_are():
    from tengsim.backend import fft
    assert fft_uses((SEAM / "fft.py").read_text(encoding="utf-8"))
    assert fft.BACKEND in ("pocketfft", "scipy.fft")


def test_allocators_and_lengths():
    from tengsim import backend
    a = backend.zeros((3, 4))
    assert isinstance(a, backend.xp.ndarray) and a.shape == (3, 4) and not a.any()
    assert backend.empty(5).shape == (5,) and backend.zeros(2, int).dtype.kind == "i"
    assert backend.to_host(np.float64(2.5)) == 2.5 and type(backend.to_host(np.float64(1))) is float
    for n in (1, 7, 97, 250, 1001):
        m = backend.fast_len(n)
        assert m >= n and _smooth(m, (2, 3, 5, 7, 11))
        k = backend.fast_odd_len(n)
        assert k >= n and k % 2 == 1 and _smooth(k, (3, 5, 7, 11, 13))
    assert backend.fast_odd_len(14) == 15 and backend.fast_len(97) == 100


def _smooth(m, primes):
    for p in primes:
        while m % p == 0:
            m //= p
    return m == 1


@pytest.mark.parametrize("boundary", registered("boundary"))
def test_kernels_pickle_without_their_buffers(boundary):
    """Dask workers pickle kernels: the convolvers (tengsim.kernels.convolve, .dct) travel without their
    per-thread buffers and convolve the same afterwards."""
    import pickle

    from tengsim.grid import Grid
    from tengsim.kernels import make_kernel, make_mirror_kernel

    g = Grid(15, 15, 0.2, 0.2)
    rng = np.random.default_rng(2)
    full, mk = make_kernel(boundary, g, 0.7), make_mirror_kernel(boundary, g, 0.7, (0, 1))
    for K, on in ((full, lambda k: k), (mk, lambda k: k.reduced)):
        p = rng.standard_normal(on(K).grid.shape)
        w = on(K).apply(p)  # the buffers are made
        assert K._conv._tls.__dict__
        K2 = pickle.loads(pickle.dumps(K))
        assert not K2._conv._tls.__dict__
        assert np.array_equal(on(K2).apply(p), w)
