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


# --- independent geometry (numpy): light time, Earth rotation during flight, ENU axes ---

C = 299792458.0
OMEGA_E = 7.2921151467e-5        # WGS-84 Earth rate used by GPS (IS-GPS-200), rad/s


def _signal(eph, sat, t_rx, r, tau=0.0):
    """Satellite position in the ECEF frame of reception, its clock (s) and the range
    (m) of the signal received at GPS time ``t_rx`` at ECEF ``r``: the transmit time
    t_rx − ρ/c iterated, the satellite rotated by Ω_E·ρ/c about z (Sagnac)."""
    rho = 0.0
    for _ in range(10):
        s = eph.state(sat, [t_rx - rho / C], tau).to_numpy()[0]
        c, sn = np.cos(OMEGA_E * rho / C), np.sin(OMEGA_E * rho / C)
        rs = np.array([[c, sn, 0.0], [-sn, c, 0.0], [0.0, 0.0, 1.0]]) @ s[:3]
        new = np.linalg.norm(rs - r)
        done = abs(new - rho) < 1e-9
        rho = new
        if done:
            break
    return rs, s[6], rho


def _enu_axes(lat, lon):
    """Rows: east, north, up unit vectors in ECEF."""
    return np.array([[-np.sin(lon), np.cos(lon), 0.0],
                     [-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)],
                     [np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)]])


def _epoch_geometry(eph, row, sats):
    """Unit lines of sight (ECEF), elevations (rad), satellite clocks (s) and ranges (m)
    of ``sats`` at an SPP solution row."""
    r = row[["x_m", "y_m", "z_m"]].to_numpy(float)
    tau = 0.0 if np.isnan(row["tau_gps_s"]) else row["tau_gps_s"]
    t_rx = row["time_s"] - row["clock_m"] / C
    up = _enu_axes(row["lat_rad"], row["lon_rad"])[2]
    out = [_signal(eph, s, t_rx, r, tau) for s in sats]
    los = np.array([(rs - r) / rho for rs, _, rho in out])
    return los, np.arcsin(los @ up), np.array([o[1] for o in out]), np.array([o[2] for o in out])


@pytest.fixture(scope="module")
def southern():
    """GPS + GLONASS at 33.9°S, 18.4°E (not the thesis's Moscow), time of week 302400 s,
    no atmosphere (so the test's prediction needs only range and clocks), τ_GPS −200 ns."""
    t = np.arange(302400.0, 302400.0 + 1800.0, 300.0)
    lla = np.array([np.radians(-33.9), np.radians(18.4), 50.0])
    eph = g.Ephemerides.nominal(302000.0, 305000.0, tau_gps=-2e-7, seed=4)
    opts = g.GnssOptions(iono=False, tropo=False, sigma_code=2.0, sigma_code_glonass=4.0)
    obs = g.simulate(eph, t, np.tile(lla, (len(t), 1)), np.zeros((len(t), 3)), opts, tau_gps=-2e-7, clock_bias=3e-4,
                     clock_drift=2e-9, seed=7)
    return eph, obs, opts


@pytest.mark.parametrize("systems", ["GR", "G"])
def test_dop_is_the_unweighted_enu_geometry_of_the_used_satellites(southern, systems):
    """DOP against (GᵀG)⁻¹ built here: rows (−u_ENU, 1[, 1 on GLONASS rows for τ_GPS])."""
    eph, obs, opts = southern
    obs = obs[obs.sat.str[0].isin(list(systems))]
    r = g.solve(eph, obs, opts, elevation_weight=True, fault_detection=False)
    assert len(r.epochs) == 6
    for k, row in r.epochs.iterrows():
        used = r.satellites[(r.satellites.time_s == row.time_s) & r.satellites.used]
        los, _, _, _ = _epoch_geometry(eph, row, used.sat)
        enu = los @ _enu_axes(row.lat_rad, row.lon_rad).T
        glo = (used.sat.str[0] == "R").to_numpy(float)
        G = np.column_stack([-enu, np.ones(len(enu))] + ([glo] if systems == "GR" else []))
        q = np.linalg.inv(G.T @ G)
        expect = dict(hdop=np.sqrt(q[0, 0] + q[1, 1]), vdop=np.sqrt(q[2, 2]), pdop=np.sqrt(np.trace(q[:3, :3])),
                      tdop=np.sqrt(q[3, 3]), gdop=np.sqrt(np.trace(q[:4, :4])))
        for name, v in expect.items():
            assert abs(row[name] / v - 1.0) < 1e-9, (name, row[name], v)


