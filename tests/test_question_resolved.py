"""examples/design/question*_resolved.toml (docs/design.md, "The design question"):
the coarse design studies with resolve = "auto"; the same points otherwise, and bad refinement keys refused."""
from pathlib import Path

import pytest

from tengsim.cli.main import main

DESIGN = Path(__file__).parents[1] / "examples" / "design"
PAIRS = [("question_resolved", "question"), ("question_periodic_resolved", "question_periodic")]
KEYS = ("resolve", "resolve_tol", "max_pixels", "resolve_pressures")


@pytest.mark.parametrize("name, coarse", PAIRS)
def test_resolved_study_is_the_coarse_one_with_refinement(name, coarse):
    """Every point valid; the same 90 points as the coarse file once the refinement keys are removed;
    each point refines from the coarse grid (45², within max_pixels) with tolerance 1 %, converging A/S at
    the study's [observables] pressures too."""
    from tengsim.run.plan import plan_contact
    from tengsim.study.validate import validate
    from tengsim.study.spec import load_study

    s, c = load_study(DESIGN / f"{name}.toml"), load_study(DESIGN / f"{coarse}.toml")
    valid, invalid = validate(s)
    assert valid and not invalid, invalid
    assert len(s.points) == len(c.points) == 90
    strip = [{k: v for k, v in p.contact.items() if k not in KEYS} for p in s.points]
    assert strip == [dict(p.contact) for p in c.points]
    for p in s.points:
        assert (p.contact["resolve"], p.contact["resolve_tol"], p.contact["max_pixels"]) == ("auto", 0.01, 10000)
        assert p.contact["resolve_pressures"] == [f"{x:.6g}Pa" for x in s.observables["pressures"]]
        plan = plan_contact(dict(p.contact))
        g = plan.shape.grid(plan.dx)
        assert (g.nx, g.ny) == (45, 45) and g.nx * g.ny <= p.contact["max_pixels"]


@pytest.mark.parametrize("old, new, word", [("max_pixels = 10000", "max_pixels = 4", "max_pixels"),
                                            ("max_pixels = 10000", "max_pixels = 8192.5", "8192.5"),
                                            ("resolve_tol = 0.01", "resolve_tol = 2", "resolve_tol"),
                                            ('\nresolve = "auto"', '\nresolve = "yes"', "'yes'")])
def test_resolved_study_bad_refinement_key_exit_2_nothing_written(tmp_path, capsys, old, new, word):
    text = (DESIGN / "question_resolved.toml").read_text()
    assert text.count(old) == 1
    f = tmp_path / "s.toml"
    f.write_text(text.replace(old, new))
    rc = main(["sweep", str(f), "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and word in err, err
    assert not (tmp_path / "out").exists()


def test_more_grids_study_is_the_periodic_one_for_the_smooth_sided_patterns():
    """docs/validation.md, "Automatic refinement" (edges kept in place): the periodic study's pyramid, cone and hemisphere points, nothing else
    changed but max_pixels, which admits the refinement 45², 65², 105², 165², 245² (each base edge a quarter
    pixel past a pixel centre on every grid: tengsim.run.resolve keeps it there) and no finer grid."""
    from tengsim.run.plan import plan_contact
    from tengsim.run.grids import FACTOR, aligned, edge_phases
    from tengsim.study.validate import validate
    from tengsim.study.spec import load_study

    s, base = load_study(DESIGN / "question_periodic_resolved_245.toml"), load_study(DESIGN / "question_periodic_resolved.toml")
    valid, invalid = validate(s)
    assert valid and not invalid, invalid
    smooth = [dict(p.contact) for p in base.points if p.contact["shape"] in ("pyramid", "cone", "hemisphere")]
    assert len(s.points) == len(smooth) == 54
    assert [{**dict(p.contact), "max_pixels": 10000} for p in s.points] == smooth
    for p in s.points:
        cap = p.contact["max_pixels"]
        assert cap == 61000
        plan = plan_contact(dict(p.contact))
        g = plan.shape.grid(plan.dx)
        phases, sides = edge_phases(plan.shape, g), [g.nx]
        assert phases == pytest.approx((0.25,), abs=1e-9)
        while True:
            g = aligned(plan.shape, plan.shape.grid(g.dx / FACTOR), phases, cap)
            if g.nx * g.ny > cap:
                break
            sides.append(g.nx)
            assert edge_phases(plan.shape, g) == pytest.approx(phases, abs=1e-9)
        assert sides == [45, 65, 105, 165, 245]
