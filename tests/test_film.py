"""Finite-thickness film on a rigid substrate (tengsim.kernels.film, the film options of the kernels, [contact]).

References and tolerances:
* thickness → ∞: the half-space kernels to 1e-6 (relative, zero-mean load for the periodic one);
* thin film: the uniaxial-strain (oedometric) compliance t(1 + ν)(1 − 2ν)/(E(1 − ν)), E = E*(1 − ν²),
  exact at q = 0 and as the q → 0 limit of the bonded multiplier; frictionless: t/E* as q → 0+;
* an independent axisymmetric reference (Hankel quadrature of (2κ/q) C(qT) times the load's transform)
  for a Gaussian load: periodic kernel to 1e-5, free kernel to its O(dx²) pixel error (3e-3 at dx 0.1);
* flat punch: compressible bonded layer → π a² M / h (oedometric) as a/h grows; incompressible bonded
  layer, frictionless punch: the thin-layer result F = 3π G a⁴ δ / (8 h³) (Jaffar 1989; Chadwick 2002),
  reached by Richardson extrapolation in h/a to 1 %.
"""
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.sparse.linalg import LinearOperator, cg
from scipy.special import j0

from tengsim.kernels import film
from tengsim.run.plan import plan_contact
from tengsim.run.simulate import simulate as run_contact
from tengsim.errors import TengsimError
from tengsim.grid import Grid
from tengsim.kernels import FreeKernel, PeriodicKernel, make_kernel

NUS = [("bonded", 0.3), ("bonded", 0.49), ("bonded", 0.5), ("frictionless", 0.3)]


def test_factor_limits_and_series_continuity():
    s = np.array([20.0, 40.0, 200.0])
    for sub, nu in NUS + [("bonded", -0.5)]:
        assert np.allclose(film.compliance_factor(s, nu, sub), 1.0, rtol=1e-12, atol=0)
        c1 = film.small_s_slope(nu, sub)
        small = film.compliance_factor(np.array([1e-7]), nu, sub)[0] / 1e-7
        assert small == pytest.approx(c1, rel=1e-9, abs=1e-13)  # ν = 1/2: C ≈ (2/3)s³
        # the series and the closed form meet at the switch (no jump in C)
        a, b = film.compliance_factor(np.array([0.02 * (1 - 1e-12), 0.02 * (1 + 1e-12)]), nu, sub)
        assert abs(a - b) <= 1e-9 * abs(b)  # ν = 1/2: the closed form keeps ~9 digits at s = 0.02 (C ≈ 5e-6)
    assert film.small_s_slope(0.3, "bonded") == pytest.approx(0.4 / (2 * 0.49))


def test_thin_film_is_oedometric():
    """Bonded: (2/(E* q)) C(qt) → t(1+ν)(1−2ν)/(E(1−ν)) as q → 0, and that is the periodic mean mode."""
    E_star, t = 0.59e6, 400e-6
    for nu in (0.0, 0.3, 0.45, 0.49):
        oed = film.oedometric_compliance_si(t, E_star, nu)
        E = E_star * (1 - nu**2)
        assert oed == pytest.approx(t * (1 + nu) * (1 - 2 * nu) / (E * (1 - nu)), rel=1e-14)
        q = 1e-3 / t
        limit = 2 / (E_star * q) * film.compliance_factor(np.array([q * t]), nu, "bonded")[0]
        assert limit == pytest.approx(oed, rel=1e-5)  # next term is O((qt)²) = 1e-6
        assert film.mean_compliance(t, nu, 1 / E_star) == pytest.approx(oed, rel=1e-14)
    # frictionless: a thin layer that may slide is softer as q → 0+ (t/E*), its q = 0 mode is oedometric
    q = 1e-4
    assert 2 / q * film.compliance_factor(np.array([q * 2.0]), 0.3, "frictionless")[0] == pytest.approx(2.0)
    k = PeriodicKernel(Grid.square(4.0, 0.1), 1.0, thickness=2.0, substrate="frictionless", poisson=0.3)
    assert k.mean_compliance == pytest.approx(2.0 * 0.4 / 0.49)


def test_thick_film_recovers_half_space():
    g = Grid.square(4.0, 0.1)
    rng = np.random.default_rng(1)
    for sub, nu in NUS:
        p = rng.standard_normal(g.shape)
        p -= p.mean()
        a = PeriodicKernel(g, 0.35).apply(p)
        b = PeriodicKernel(g, 0.35, thickness=1e7, substrate=sub, poisson=nu).apply(p)
        assert np.abs(a - b).max() <= 1e-6 * np.abs(a).max()
        p = rng.random(g.shape)
        a = FreeKernel(g, 0.35).apply(p)
        b = FreeKernel(g, 0.35, thickness=1e7, substrate=sub, poisson=nu).apply(p)
        assert np.abs(a - b).max() <= 1e-6 * np.abs(a).max()


