"""Device model (paper Sections 4-5): closed forms, limits, bookkeeping, event rules, convergence."""
import math

import numpy as np
import pytest

from tengsim.cases.paper import fig7_params, fig7_summary, fig7_waveform, fig8_params, fig8_summary, run_fig7, run_fig8
from tengsim.device import (EPS0, AreaTable, ConstantArea, DeviceParams, Sine, SolverOptions, SquareWave, Staircase,
                            TableWaveform, cmeo_cycle, eq20_force, field_force, figure_of_merit, fom_structural,
                            isc_apart, resistance_sweep, simulate, voc_apart, voc_from_area, voc_from_contact_length,
                            voc_polymer, vq_cycle, parse_waveform)
from tengsim.errors import TengsimError

P7 = fig7_params()
WF7 = fig7_waveform()


def synthetic_table():
    """Saturating A/S(P) like the engine's group-A curve: 0.25 (lambda_c = m = L/2) at full contact."""
    p = np.linspace(0.0, 2e5, 81)
    return AreaTable(p, 0.25 * (1 - np.exp(-p / 4e4)))


@pytest.fixture(scope="module")
def fig7_run():
    return run_fig7(3)


# --- closed forms (Eqs. 12, 17-19) ---

def test_voc_apart_fig7_is_200V():
    v = voc_apart(P7.sigma_C_per_m2, P7.area_m2, P7.gap_m, P7.area_m2)
    assert v == pytest.approx(200.0, rel=1e-3)
    assert v == pytest.approx(P7.voltage_scale, rel=1e-12)


def test_eq12_forms_agree_and_full_contact_voltage():
    sigma, er, T, L = 5.84e-6, 2.40, 400e-6, 2e-6
    lam = np.array([0.2e-6, 0.5e-6, 1.0e-6])
    v1 = voc_from_contact_length(lam, L, sigma, er, T)
    v2 = voc_polymer((lam / L) ** 2, sigma, er, T)
    np.testing.assert_allclose(v1, v2, rtol=1e-14)
    assert v1[-1] == pytest.approx(sigma * 0.25 * T / (er * EPS0), rel=1e-12)  # lambda_c = m = L/2
    curve = voc_from_area(sigma=sigma, eps_r=er, thickness=T, force_N=[1e-7, 2e-7, 3e-7], lambda_c=lam,
                          cell_length=L)
    np.testing.assert_allclose(curve.pressure_Pa, np.array([1e-7, 2e-7, 3e-7]) / L ** 2)
    np.testing.assert_allclose(curve.voc_V, v1)
    assert "V_oc" in curve.to_dataset()


def test_eq12_rejects_bad_area():
    with pytest.raises(TengsimError, match="area fraction"):
        voc_from_area(sigma=1e-6, eps_r=2, thickness=1e-4, pressure_Pa=[1.0, 2.0], area_fraction=[0.1, 1.5])


def test_forces_sign_and_regularisation():
    s, S, T, er = P7.sigma_C_per_m2, P7.area_m2, P7.thickness_m, P7.eps_r
    f0 = field_force(0.0, s, S, S)
    assert f0 > 0 and f0 == pytest.approx(s ** 2 * S / (2 * EPS0))  # attraction toward the polymer
    assert eq20_force(0.0, s, S, 1e-3, S, T, er) == pytest.approx(f0, rel=1e-12)  # sign-corrected Eq. 20
    q = 0.5 * s * S
    raw = [abs(eq20_force(q, s, S, d, S, T, er)) for d in (1e-9, 0.5e-9)]
    assert raw[1] / raw[0] == pytest.approx(4.0, rel=1e-3)  # 1/d^2 as printed
    reg = eq20_force(q, s, S, 0.0, S, T, er, reg_gap=1e-6)
    assert np.isfinite(reg)
    assert field_force(q, s, S, S) == pytest.approx((s * S - q) ** 2 / (2 * EPS0 * S))


# --- dynamic model: limits ---

