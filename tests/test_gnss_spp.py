"""Single-point positioning: the τ_GPS experiment of the thesis (spec §4 rows 4–6), DOP
against a numpy evaluation, and bad input."""

import numpy as np
import pandas as pd
import pytest

import atomnav as an
import atomnav.gnss as g

LLA = np.array([np.radians(55.75), np.radians(37.6), 200.0])
TAU = -340e-9


def _pick(obs, n_gps=8, n_glo=4):
    """The n highest GPS and GLONASS satellites of every epoch."""
    o = obs.sort_values(["time_s", "elevation_rad"], ascending=[True, False])
    gps = o[o.sat.str[0] == "G"].groupby("time_s").head(n_gps)
    glo = o[o.sat.str[0] == "R"].groupby("time_s").head(n_glo)
    return pd.concat([gps, glo]).sort_values(["time_s", "sat"]).reset_index(drop=True)


@pytest.fixture(scope="module")
def experiment():
    t = np.arange(0.0, 86400.0, 600.0)          # every 10 min for 24 h
    eph = g.Ephemerides.nominal(0.0, 86400.0, tau_gps=TAU, seed=1)
    obs = g.simulate(eph, t, np.tile(LLA, (len(t), 1)), np.zeros((len(t), 3)), tau_gps=TAU, clock_bias=1e-4,
                     clock_drift=1e-9, seed=2)
    return eph, _pick(obs)


def test_tau_gps_is_recovered_and_needed(experiment):
    eph, obs = experiment
    n = obs.groupby("time_s").size()
    assert n.min() >= 10 and (obs[obs.sat.str[0] == "R"].groupby("time_s").size() >= 3).all()
    truth = an.earth.lla_to_ecef(LLA)
    # the thesis's least squares, without fault exclusion (without τ every GLONASS
    # residual would be excluded as a fault)
    joint = g.solve(eph, obs, fault_detection=False).epochs
    no_tau = g.solve(eph, obs, use_tau=False, fault_detection=False).epochs
    gps = g.solve(eph, obs[obs.sat.str[0] == "G"], fault_detection=False).epochs
    tau = joint["tau_gps_s"].to_numpy()
    sigma_mean = np.sqrt(np.mean(joint["sigma_tau_gps_s"] ** 2) / len(tau))
    assert abs(tau.mean() - TAU) < 3 * sigma_mean          # within 3σ of its own uncertainty
    assert abs(tau.mean() - TAU) < 25e-9
    assert np.all(np.abs(tau - TAU) < 40e-9)                # every epoch (spec §4 row 4)
    m_joint, m_gps, m_no = (s["residual_metric_m"].mean() for s in (joint, gps, no_tau))
    assert m_joint < 2 * m_gps
    assert m_no > 10 * m_joint
    bias = np.linalg.norm((no_tau[["x_m", "y_m", "z_m"]].to_numpy() - truth).mean(axis=0))
    assert bias > 30.0                                      # tens of metres (≈ c·340 ns = 102 m)
    assert np.linalg.norm((joint[["x_m", "y_m", "z_m"]].to_numpy() - truth).mean(axis=0)) < 2.0
    assert np.isnan(gps["tau_gps_s"]).all() and (gps["n_unknowns"] == 4).all()


def test_doppler_velocity_and_clock_drift(experiment):
    eph, obs = experiment
    s = g.solve(eph, obs.iloc[:40]).epochs
    assert np.all(np.abs(s[["vx_mps", "vy_mps", "vz_mps"]].to_numpy()) < 0.2)
    assert np.all(np.abs(s["clock_drift_mps"] - 299792458.0 * 1e-9) < 0.2)


def test_dop_matches_numpy_geometry(experiment):
    eph, obs = experiment
    ep = obs[obs.time_s == 0.0]
    gps = ep[ep.sat.str[0] == "G"]
    s = g.solve(eph, gps).epochs
    rows = []
    for sat in gps.sat:
        a = eph.look_angles(sat, [0.0], LLA).to_numpy()[0]
        el, az = a
        rows.append([-np.cos(el) * np.cos(az), -np.cos(el) * np.sin(az), np.sin(el), 1.0])
    q = np.linalg.inv(np.array(rows).T @ np.array(rows))
    assert abs(s["pdop"][0] - np.sqrt(np.trace(q[:3, :3]))) < 1e-3
    assert abs(s["hdop"][0] - np.sqrt(q[0, 0] + q[1, 1])) < 1e-3
    assert abs(s["gdop"][0] - np.sqrt(np.trace(q))) < 1e-3


def test_an_epoch_with_too_few_satellites_is_reported_not_solved(experiment):
    eph, obs = experiment
    ep = obs[obs.time_s == 0.0]
    few = pd.concat([ep[ep.sat.str[0] == "G"].head(3), ep[ep.sat.str[0] == "R"].head(1)])
    later = obs[obs.time_s == obs.time_s.unique()[1]]
    r = g.solve(eph, pd.concat([few, later]))
    assert r.epochs["time_s"].tolist() == [later.time_s.iloc[0]]
    first = r.satellites[r.satellites.time_s == 0.0]
    assert first["sat"].tolist() == few["sat"].tolist() and (first["excluded"] == "too_few_satellites").all()
    assert first["residual_m"].isna().all() and not first["used"].any()
    assert r.exclusions()["too_few_satellites"] == 4


def test_duplicated_satellite_is_rejected(experiment):
    eph, obs = experiment
    ep = obs[obs.time_s == 0.0]
    dup = pd.concat([ep, ep.iloc[[2]]])
    with pytest.raises(ValueError, match=f"duplicated satellite {ep.sat.iloc[2]} at index {len(ep)}"):
        g.solve(eph, dup)


def test_channel_mismatch_and_unknown_channel_are_rejected(experiment):
    eph, obs = experiment
    ep = obs[obs.time_s == 0.0].reset_index(drop=True)
    i = int(np.nonzero(ep.sat.str[0] == "R")[0][0])
    bad = ep.copy()
    bad.loc[i, "channel"] = 9
    with pytest.raises(ValueError, match=f"unknown GLONASS frequency channel 9 at index {i}"):
        g.solve(eph, bad)
    k = eph.channel(ep.sat[i])
    bad.loc[i, "channel"] = k + 1 if k < 6 else k - 1
    with pytest.raises(ValueError, match="but the ephemeris says"):
        g.solve(eph, bad)


def test_ephemeris_older_than_its_validity_is_rejected():
    eph = g.Ephemerides.nominal(0.0, 3600.0)
    obs = g.simulate(eph, [600.0], [LLA], [[0, 0, 0]])
    late = obs.assign(time_s=30000.0)
    with pytest.raises(ValueError, match="obs: G.. at t = 30000 s: nearest set is .* s away .*: the time does not overlap the ephemerides"):
        g.solve(eph, late)  # no satellite of the epoch is covered