def test_correction_profile_against_quadrature():
    """h(ρ) = ∫ (C − 1) J0(sρ) ds: table + closed-form parts against adaptive quadrature; h = −1/ρ far out."""
    rho = np.array([0.0, 0.37, 1.0, 3.3, 10.0, 25.0, 39.9, 45.0])
    for sub, nu in NUS:
        h = film.correction_profile(rho, nu, sub)
        for r, v in zip(rho, h):
            ref = quad(lambda s: (film.compliance_factor(np.array([s]), nu, sub)[0] - 1) * j0(s * r),
                       0, 60, limit=4000, epsabs=1e-13, epsrel=1e-12)[0]
            assert v == pytest.approx(ref, abs=1e-8)


def _gaussian_reference(r, nu, sub, T, a2, kappa=1.0):
    """w(r) of p = exp(−r²/a²) on the layer: κ a² ∫ C(qT) e^{−q²a²/4} J0(qr) dq (Hankel transform)."""
    f = lambda q: film.compliance_factor(np.array([q * T]), nu, sub)[0] * np.exp(-q * q * a2 / 4) * j0(q * r)
    return kappa * a2 * quad(f, 0, 40, limit=500, epsabs=1e-13)[0]


def test_kernels_against_axisymmetric_reference():
    """Both film kernels against an independent Hankel-transform solution for a Gaussian load (T = 1,
    cell 20 T).  The periodic array differs from the isolated load only by its images (decaying like the
    layer's kernel) and, on a frictionless substrate, by the uniform (M_oed − κT)·F/A of its mean mode."""
    a2, T, L, dx = 0.5, 1.0, 20.0, 0.1
    g = Grid.square(L, dx)
    x = (np.arange(g.nx) - (g.nx - 1) / 2) * g.dx
    X, Y = np.meshgrid(x, x, indexing="ij")
    p = np.exp(-(X**2 + Y**2) / a2)
    c = (g.nx - 1) // 2
    idx = [c, c + 10, c + 20, c + 30]
    for sub, nu in NUS:
        ref = np.array([_gaussian_reference(x[i], nu, sub, T, a2) for i in idx])
        kp = PeriodicKernel(g, 1.0, thickness=T, poisson=nu, substrate=sub)
        off = (kp.mean_compliance - 2 * T * film.small_s_slope(nu, sub)) * np.pi * a2 / (g.lx * g.ly)
        wp = kp.apply(p)[c, idx] - off
        assert np.abs(wp - ref).max() <= 1e-5 * ref[0]
        wf = FreeKernel(g, 1.0, thickness=T, poisson=nu, substrate=sub).apply(p)[c, idx]
        assert np.abs(wf - ref).max() <= 3e-3 * ref[0]  # pixel (piecewise-constant) error, O(dx²)


def test_free_kernel_film_thinner_than_a_pixel():
    """T = dx/4 and dx/2: the correction is integrated on sub-pixels (measured 1.7e-4, 6.1e-4 for ν = 0.3;
    3×3 points per pixel gave 15 %), and pixels beyond 40 T get exactly zero influence."""
    a2, L, dx = 4.0, 24.0, 0.2
    g = Grid.square(L, dx)
    x = (np.arange(g.nx) - (g.nx - 1) / 2) * g.dx
    X, Y = np.meshgrid(x, x, indexing="ij")
    p = np.exp(-(X**2 + Y**2) / a2)
    c = (g.nx - 1) // 2
    idx = [c, c + 5, c + 10]
    for T in (0.05, 0.1):
        ref = np.array([_gaussian_reference(x[i], 0.3, "bonded", T, a2) for i in idx])
        w = FreeKernel(g, 1.0, thickness=T, poisson=0.3).apply(p)[c, idx]
        assert np.abs(w - ref).max() <= 1e-3 * ref[0]
    e = np.zeros(g.shape)
    e[c, c] = 1.0
    w = FreeKernel(g, 1.0, thickness=0.05, poisson=0.3).apply(e)
    far = np.hypot(X, Y) > 40 * 0.05 + 2 * dx
    assert np.abs(w[far]).max() <= 1e-12 * w[c, c]