def test_short_circuit_limit_matches_eq19():
    # R C_contact ~ 8 ns << the I_SC spike time (T/eps_r)/ydot ~ 8 us; start at rest (no Q(0) spike)
    p = P7.replace(load_ohm=1.0, initial_charge="rest")
    r = simulate(p, WF7, 0.004, dt_out=5e-6)
    fl = r.contact == 0
    isc = isc_apart(p.sigma_C_per_m2, r.area, r.gap, r.ydot, p.thickness_m, p.eps_r)
    np.testing.assert_allclose(r.I_sc, isc, rtol=1e-12)
    scale = np.max(np.abs(isc[fl]))
    assert scale > 1e-4
    assert np.max(np.abs(r.I[fl] - isc[fl])) < 5e-3 * scale
    ex = simulate(P7.replace(load_ohm=0.0), WF7, 0.004, dt_out=5e-6)  # exact R = 0 limit
    np.testing.assert_allclose(ex.I, ex.I_sc, rtol=1e-12, atol=0)
    assert np.all(ex.V == 0)


def test_open_circuit_limit_voltage_tracks_voc():
    r = simulate(P7.replace(load_ohm=1e13), WF7, 0.1, dt_out=1e-4)
    assert np.max(np.abs(r.V - r.V_oc)) < 1e-3 * np.max(r.V_oc)
    o = simulate(P7.replace(load_ohm=math.inf), WF7, 0.1, dt_out=1e-4)
    np.testing.assert_allclose(o.V, o.V_oc, rtol=1e-12, atol=1e-9)
    assert o.V_oc[0] == pytest.approx(P7.voltage_scale, rel=1e-12)


def test_start_transient_and_rest_start():
    z = simulate(P7, WF7, 1e-4)
    assert z.I[0] == pytest.approx(P7.voltage_scale / P7.load_ohm, rel=1e-9)  # V_OC / R, ~200 uA
    rest = simulate(P7.replace(initial_charge="rest"), WF7, 1e-4)
    assert abs(rest.I[0]) < 1e-12


# --- events: impact and release ---

def test_impact_time_velocity_and_release_rule():
    p = P7.replace(damping_ratio=0.0, force_model="none")
    r = simulate(p, WF7, 0.15, dt_out=1e-4)
    F, k, M, d0 = 10.0, p.stiffness_N_per_m, p.mass_kg, p.gap_m
    w = math.sqrt(k / M)
    assert r.impacts_s[0] == pytest.approx(math.acos(1 - d0 * k / F) / w, rel=1e-7)
    v_imp = math.sqrt(2 * (F * d0 - 0.5 * k * d0 ** 2) / M)
    i = np.nonzero(r.E_impact > 0)[0][0]
    assert r.E_impact[i] == pytest.approx(0.5 * M * v_imp ** 2, rel=1e-6)  # inelastic: all KE lost
    c = r.contact == 1
    assert np.all(r.y[c] == d0) and np.all(r.ydot[c] == 0)
    assert r.releases_s[0] == pytest.approx(0.1, abs=1e-12)  # P_a S drops below k_e d0 at the fall


def test_release_when_force_falls_below_spring():
    p = P7.replace(force_model="none")
    wf = Sine(10.0 / p.area_m2, 5.0, offset_Pa=10.0 / p.area_m2, phase_rad=-math.pi / 2)  # 0 -> 20 N
    r = simulate(p, wf, 0.2, dt_out=1e-4)
    assert r.releases_s.size >= 1
    t_rel = r.releases_s[0]
    assert wf(t_rel) * p.area_m2 == pytest.approx(p.stiffness_N_per_m * p.gap_m, rel=1e-8)


def test_damping_controls_rebound():
    und = simulate(P7.replace(damping_ratio=0.0, force_model="none"), WF7, 0.2, dt_out=2e-5)
    assert np.max(und.V_oc) == pytest.approx(2 * P7.voltage_scale, rel=2e-3)  # gap swings to 2 d0
    dam = simulate(P7, WF7, 0.2, dt_out=2e-5)  # default zeta = 0.7
    assert P7.voltage_scale < np.max(dam.V_oc) < 1.05 * P7.voltage_scale


# --- bookkeeping ---

