"""The charged area A/S of Eq. (12) measured on the 2-D contact map (tengsim.analysis.charged_area: the area
where the gap is below the law's peak-tension separation), the same code for every shape, against known answers:
flat tops in full contact (cube, flat punch, ridge) give their top's footprint, a sphere (a hemisphere's
single-contact limit) Maugis–Dugdale's π a², a pyramid pressed until its land touches counts the land, a law
without tension its wall's area; the paper's Λc definition stays available."""
import math

import numpy as np
import pytest

from tengsim.analysis import charged_area, law_edge
from tengsim.grid import Grid
from tengsim.laws import LJ93, MaugisDugdale, Repulsive, Exponential


def test_every_registered_law_declares_its_peak_separation():
    from tengsim.laws.safe import SafeLaw
    assert LJ93().peak_separation == pytest.approx(3 ** (1 / 6), rel=1e-12)
    assert MaugisDugdale().peak_separation == 1.0 and MaugisDugdale().edge_opening == 1.5
    assert Exponential().peak_separation == 1.0
    assert Repulsive().peak_separation == 1.0 and Repulsive().g_peak is None  # no tension: its wall's gap
    assert law_edge(SafeLaw(LJ93())) == (LJ93().peak_separation, 1.0)
    # the separation is where the law's tension peaks
    for law in (LJ93(), MaugisDugdale(), Exponential()):
        g = np.linspace(0.95, 3.0, 200001)
        p = law.evaluate(g)[1]
        assert g[np.argmin(p)] == pytest.approx(law.peak_separation, abs=2e-4)


