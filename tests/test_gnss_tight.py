"""Tightly coupled GNSS/INS on the aided-INS engine: clock invariance of the first
differences, the clock-state option, accuracy classes, satellite count, outages (spec
gnss-ins-tight §4 rows 7, 11–15), the Schuler test and bad input. The 1-h and 40-min
studies are `slow`; the default run checks reduced versions."""

import numpy as np
import pytest

import atomnav as an
from atomnav.gnss import scenarios as S
from atomnav.gnss import tight_ins

C = 299792458.0


def _pos_diff_m(a, b):
    lat = a["lat_rad"].to_numpy()
    m, n = an.earth.radii(lat)
    d = np.column_stack([(a["lat_rad"] - b["lat_rad"]) * m, (a["lon_rad"] - b["lon_rad"]) * n * np.cos(lat), a["h_m"] - b["h_m"]])
    return np.abs(d).max()


def _run(setup, obs=None, **kw):
    ins = tight_ins(setup["eph"], setup["obs"] if obs is None else obs, **{**setup["args"], **kw})
    m = setup["imu"]
    return ins.run(m["time_s"].to_numpy(), m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(),
                   m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy(), h_ref=setup["h_ref"], progress=False)


@pytest.mark.parametrize("mode", ["closed", "open"])
def test_receiver_clock_leaves_the_first_difference_solution_unchanged(mode):
    """c·δt_r(t) = c(b + d·t) is added to every code and c·d to every rate. The clock is
    kept on a 2⁻²⁷ m (7.5 nm) grid, so that adding it to a 2·10⁷ m pseudorange is exact in
    binary64: an arbitrary float would be rounded to the input's own ulp (3.7 nm), which
    no filter can undo."""
    setup = S.build(S.Scenario(duration_s=300.0, mode=mode))
    base = _run(setup, mode=mode).nav
    q = 2.0 ** 27
    for b, d in [(1e-3, 1e-6), (-3.7e-4, -2.2e-8)]:
        obs = setup["obs"].copy()
        obs["code_m"] += np.round(C * (b + d * obs["time_s"]) * q) / q
        obs["rate_mps"] += np.round(C * d * 2.0 ** 40) / 2.0 ** 40
        nav = _run(setup, obs, mode=mode).nav
        assert _pos_diff_m(nav, base) <= 1e-9


@pytest.mark.parametrize("mode", ["closed", "open"])
def test_clock_state_formulation_tracks_the_receiver_clock(mode):
    """The nominal clock bias follows the drift between epochs (engine hook
    `propagate_extra`): the bias estimate tracks c(b + d·t), which grows by 900 m over the
    run, to metres (code σ 3 m)."""
    b, d = 1e-4, 1e-8
    r = S.run("precise_closed_1h", duration_s=300.0, formulation="clock_states", clock=(b, d), mode=mode)
    e = r["errors"]
    assert np.hypot(e.dpos_n_m, e.dpos_e_m).iloc[-60:].max() < 2.0
    nav = r["result"].nav
    assert abs(nav["extra_clock[1]"].iloc[-1] - C * d) < 0.1
    late = nav.time_s > 60.0
    bias_err = nav["extra_clock[0]"][late] - C * (b + d * nav.time_s[late])
    assert np.abs(bias_err).max() < 5.0, np.abs(bias_err).max()


def _check_precise_closed(e):
    d3 = np.sqrt(e.dpos_n_m ** 2 + e.dpos_e_m ** 2 + e.dpos_d_m ** 2)
    assert d3[e.time_s > 60.0].max() < 2.0