@pytest.mark.parametrize("force_model", ["field", "eq20"])
def test_mechanical_energy_balance(force_model):
    r = simulate(P7.replace(force_model=force_model), WF7, 0.4, dt_out=1e-4)
    lhs = r.W_applied + r.W_electric
    rhs = r.E_mech - r.E_mech[0] + r.E_damping + r.E_impact
    assert np.max(np.abs(lhs - rhs)) < 1e-6 * np.max(r.W_applied)


@pytest.mark.parametrize("zeta", [0.0, 0.7])
def test_total_energy_balance_field_model(zeta):
    r = simulate(P7.replace(damping_ratio=zeta), WF7, 0.4, dt_out=1e-4)
    stored = r.E_mech - r.E_mech[0] + r.U - r.U[0]
    lost = r.E_load + r.E_damping + r.E_impact
    assert np.max(np.abs(r.W_applied - stored - lost)) < 1e-6 * np.max(r.W_applied)
    # the electrostatic force's work is paid from the field energy and the load: -W_e = dU + E_R
    assert np.max(np.abs(-r.W_electric - (r.U - r.U[0]) - r.E_load)) < 1e-5 * np.max(r.E_load) + 1e-15


def test_steady_state_charge_and_cycle_energy(fig7_run):
    r = fig7_run
    s = fig7_summary(r)
    assert s["net_charge_per_cycle_C"] < 1e-9 * P7.charge_scale
    per = WF7.period
    e = r.cycle_values("E_load")
    w = r.cycle_values("W_applied")
    lost = r.cycle_values("E_damping") + r.cycle_values("E_impact") + e
    # over a settled cycle all work done by the applied force ends up as heat
    assert np.diff(w)[-1] == pytest.approx(np.diff(lost)[-1], rel=1e-5)
    assert s["average_power_W"] == pytest.approx(np.diff(e)[-1] / per, rel=1e-6)


# --- figure of merit and V-Q cycle ---

def test_figure_of_merit_closed_form():
    de = P7.thickness_m / P7.eps_r
    assert fom_structural(de, P7.thickness_m, P7.eps_r) == pytest.approx(0.75, rel=1e-12)
    assert fom_structural(1e6 * de, P7.thickness_m, P7.eps_r) == pytest.approx(1.0, rel=1e-5)
    fom = figure_of_merit(P7, x_max=3 * de)
    assert fom.fom_from_cycle == pytest.approx(fom.fom_closed_form, rel=1e-9)
    assert fom.fom_closed_form == pytest.approx(15 / 16, rel=1e-12)
    cm = cmeo_cycle(P7.sigma_C_per_m2, P7.area_m2, P7.thickness_m, P7.eps_r, P7.gap_m)
    assert cm.energy_J == pytest.approx(0.5 * cm.qsc_max_C * (cm.voc_max_V + cm.v_prime_max_V), rel=1e-9)


def test_vq_cycle_energy_bounded_by_cmeo(fig7_run):
    vq = vq_cycle(fig7_run)
    e = fig7_run.cycle_values("E_load")
    assert vq.energy_J == pytest.approx(np.diff(e)[-1], rel=1e-2)
    assert 0 < vq.energy_J < vq.cmeo.energy_J


# --- convergence ---

def test_tolerance_and_output_step_convergence():
    def peaks(**kw):
        s = fig7_summary(run_fig7(2, **kw))
        return np.array([s["peak_voltage_V"], s["peak_current_A"], s["voc_V"], s["isc_A"]])

    ref = peaks(options=SolverOptions(rtol=1e-10, atol=1e-12))
    loose = peaks(options=SolverOptions(rtol=1e-6, atol=1e-8))
    np.testing.assert_allclose(loose, ref, rtol=1e-4)
    fine = peaks(dt_out=1e-5)
    np.testing.assert_allclose(fine, ref, rtol=1e-3)


# --- area from the contact engine (Fig. 8) ---