def test_covariance_is_the_weighted_normal_inverse(southern):
    """Covariance against (GᵀWG)⁻¹ built here (G in ECEF, W = 1/σ² with σ/sin E and the
    GLONASS σ); the τ_GPS row in s. The solver's exact rows differ from unit vectors by the
    light-time factor κ (|κ − 1| < 1e-5), hence the 1e-4 tolerance."""
    eph, obs, opts = southern
    r = g.solve(eph, obs, opts, elevation_weight=True, fault_detection=False)
    assert r.covariance.shape == (len(r.epochs), 5, 5)
    assert list(an.gnss.spp.COVARIANCE_STATES) == ["x_m", "y_m", "z_m", "clock_m", "tau_gps_s"]
    for k, row in r.epochs.iterrows():
        used = r.satellites[(r.satellites.time_s == row.time_s) & r.satellites.used]
        los, el, _, _ = _epoch_geometry(eph, row, used.sat)
        glo = (used.sat.str[0] == "R").to_numpy()
        sigma = np.where(glo, 4.0, 2.0) / np.maximum(np.sin(el), 0.05)
        np.testing.assert_allclose(used.sigma_m, sigma, rtol=1e-9)
        G = np.column_stack([-los, np.ones(len(los)), glo.astype(float)])
        p = np.linalg.inv(G.T @ (G / sigma[:, None] ** 2))
        p[4, :] /= C
        p[:, 4] /= C
        scale = np.sqrt(np.outer(np.diag(p), np.diag(p)))
        assert np.max(np.abs(r.covariance[k] - p) / scale) < 1e-4
        enu = _enu_axes(row.lat_rad, row.lon_rad)
        p_enu = enu @ p[:3, :3] @ enu.T
        got = row[["sigma_e_m", "sigma_n_m", "sigma_u_m", "sigma_x_m", "sigma_y_m", "sigma_z_m", "sigma_clock_m",
                   "sigma_tau_gps_s"]].to_numpy(float)
        np.testing.assert_allclose(got, np.sqrt(np.r_[np.diag(p_enu), np.diag(p)]), rtol=1e-4)
    gps = g.solve(eph, obs[obs.sat.str[0] == "G"], opts, fault_detection=False)
    assert np.isnan(gps.covariance[:, 4, :]).all() and np.isfinite(gps.covariance[:, :4, :4]).all()


def test_residuals_are_measured_less_predicted_code_at_the_solution(southern):
    """Post-fit residual of every satellite (used or not) = code − (ρ + c·δt_r − c·δt^s
    [+ c·τ_GPS on GLONASS]) at the reported solution, predicted here; and Σ(r/σ)² over the
    used satellites is the reported χ². One satellite gets a 60 m fault: it is excluded,
    and its residual still reported."""
    eph, obs, opts = southern
    obs = obs.copy()
    bad = obs.index[(obs.time_s == obs.time_s.iloc[0]) & (obs.sat.str[0] == "G")][2]
    obs.loc[bad, "code_m"] += 60.0
    r = g.solve(eph, obs, opts)
    sats = r.satellites
    assert sats.loc[sats.sat == obs.sat[bad]].iloc[0].excluded == "fault"
    for _, row in r.epochs.iterrows():
        ep = sats[sats.time_s == row.time_s]
        codes = obs[obs.time_s == row.time_s].set_index("sat").loc[ep.sat, "code_m"].to_numpy()
        _, _, clk, rho = _epoch_geometry(eph, row, ep.sat)
        tau = np.where(ep.sat.str[0] == "R", C * row.tau_gps_s, 0.0)
        predicted = rho + row.clock_m - C * clk + tau
        np.testing.assert_allclose(ep.residual_m, codes - predicted, atol=1e-6)
        used = ep[ep.used]
        assert abs(((used.residual_m / used.sigma_m) ** 2).sum() / row.chi2 - 1.0) < 1e-6
    assert sats.loc[bad, "residual_m"] > 50.0


@pytest.mark.parametrize("tow", [600.0, 302400.0, 590000.0])
def test_simulated_clock_starts_at_its_bias_and_grows_by_the_drift(tow):
    """δt_r(t) = b + d·(t − t₀): at the first epoch the clock is b whatever the time of
    week (d = 3e-9 s/s would add 0.9 ms at t = 302400 s of a clock counted from the week's
    start), then grows by d·Δt. The clock is read back from the GPS code (noise σ 1 nm):
    δt_r = (P − ρ + c·δt^s)/c, ρ at the receive time t − δt_r predicted here."""
    b, d = 2.5e-4, 3e-9
    t = tow + np.array([0.0, 10.0, 1000.0])
    eph = g.Ephemerides.nominal(tow - 600.0, tow + 1600.0, glonass=False, seed=2)
    lla = np.array([np.radians(48.1), np.radians(11.6), 520.0])
    r = an.earth.lla_to_ecef(lla)
    obs = g.simulate(eph, t, np.tile(lla, (3, 1)), np.zeros((3, 3)), iono=False, tropo=False, sigma_code=1e-9,
                     sigma_rate=1e-9, clock_bias=b, clock_drift=d, seed=1)
    for tk in t:
        ep = obs[obs.time_s == tk]
        clocks = []
        for sat, code in zip(ep.sat, ep.code_m):
            dt = 0.0
            for _ in range(4):
                _, clk, rho = _signal(eph, sat, tk - dt, r)
                dt = (code - rho + C * clk) / C
            clocks.append(dt)
        assert np.ptp(clocks) < 1e-12, clocks
        assert abs(np.mean(clocks) - (b + d * (tk - t[0]))) < 1e-12, (tk, np.mean(clocks) - b)