def _check_medium(cl, ol, duration):
    lo, hi = 4.60, 32.80                      # χ²₁₅ two-sided 99 % band
    inside = ((cl.nees > lo) & (cl.nees < hi)).mean()
    assert inside >= 0.90, inside
    # open loop leaves the band for good: some 5-min window's mean NEES is above it, and
    # every later window too (a single epoch outside the band happens to any run)
    w = ol.groupby((ol.time_s // 300).astype(int)).nees.mean().to_numpy()
    above = np.nonzero(w > hi)[0]
    assert above.size and np.all(w[above[0]:] > hi) and (above[0] + 1) * 300 <= duration, w


def test_precise_closed_loop_reduced():
    _check_precise_closed(S.run("precise_closed_1h", duration_s=1200.0)["errors"])


def _max_3d(e):
    d3 = np.sqrt(e.dpos_n_m ** 2 + e.dpos_e_m ** 2 + e.dpos_d_m ** 2)
    return float(d3[e.time_s > 60.0].max())


def _check_precise_open_vs_closed(duration):
    """Issue 8: precise INS, open and closed loop both below 2 m and within 20 % of each
    other (max 3-D position error after the first minute)."""
    cl = _max_3d(S.run("precise_closed_1h", duration_s=duration)["errors"])
    ol = _max_3d(S.run("precise_open_1h", duration_s=duration)["errors"])
    assert cl < 2.0 and ol < 2.0, (ol, cl)
    assert abs(ol / cl - 1) <= 0.2, (ol, cl)
    return ol, cl


def test_precise_open_loop_equals_closed_loop_reduced():
    _check_precise_open_vs_closed(1200.0)


@pytest.mark.slow
def test_precise_open_loop_equals_closed_loop_1h():
    _check_precise_open_vs_closed(3600.0)


def test_medium_open_loop_leaves_the_nees_band_closed_loop_stays_reduced():
    cl = S.run("medium_closed_1h", duration_s=1200.0)["errors"]
    ol = S.run("medium_open_1h", duration_s=1200.0)["errors"]
    _check_medium(cl, ol, 1200.0)


@pytest.mark.slow
def test_precise_closed_loop_1h():
    _check_precise_closed(S.run("precise_closed_1h")["errors"])


@pytest.mark.slow
def test_medium_open_loop_leaves_the_nees_band_closed_loop_stays_1h():
    _check_medium(S.run("medium_closed_1h")["errors"], S.run("medium_open_1h")["errors"], 3600.0)


def _check_constellation(duration):
    res = {n: S.last_rms(S.run(f"sats_{n}", duration_s=duration)["errors"]) for n in ("all", 3, 2, 0)}
    assert res[3] <= 3 * res["all"], res
    assert res[2] > 10 * res["all"], res        # two satellites: reported, much larger
    return res


def test_three_satellites_close_to_full_constellation_40min():
    """Spec row 13's 40-min run (about 10 s). With the baro-damped vertical channel a
    20-min run is not enough for three satellites: the vertical accelerometer bias holds
    the altitude off by b_a/ω_v² (≈ 2 m for 20 µg), which two first-difference rows
    separate from the horizontal only slowly (3.07 × the full constellation at 20 min,
    2.81 × at 40 min)."""
    _check_constellation(2400.0)


def _outage(cls, minutes):
    return S.outage_summary(S.run(f"outage_{cls}_{minutes}min")["errors"], 900.0, 60.0 * minutes)


def test_precise_ins_is_insensitive_to_outage_length():
    r = {m: _outage("precise", m) for m in (1, 20)}
    assert abs(r[20]["post"] / r[1]["post"] - 1) < 0.3, r


@pytest.mark.slow
def test_precise_ins_is_insensitive_to_outage_length_all():
    r = {m: _outage("precise", m) for m in (1, 5, 10, 20)}
    assert all(abs(r[m]["post"] / r[1]["post"] - 1) < 0.3 for m in r), r


def test_coarse_ins_reconverges_after_a_5_minute_outage():
    r = _outage("coarse", 5)
    assert r["end"] > 20 * r["pre"]              # the outage really happened
    assert r["at5"] <= 2 * r["pre"], r


def test_schuler_period_of_the_stationary_ins():
    periods = an.diagnostics.schuler_test(np.radians(55.75), v0=200.0, hours=3.0, h=200.0)["periods_min"][:3]
    assert abs(np.mean(periods) / 84.4 - 1) < 0.005, periods


def test_observation_time_outside_the_imu_record_is_rejected():
    setup = S.build(S.Scenario(duration_s=60.0))
    obs = setup["obs"].copy()
    obs.loc[obs.time_s == obs.time_s.max(), "time_s"] = 500.0
    with pytest.raises(ValueError, match=r"time: the measurement at 500 s \(index \d+\) is outside the IMU span"):
        _run(setup, obs)


def test_unknown_formulation_is_rejected():
    setup = S.build(S.Scenario(duration_s=30.0))
    with pytest.raises(ValueError, match="formulation"):
        tight_ins(setup["eph"], setup["obs"], **{**setup["args"], "formulation": "double_difference"})
