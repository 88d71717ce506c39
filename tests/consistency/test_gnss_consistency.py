"""Monte Carlo consistency of single-point positioning: the σ the solver reports (from its
covariance (GᵀWG)⁻¹) against the scatter of its errors over independent noise draws, on
two programs unlike the thesis's (Demidov 2009: static at Moscow, GPS + GLONASS):

- ``static_south``: static receiver at 33.9°S, 18.4°E, GPS only, 15° mask, code σ 2 m
  drawn by the simulator (constant σ, as the solver assumes without elevation weighting);
- ``aircraft``: receiver at 9 km flying north-east at 250 m/s from 10°N, 70°W, GPS +
  GLONASS with τ_GPS estimated, elevation-weighted σ/sin E (GPS 2 m, GLONASS 4 m). The
  simulator draws a constant σ, so its observations are made with a 1 nm σ and the test
  adds Gaussian noise of exactly the solver's model σ/max(sin E, 0.05) at the true E:
  the test checks the covariance algebra, not a mismatch of noise models.

Fault detection is off (at its 0.1 % false-alarm level it would drop a few good
satellites and change the geometry of those draws). Errors are normalised epoch by epoch
by the reported σ and pooled: ratio = RMS(e/σ) per axis (east, north, up), for c·δt_r and
for τ_GPS. With N pooled values the ratio's sampling σ is about 1/√(2N).
"""

import numpy as np
import pytest

import atomnav as an
import atomnav.gnss as g

C = 299792458.0
BIAS, DRIFT, TAU = 3e-4, 3e-9, -2e-7


def _enu_axes(lat, lon):
    """Rows: east, north, up unit vectors in ECEF."""
    return np.array([[-np.sin(lon), np.cos(lon), 0.0],
                     [-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)],
                     [np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)]])


def _static_south(n_draws, n_epochs):
    t = 200000.0 + 240.0 * np.arange(n_epochs)
    lla = np.tile([np.radians(-33.9), np.radians(18.4), 50.0], (n_epochs, 1))
    eph = g.Ephemerides.nominal(t[0] - 300.0, t[-1] + 300.0, glonass=False, seed=11)
    opts = g.GnssOptions(sigma_code=2.0, elevation_weight=False, fault_detection=False, elevation_mask=0.0)
    for seed in range(n_draws):
        obs = g.simulate(eph, t, lla, np.zeros_like(lla), opts, clock_bias=BIAS, clock_drift=DRIFT, mask_deg=15.0,
                         seed=1000 + seed)
        yield g.solve(eph, obs, opts), lla, t


def _aircraft(n_draws, n_epochs):
    t = 400000.0 + 60.0 * np.arange(n_epochs)
    vel = np.array([150.0, 200.0, 0.0])                     # NED, m/s
    a = 6378137.0 + 9000.0
    lat = np.radians(10.0) + vel[0] * (t - t[0]) / a
    lon = np.radians(-70.0) + vel[1] * (t - t[0]) / (a * np.cos(lat))
    lla = np.column_stack([lat, lon, np.full(n_epochs, 9000.0)])
    eph = g.Ephemerides.nominal(t[0] - 300.0, t[-1] + 300.0, tau_gps=TAU, seed=12)
    sim = g.GnssOptions(sigma_code=1e-9, sigma_rate=1e-9)
    clean = g.simulate(eph, t, lla, np.tile(vel, (n_epochs, 1)), sim, tau_gps=TAU, clock_bias=BIAS, clock_drift=DRIFT,
                       mask_deg=10.0, seed=5)
    opts = g.GnssOptions(sigma_code=2.0, sigma_code_glonass=4.0, elevation_weight=True, fault_detection=False,
                         elevation_mask=0.0)
    sigma = np.where(clean.sat.str[0] == "R", 4.0, 2.0) / np.maximum(np.sin(clean.elevation_rad), 0.05)
    rng = np.random.default_rng(20240607)
    for _ in range(n_draws):
        obs = clean.assign(code_m=clean.code_m + sigma * rng.standard_normal(len(clean)))
        yield g.solve(eph, obs, opts), lla, t


PROGRAMS = {"static_south": _static_south, "aircraft": _aircraft}