def _punch_stiffness(a, h, nu, px_per_a, cell_over_a=3.0, kappa=1.0):
    """F/δ of a rigid frictionless flat punch (radius a) on a periodic film: K p = δ on the punch, p = 0 off."""
    n = int(cell_over_a * px_per_a) | 1
    d = cell_over_a * a / n
    g = Grid(n, n, d, d)
    x = (np.arange(n) - (n - 1) / 2) * d
    X, Y = np.meshgrid(x, x, indexing="ij")
    idx = np.flatnonzero(X**2 + Y**2 <= a * a)
    K = PeriodicKernel(g, kappa, thickness=h, poisson=nu)

    def mv(v):
        p = np.zeros(n * n)
        p[idx] = v
        return K.apply(p.reshape(n, n)).ravel()[idx]

    import inspect

    tol_kw = "rtol" if "rtol" in inspect.signature(cg).parameters else "tol"  # scipy < 1.12 names it tol
    sol, info = cg(LinearOperator((idx.size, idx.size), matvec=mv, dtype=float), np.ones(idx.size),
                   maxiter=5000, **{tol_kw: 1e-10})
    assert info == 0
    return sol.sum() * d * d


def test_flat_punch_thin_compressible_layer_is_oedometric():
    """F/δ → π a² M/h (κ = 1/E*, M/E* = (1 − ν)²/(1 − 2ν)) with an O(h/a) edge correction: measured ratios
    1.058, 1.026, 1.011 at a/h = 4, 8, 16 (ν = 0.3)."""
    nu, ratios = 0.3, []
    for ah in (4, 8, 16):
        h = 1.0 / ah
        ratios.append(_punch_stiffness(1.0, h, nu, 64, cell_over_a=4.0) / (np.pi / film.mean_compliance(h, nu)))
    assert all(r > 1 for r in ratios) and ratios[0] > ratios[1] > ratios[2]
    assert ratios[2] == pytest.approx(1.0, abs=0.015)
    assert (ratios[1] - 1) / (ratios[2] - 1) == pytest.approx(2.0, rel=0.25)  # first order in h/a


def test_flat_punch_thin_incompressible_layer():
    """Frictionless flat punch on a bonded incompressible layer, thin-layer limit F = 3πG a⁴δ/(8h³)
    (G = E*/4 at ν = 1/2; Jaffar, Int. J. Mech. Sci. 31, 229 (1989); Chadwick, SIAM J. Appl. Math. 62,
    1520 (2002)).  Ratios 1.94, 1.41, 1.19 at a/h = 8, 16, 32 (128 px per a) extrapolate (Richardson, two
    terms in h/a) to 0.9985."""
    G = 0.25
    r = {}
    for ah in (8, 16, 32):
        h = 1.0 / ah
        r[ah] = _punch_stiffness(1.0, h, 0.5, 128) / (3 * np.pi * G / (8 * h**3))
    assert r[8] > r[16] > r[32] > 1
    extrapolated = (8 * r[32] - 6 * r[16] + r[8]) / 3
    assert extrapolated == pytest.approx(1.0, abs=0.01)


def test_pinned_mean_flags_and_params():
    g = Grid.square(4.0, 0.2)
    assert PeriodicKernel(g, 1.0).pinned_mean
    assert not PeriodicKernel(g, 1.0, thickness=2.0, poisson=0.49).pinned_mean
    assert PeriodicKernel(g, 1.0, thickness=2.0, poisson=0.5).pinned_mean  # incompressible bonded: no mean compliance
    # the q = 0 mode is uniaxial strain on either substrate: none at ν = 1/2
    assert PeriodicKernel(g, 1.0, thickness=2.0, poisson=0.5, substrate="frictionless").pinned_mean
    assert not FreeKernel(g, 1.0, thickness=2.0).pinned_mean
    k = make_kernel("free", g, 1.0, thickness=3.0, substrate="Frictionless", poisson=0.2)
    assert k.params() == {"boundary": "free", "coupling": 1.0, "thickness": 3.0, "substrate": "frictionless",
                          "poisson": 0.2}
    assert PeriodicKernel(g, 1.0).params() == {"boundary": "periodic", "coupling": 1.0}


@pytest.mark.parametrize("kw, msg", [
    ({"thickness": 0.0}, "thickness must be finite and > 0"),
    ({"thickness": -2.0}, "thickness must be finite and > 0"),
    ({"thickness": 2.0, "poisson": 0.51}, "poisson must be in (-1, 0.5]"),
    ({"thickness": 2.0, "poisson": -1.0}, "poisson must be in (-1, 0.5]"),
    ({"thickness": 2.0, "substrate": "glued"}, "substrate must be one of bonded, frictionless"),
])
def test_kernel_refuses_bad_film(kw, msg):
    for cls in (FreeKernel, PeriodicKernel):
        with pytest.raises(TengsimError, match=msg.replace("(", r"\(").replace("]", r"\]")):
            cls(Grid.square(4.0, 0.2), 1.0, **kw)


