"""How far one path's force curve is from another's (the adaptive walk against a fixed-step one)."""
from __future__ import annotations

import numpy as np

from tengsim.continuation.specs import BRANCHES


def compare_paths(ref, other, interp: str = "pchip") -> dict:
    """How far the curve ``other`` is from ``ref`` (two ContactResults of the same problem).

    Per branch, ``other`` is cut at its jumps into continuous segments and F is interpolated on each
    segment (``interp`` 'linear': the curve as plotted; 'pchip': monotone cubic, scipy's PCHIP, linear
    on a 2-row segment) at every D of ``ref`` that lies
    inside one of them; D values of ``ref`` inside a jump interval of ``other`` (between its D_before
    and D_after) are skipped, and so are rows of ``ref`` that start a jump (the state on the far
    side of ``ref``'s own jump, compared only if ``other`` has a segment there).  The difference is
    relative to max(|F_ref(D)|, F_adh), F_adh = the magnitude of the most tensile F of ``ref`` (the adhesive force
    scale), so it is a relative error where |F| is large and an error in units of the pull-off force
    where F crosses zero.  Returns {'max_rel_dF', 'where' ((branch, D) of it), 'n_compared', 'n_skipped', 'max_rel_dF_same_D'
    (rows at equal D, no interpolation), 'jumps_ref', 'jumps_other' (lists of (branch, D_before,
    D_after)), 'max_jump_dD' (largest |ΔD_after| between jumps matched by branch and order; NaN if
    the counts differ)}.
    """
    from scipy.interpolate import PchipInterpolator

    f_adh = max(abs(float(np.min(ref.table["F"]))), 1e-12)
    worst, worst_same, n_cmp, n_skip, where = 0.0, 0.0, 0, 0, None
    for br in BRANCHES:
        a, b = ref.branch(br), other.branch(br)
        if len(a["D"]) == 0 or len(b["D"]) == 0:
            continue
        cuts = [0] + [i for i in np.flatnonzero(b["jump"]) if i > 0] + [len(b["D"])]
        segs = []
        for i0, i1 in zip(cuts[:-1], cuts[1:]):
            D, F = b["D"][i0:i1], b["F"][i0:i1]
            if len(D) == 0:
                continue
            o = np.argsort(D)
            D, F = D[o], F[o]
            fn = PchipInterpolator(D, F) if len(D) >= 3 and interp == "pchip" else (lambda x, D=D, F=F: np.interp(x, D, F))
            segs.append((D[0], D[-1], fn))
        for D, F in zip(a["D"], a["F"]):
            seg = [s for s in segs if s[0] - 1e-12 <= D <= s[1] + 1e-12]
            if not seg:
                n_skip += 1
                continue
            scale = max(abs(F), f_adh)
            e = min(abs(float(s[2](D)) - F) for s in seg) / scale
            if e > worst:
                worst, where = e, (br, float(D))
            n_cmp += 1
            same = np.flatnonzero(np.abs(b["D"] - D) < 1e-9)
            if len(same):
                worst_same = max(worst_same, float(np.min(np.abs(b["F"][same] - F))) / scale)

    def jl(res):
        return [(j.branch, j.D_before, j.D_after) for j in res.jumps]

    ja, jb = jl(ref), jl(other)
    if len(ja) == len(jb) and all(x[0] == y[0] for x, y in zip(ja, jb)):
        dj = max((abs(x[2] - y[2]) for x, y in zip(ja, jb)), default=0.0)
    else:
        dj = float("nan")
    return {"max_rel_dF": worst, "where": where, "max_rel_dF_same_D": worst_same, "n_compared": n_cmp,
            "n_skipped": n_skip, "jumps_ref": ja, "jumps_other": jb, "max_jump_dD": dj}