def test_a_step_counts_its_top_and_an_opening_edge_is_subpixel():
    g = Grid(40, 40, 1.0, 1.0)
    H = np.full((40, 40), 29.0)
    H[10:18, 10:18] = 0.0                          # a flat top in contact beside a land that is not
    for periodic in (False, True):
        assert charged_area(H, g, 3 ** (1 / 6), 1.0, periodic) == pytest.approx(64.0, rel=1e-12)
        assert charged_area(H, g, 1.0, 1.5, periodic) == pytest.approx(64.0, rel=1e-12)
    # a disc whose gap opens as (r − a)^{3/2} outside (a Dugdale edge), a over one pixel: within 0.5 %
    n, dx = 121, 0.05
    gr = Grid(n, n, dx, dx)
    x = (np.arange(n) - n // 2) * dx
    r = np.hypot(x[:, None], x[None, :])
    for a in np.linspace(1.0, 1.05, 6):
        Hd = np.where(r > a, 0.7 * np.clip(r - a, 0, None) ** 1.5, -1e-4)
        assert charged_area(Hd, gr, 1.0, 1.5) == pytest.approx(math.pi * a * a, rel=5e-3)
        Hl = np.where(r > a, 0.2 + 0.5 * (r - a), 0.2 * (r / a) ** 2)  # a gap crossing the level with a slope
        assert charged_area(Hl, gr, 1.2, 1.0) == pytest.approx(math.pi * a * a, rel=5e-3)


def _walk(shape, law, Ds, periodic=False, mu=1.0, dx=0.1, tol=1e-6):
    from tengsim.continuation import walk_states
    from tengsim.kernels import FreeKernel, PeriodicKernel
    from tengsim.observers import Context, Summary
    from tengsim.analysis import apex_index
    from tengsim.solvers import FastSolver

    grid = shape.grid(dx)
    U0 = shape.gap(grid)
    kernel = (PeriodicKernel if periodic else FreeKernel)(grid, mu ** 1.5)
    ctx = Context(grid, apex_index(U0), U0, law, kernel)
    out = []
    for D, eq in walk_states(U0, law, kernel, FastSolver(tol, max_iter=30000), Ds):
        assert eq.converged, (D, eq.residual)
        out.append((D, eq, Summary()(eq, ctx)))
    return grid, U0, out


@pytest.mark.parametrize("name", ["cube", "flat_punch", "line"])
def test_flat_top_in_full_contact_gives_its_footprint(name):
    """Cube (flat-topped pillar), flat punch and ridge, top pressed into full contact, land apart: A/S = the top's
    footprint within 1 % (the top's pixels; the nominal footprint within the pixel's share)."""
    from tengsim.shapes import Cube, FlatPunch, Line
    shape = {"cube": Cube(half_width=1.0, height=8.0, cell=5.0), "flat_punch": FlatPunch(radius=1.0, cell=5.0, step=8.0),
             "line": Line(half_width=1.0, height=8.0, cell=5.0)}[name]
    nominal = {"cube": (2 / 5) ** 2, "flat_punch": math.pi / 25, "line": 2 / 5}[name]
    grid, U0, rows = _walk(shape, LJ93(), [0.5, 1.0, 1.5], periodic=name == "line")
    top = np.count_nonzero(U0 <= U0.min() + 1e-9) / U0.size
    assert top == pytest.approx(nominal, rel=0.1)
    for D, eq, s in rows:
        assert np.all(eq.H[U0 <= U0.min() + 1e-9] < 3 ** (1 / 6) - 1)  # the top in contact
        assert np.all(eq.H[U0 > 1.0] > 3.0)                              # the land apart
        assert s["charged_fraction"] == pytest.approx(top, rel=0.01), (D, s["charged_fraction"], top)
        assert s["charged_fraction"] < 1.5 * nominal                      # never the whole cell (the old Λc²)


def test_sphere_single_contact_gives_maugis_dugdale_area():
    """A sphere R = 1 (the single-contact limit of a hemisphere), Maugis–Dugdale law (wall 1e4), μ = 1, free
    cell 8, dx 0.08 (a ≈ 20–24 pixels): at each load on the contact branch the 2-D charged area is π a² with a
    the engine's own contact radius (the sub-pixel edge fit, tengsim.analysis.edge_radius) within 1.5 % (radius
    0.7 %), and with a Maugis' contact radius at that load within 1.5 % (measured: −0.2, −1.4, −0.1 %; the
    grid's own share: its edge radius lies 0.7–1.1 % from Maugis' here)."""
    from tengsim import references as ref
    from tengsim.analysis import apex_index, edge_radius
    from tengsim.laws import LJ_PEAK_TENSION
    from tengsim.shapes import Paraboloid
    from tengsim.continuation import walk_states
    from tengsim.kernels import FreeKernel
    from tengsim.solvers import FastSolver

    mu = 1.0
    shape = Paraboloid(1.0, 8.0)
    grid = shape.grid(0.08)
    U0 = shape.gap(grid)
    kernel = FreeKernel(grid, mu ** 1.5)
    start = None
    for _, eq in walk_states(U0, MaugisDugdale(), kernel, FastSolver(1e-5, max_iter=50000), [0.0]):
        start = eq.state
    law = MaugisDugdale(wall_stiffness=1e4)
    g_c, opening = law_edge(law)
    lam = ref.md_lambda(1.0, mu ** -1.5, 1.0, LJ_PEAK_TENSION)
    sc = ref.md_scales(1.0, mu ** -1.5, 1.0)
    c = ref.maugis_dugdale_curve(lam, A_max=4.0, n=4000, A_min=1e-3)
    i = int(np.argmin(c.P))
    for D, eq in walk_states(U0, law, kernel, FastSolver(1e-7, max_iter=30000), [0.0, 0.5, 1.0], start):
        assert eq.converged
        load = eq.P.sum() * grid.area / math.pi          # P̄ = F/(πWR), compressive positive
        a = float(np.interp(load, c.P[i:], c.A[i:])) * sc.length
        A = charged_area(eq.H, grid, g_c, opening)
        assert A == pytest.approx(math.pi * edge_radius(eq.H, grid, apex_index(U0)) ** 2, rel=0.015), D
        assert A == pytest.approx(math.pi * a * a, rel=0.015), (D, a)


def test_pyramid_pressed_until_the_land_touches_counts_the_land():
    """A periodic pyramid array pressed until its land touches: A/S holds the land (more than the pyramid's
    footprint, at least the repulsive area), where the paper's Λc² stops at the footprint."""
    from tengsim.shapes import Pyramid
    shape = Pyramid(N=1.5, cell=4.0)                 # base 3, height 3 ε, footprint (3/4)² = 0.5625
    grid, U0, rows = _walk(shape, LJ93(), [1.0, 2.0, 3.0, 4.0, 5.0], periodic=True, mu=0.5, dx=0.1)
    D, eq, s = rows[-1]
    rep = s["area_repulsive"] / (grid.nx * grid.ny * grid.area)
    assert np.count_nonzero(eq.H[U0 >= 3.0 - 1e-9] < 0.0) > 0          # the land touches
    assert s["charged_fraction"] >= rep > (3.0 / 4.0) ** 2
    assert s["charged_fraction"] > 0.7


def test_repulsive_law_charges_its_wall_area():
    """A law without tension (non-adhesive wall): the charged area is where its wall acts, g <= 1 (P >= its
    scale c): on a flat punch it grows from the edge inwards to the top, never beyond it while the land is apart."""
    from tengsim.shapes import FlatPunch
    shape = FlatPunch(radius=1.0, cell=5.0, step=8.0)
    grid, U0, rows = _walk(shape, Repulsive(), [4.0, 8.0])
    top = np.count_nonzero(U0 <= U0.min() + 1e-9) / U0.size
    for D, eq, s in rows:
        assert s["min_pressure"] > 0 and np.all(eq.H[U0 > 1.0] > 1.0)   # no tension anywhere; the land apart
        assert s["charged_fraction"] <= top * 1.01                       # never beyond the top (the old Λc: the cell)
    # the wall engages from the punch's edge inwards (its centre is the least pressed): at D = 8, 0.97 of the top
    assert rows[0][2]["charged_fraction"] < rows[1][2]["charged_fraction"]
    assert rows[1][2]["charged_fraction"] >= 0.95 * top


def test_flat_mesa_topography_gives_its_top():
    """A height map with flat round mesas (a measured-surface stand-in; the 'topography' shape reads the same
    U0 from a file), periodic, pressed onto its tops: A/S = the mesa's top (pixels) within 1 %, growing with the
    mesa's radius (the old Λc measured the tensile minimum inside the flat face: A/S ≈ 0)."""
    from tengsim.shapes.heightmap import HeightMap
    n, cell = 50, 5.0
    x = (np.arange(n) - n // 2) * cell / n
    r = np.hypot(x[:, None], x[None, :])
    areas = []
    for radius in (1.2, 1.5):
        z = np.where(r <= radius, 8.0, 0.0)
        shape = HeightMap(z, cell)
        grid, U0, rows = _walk(shape, LJ93(), [0.5, 1.0], periodic=True, dx=cell / n)
        top = np.count_nonzero(U0 <= U0.min() + 1e-9) / U0.size
        for D, eq, s in rows:
            assert s["charged_fraction"] == pytest.approx(top, rel=0.01), (radius, D)
        areas.append(rows[-1][2]["charged_fraction"])
    assert areas[1] > areas[0]