def test_contact_table_film_keys_physical_and_dimensionless():
    base = {"shape": "pyramid", "pitch": "2um", "base": "1um", "height": "0.7um", "E_star": "0.59MPa",
            "W": "54mJ/m2", "tabor": 0.5, "boundary": "periodic", "dx": 0.2}
    plan = plan_contact({**base, "thickness": "400um", "poisson": 0.49})
    lateral = plan.extra["lateral_m"]
    assert plan.kernel_params == {"thickness": pytest.approx(400e-6 / lateral), "substrate": "bonded",
                                  "poisson": 0.49}
    assert plan.extra["thickness_m"] == pytest.approx(400e-6)
    plan = plan_contact({"shape": "pyramid", "N": 0.946, "cell": 3.78, "thickness": 5, "substrate": "frictionless"})
    assert plan.kernel_params == {"thickness": 5.0, "substrate": "frictionless", "poisson": 0.5}
    assert plan_contact({"shape": "pyramid", "N": 0.946, "cell": 3.78}).kernel_params == {}
    for bad, msg in [({"thickness": "2um"}, "has a unit, but this run is dimensionless"),
                     ({"poisson": 0.3}, "poisson describes a film: give its thickness too"),
                     ({"thickness": 1.0, "poisson": 0.7}, r"poisson must be in \(-1, 0.5\]")]:
        with pytest.raises(TengsimError, match=msg):
            plan_contact({"shape": "pyramid", "N": 0.946, "cell": 3.78, **bad})


def test_periodic_film_run_keeps_law_range_and_has_finite_slope():
    """Group A (paper scaling), periodic, 400 µm bonded film with ν = 0.49, coarse grid: every state in the
    law's range (the half-space run, same path, is not), and dP/dD once flat = the film's M/t to 2 %."""
    base = {"shape": "pyramid", "pitch": "2um", "base": "1um", "height": "0.7um", "E_star": "0.59MPa",
            "W": "54mJ/m2", "tabor": 0.5, "boundary": "periodic", "dx": 0.25, "d_min": -1.0, "d_max": 20.0,
            "d_step": 0.25, "tol": 1e-6}
    res = run_contact({**base, "thickness": "400um", "poisson": 0.49})
    assert res.params["thickness"] == pytest.approx(400e-6 / res.params["lateral_m"])
    assert res.params["poisson"] == 0.49 and res.params["substrate"] == "bonded"
    assert res.all_converged
    assert bool(np.all(res.table["in_law_range"]))
    a = res.branch("approach")
    P, D = a["pressure_Pa"], a["D"]
    flat = (P > 20e3)
    slope = np.polyfit(D[flat], P[flat], 1)[0]
    eps = res.params["eps_m"]
    expected = eps / film.oedometric_compliance_si(400e-6, 0.59e6, 0.49)
    assert slope == pytest.approx(expected, rel=0.02)
    hs = run_contact(base)
    assert not bool(np.all(hs.table["in_law_range"]))