def test_fig8_voc_steps_follow_area_table():
    tab = synthetic_table()
    p = fig8_params(tab)
    wf = Staircase((2e4, 6e4, 1.5e5), 2.0)
    r = simulate(p, wf, wf.duration, dt_out=1e-4)
    v = fig8_summary(r)["voc_steps_V"]
    a = tab(np.array(wf.amplitudes_Pa))
    np.testing.assert_allclose(np.array(v) / v[-1], a / a[-1], rtol=1e-3)
    assert r.area[0] == 0  # uncharged until first contact


def test_run_fig8_with_table_and_area_memory():
    r = run_fig8(synthetic_table(), dt_out=5e-4)
    s = fig8_summary(r)
    assert len(s["voc_steps_V"]) == 15 and np.all(np.diff(s["voc_steps_V"]) > 0)
    down = Staircase((1.5e5, 2e4), 2.0)
    rmax = simulate(fig8_params(synthetic_table()), down, down.duration, dt_out=1e-4)
    rrel = simulate(fig8_params(synthetic_table(), area_memory="release"), down, down.duration, dt_out=1e-4)
    vmax, vrel = fig8_summary(rmax)["voc_steps_V"], fig8_summary(rrel)["voc_steps_V"]
    assert vmax[1] == pytest.approx(vmax[0], rel=1e-3)  # charges persist
    assert vrel[1] < 0.6 * vrel[0]


def test_resistance_sweep_has_interior_optimum():
    sw = resistance_sweep(P7, WF7, [1e5, 5e6, 1e9], cycles=2)
    assert sw.optimum_ohm == 5e6 and not sw.optimum_at_edge
    assert np.all(sw.energy_per_cycle_J > 0)
    assert sw.energy_per_cycle_J.max() < figure_of_merit(P7).energy_max_J


# --- parameters, waveforms, results ---

@pytest.mark.parametrize("change, word", [({"mass_kg": -1.0}, "mass_kg"), ({"load_ohm": -5.0}, "load_ohm"),
                                          ({"force_model": "magic"}, "force_model"),
                                          ({"damping_ratio": float("nan")}, "damping_ratio")])
def test_params_validation_names_bad_value(change, word):
    with pytest.raises(TengsimError, match=word):
        P7.replace(**change)


def test_waveforms():
    sq = SquareWave(1.0, 5.0)
    np.testing.assert_array_equal(sq([0.0, 0.099, 0.1, 0.19, 0.2]), [1, 1, 0, 0, 1])
    np.testing.assert_allclose(sq.breakpoints(0, 0.45), [0.1, 0.2, 0.3, 0.4])
    st = Staircase.linear(1e4, 1.5e5, 1e4, 2.0)
    assert len(st.amplitudes_Pa) == 15 and st.amplitudes_Pa[-1] == pytest.approx(1.5e5)
    assert st(0.6) == pytest.approx(2e4) and st(0.8) == 0 and st(100.0) == 0
    tw = TableWaveform([0, 1, 2], [0, 10, 0], interp="step")
    assert tw(1.5) == 10 and tw(0.5) == 0
    assert parse_waveform({"kind": "sine", "amplitude_Pa": 1, "frequency_Hz": 2}).period == 0.5
    with pytest.raises(TengsimError, match="frequency_Hz"):
        SquareWave(1.0, -1.0)
    with pytest.raises(TengsimError, match="strictly increasing"):
        AreaTable([0, 0], [0, 1])


def test_result_dataset_and_csv(tmp_path, fig7_run):
    ds = fig7_run.to_dataset()
    assert ds["V"].attrs["units"] == "V" and "params" in ds.attrs
    path = tmp_path / "r.csv"
    fig7_run.write_csv(path)
    lines = path.read_text().splitlines()
    head = [ln for ln in lines if not ln.startswith("#")][0].split(",")
    assert head[:6] == ["t", "y", "ydot", "Q", "I", "V"] and "contact" in head
    assert any(ln.startswith("# params:") for ln in lines)


def test_constant_area_fraction_scales_voc():
    r = simulate(P7.replace(area=ConstantArea(0.5), load_ohm=math.inf), WF7, 0.01)
    assert r.V_oc[0] == pytest.approx(0.5 * P7.voltage_scale, rel=1e-12)