def _ratios(program, n_draws, n_epochs):
    """RMS of error/σ per block over every draw and epoch, and the pooled count."""
    z = {k: [] for k in ("east", "north", "up", "clock", "tau")}
    for r, lla, t in PROGRAMS[program](n_draws, n_epochs):
        e = r.epochs
        assert len(e) == n_epochs and (e.n_excluded == 0).all()
        truth = an.earth.lla_to_ecef(lla)
        for k in range(n_epochs):
            rot = _enu_axes(lla[k, 0], lla[k, 1])
            err = rot @ (e[["x_m", "y_m", "z_m"]].to_numpy()[k] - truth[k])
            sig = np.sqrt(np.diag(rot @ r.covariance[k, :3, :3] @ rot.T))
            for name, v in zip(("east", "north", "up"), err / sig):
                z[name].append(v)
            z["clock"].append((e.clock_m[k] - C * (BIAS + DRIFT * (t[k] - t[0]))) / np.sqrt(r.covariance[k, 3, 3]))
            if np.isfinite(e.tau_gps_s[k]):
                z["tau"].append((e.tau_gps_s[k] - TAU) / e.sigma_tau_gps_s[k])
    return {k: float(np.sqrt(np.mean(np.square(v)))) for k, v in z.items() if v}, len(z["east"])


def _check(program, n_draws, n_epochs):
    ratios, n = _ratios(program, n_draws, n_epochs)
    assert set(ratios) >= {"east", "north", "up", "clock"} and (program != "aircraft" or "tau" in ratios)
    # [0.85, 1.15] is ≥ 3 sampling σ (1/√(2N)) for N ≥ 200 pooled values
    assert 3.0 / np.sqrt(2 * n) <= 0.15
    bad = {k: v for k, v in ratios.items() if not 0.85 <= v <= 1.15}
    assert not bad, (program, n, ratios)


@pytest.mark.parametrize("program", list(PROGRAMS))
def test_spp_sigma_matches_its_scatter(program):
    """Reduced size: 25 draws × 10 epochs = 250 pooled values per block (sampling σ of the
    ratio 0.045: the band is 3.4 σ)."""
    _check(program, 25, 10)


@pytest.mark.slow
@pytest.mark.parametrize("program", list(PROGRAMS))
def test_spp_sigma_matches_its_scatter_full(program):
    """Full size: 200 draws × 25 epochs = 5000 pooled values per block (sampling σ 0.01)."""
    _check(program, 200, 25)


# --- the tightly coupled GNSS/INS filter (Demidov 2009's MOVE program, scenarios.build) ---


def _tight_nees(runs, duration, motion):
    """Run-averaged NEES of position, velocity and attitude from the full covariance the
    filter returns, over ``runs`` seeds (each draws its IMU errors from the preset's model,
    the initial error from P₀, the satellite clocks and the code/rate noise)."""
    from atomnav.gnss import scenarios as S

    nees = []
    for seed in range(runs):
        setup = S.build(S.Scenario("precise", motion=motion, duration_s=duration, seed=seed))
        ins = g.tight_ins(setup["eph"], setup["obs"], **setup["args"])
        m = setup["imu"]
        res = ins.run(m["time_s"].to_numpy(), m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(),
                      m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy(), h_ref=setup["h_ref"], chunk_s=300.0,
                      progress=False, covariance=True)
        nees.append(res.nees(setup["trajectory"])["nees"].to_numpy())
    return np.mean(nees, axis=0)


def _check_tight(runs, duration, motion):
    nees = _tight_nees(runs, duration, motion)
    lo, hi = an.filter.chi2_band(9, runs)
    inside = np.mean((nees >= lo) & (nees <= hi))
    assert inside >= 0.90, (motion, inside, nees.mean(), lo, hi)


def test_tight_filter_nees_50_runs_reduced():
    """50 runs of 60 s of the drive: the run-averaged NEES (9 states) inside the χ² 95 %
    band at ≥ 90 % of the epochs."""
    _check_tight(50, 60.0, "MOVE")


@pytest.mark.slow
def test_tight_filter_nees_50_runs_full():
    """50 runs of 600 s of the drive."""
    _check_tight(50, 600.0, "MOVE")


@pytest.mark.slow
def test_tight_filter_is_conservative_not_optimistic_when_stationary():
    """Stationary 600 s, 50 runs: measured 83 % of the epochs inside the band and every
    other one below it (run-mean NEES 8.40 for 9 states) — the covariance is conservative,
    as tight_ins's docstring states; it must never be optimistic."""
    nees = _tight_nees(50, 600.0, "STAT")
    lo, hi = an.filter.chi2_band(9, 50)
    assert np.mean(nees > hi) <= 0.05, np.mean(nees > hi)
    assert np.mean((nees >= lo) & (nees <= hi)) >= 0.75 and nees.mean() <= 9.0, nees.mean()