@pytest.mark.parametrize("args, msg", [
    (["--thickness", "0"], "thickness must be finite and > 0"),
    (["--thickness", "-1"], "thickness must be finite and > 0"),
    (["--thickness", "2", "--poisson", "0.6"], "poisson must be in (-1, 0.5]"),
    (["--thickness", "2", "--poisson", "-1"], "poisson must be in (-1, 0.5]"),
    (["--thickness", "2", "--substrate", "glued"], "is not one of bonded, frictionless"),
    (["--poisson", "0.3"], "give its thickness too"),
])
def test_cli_refuses_bad_film(tmp_path, args, msg):
    out = tmp_path / "r.csv"
    p = subprocess.run([sys.executable, "-m", "tengsim.cli.main", "contact", "pyramid", "--N", "0.946",
                        "--cell", "3.78", *args, "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 2
    lines = p.stderr.strip().splitlines()
    assert len(lines) == 1 and msg in lines[0], p.stderr
    assert not out.exists()


def test_cli_film_run_writes_its_parameters(tmp_path):
    out = tmp_path / "r.csv"
    p = subprocess.run([sys.executable, "-m", "tengsim.cli.main", "contact", "pyramid", "--N", "0.946",
                        "--cell", "3.78", "--dx", "0.3", "--d-max", "1", "--d-step", "0.5", "--thickness", "4",
                        "--substrate", "frictionless", "--poisson", "0.3", "--boundary", "free", "--quiet",
                        "--out", str(out)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    head = out.read_text()
    assert "# thickness: 4.0" in head and '# substrate: "frictionless"' in head and "# poisson: 0.3" in head


def test_nested_solve_keeps_the_film_on_coarse_levels():
    """multilevel's coarse grids get the same film (each a kernel of the given kernel's class); the nested
    result is an equilibrium of the film problem and the same state as a cold start on the fine grid
    (energy to 1e-9)."""
    from tengsim.shapes import random_rough
    from tengsim.laws import LJ93
    from tengsim.solvers.multilevel import nested_solve
    from tengsim.solvers import FastSolver, Problem, State

    made = []

    class Spy(PeriodicKernel):
        def __post_init__(self):
            super().__post_init__()
            made.append(self.film_params())

    surf = random_rough(64, 16.0, hurst=0.8, rms_height=1.0, short_cutoff=2.0, seed=3)
    grid = surf.grid()
    U0 = surf.gap(grid)
    g0 = U0 - float(np.quantile(U0, 0.05)) + 1.0
    K = Spy(grid, 0.5**1.5, thickness=4.0, poisson=0.45)
    made.clear()
    solver = FastSolver(tol=1e-7)
    ns = nested_solve(solver, g0, LJ93(), K, min_size=32, max_dx=1.0)
    eq = ns.equilibrium
    assert [lv.shape for lv in ns.levels] == [(32, 32), (64, 64)] and eq.converged
    assert made == [{"thickness": 4.0, "substrate": "bonded", "poisson": 0.45}]
    r = eq.H - (g0 - 1.0 + K.apply(LJ93().pressure(eq.H + 1.0)))
    assert np.max(np.abs(r)) < 1.01e-7
    cold = solver.solve(Problem(g0, LJ93(), K), State.zero(g0.shape))
    assert cold.converged and abs(eq.energy - cold.energy) <= 1e-9 * abs(cold.energy)


def test_incompressible_periodic_film_warns_like_the_half_space():
    """ν = 1/2 (the default) on a bonded periodic film: no mean compliance, states leave the law's range
    once the array is flat, and the warning says why and what to do."""
    base = {"shape": "pyramid", "pitch": "2um", "base": "1um", "height": "0.7um", "E_star": "0.59MPa",
            "W": "54mJ/m2", "tabor": 0.5, "boundary": "periodic", "dx": 0.25, "d_min": -1.0, "d_max": 6.0,
            "d_step": 0.5, "thickness": "400um"}
    res = run_contact(base)
    assert not bool(np.all(res.table["in_law_range"]))
    assert "incompressible (poisson = 0.5)" in res.params["warning"]
    assert "warning" not in run_contact({**base, "poisson": 0.49}).params


def _kernels(coupling, **film):
    """Each kernel class built with ``coupling`` and the film ``film`` (the slab kernel with a stand-in comm: it is
    validated before the comm is asked anything)."""
    from tengsim.grid import Grid, Mirror
    from tengsim.kernels import FreeKernel, MirrorKernel, PeriodicKernel
    from tengsim.kernels.distributed import SlabPeriodicKernel

    g = Grid(9, 9, 0.5, 0.5)
    return [lambda: FreeKernel(g, coupling, **film), lambda: PeriodicKernel(g, coupling, **film),
            lambda: MirrorKernel("free", g, coupling, Mirror(g, (0, 1)), **film),
            lambda: SlabPeriodicKernel(g, coupling, object(), **film)]


@pytest.mark.parametrize("coupling, film, message", [
    (-1.0, {}, "coupling must be finite and > 0, got -1.0"),
    ("x", {}, "coupling must be a number, got 'x'"),
    (float("nan"), {"thickness": -1.0}, "coupling must be finite and > 0, got nan"),  # the coupling first
    (1.0, {"thickness": -1.0}, "thickness must be finite and > 0, got -1.0"),
    (1.0, {"thickness": 1.0, "poisson": 0.7}, "poisson must be in (-1, 0.5], got 0.7"),
])
def test_every_kernel_validates_its_body_in_one_place(coupling, film, message):
    for build in _kernels(coupling, **film):
        with pytest.raises(TengsimError) as err:
            build()
        assert str(err.value) == message


def test_kernels_keep_the_coupling_as_before():
    """FreeKernel and PeriodicKernel keep the coupling as given; the mirror kernel holds it as a float."""
    free, periodic, mirror, _ = _kernels(1)
    assert type(free().coupling) is int and type(periodic().coupling) is int
    assert type(mirror().coupling) is float and mirror().coupling == 1.0
