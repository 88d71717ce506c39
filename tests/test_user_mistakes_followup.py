"""Regressions of the realistic-mistakes fuzz strategy's findings (tests/fuzz_mistakes.py),
each with its exact call: a user's mistake raises an error naming the argument, or warns
(UnitWarning), never gives a silently different answer."""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd
import pytest
from scipy.spatial.transform import Rotation

import atomnav as an

DEG = np.pi / 180


def _unit_warnings(call):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = call()
    return out, [w.message for w in caught if issubclass(w.category, an.UnitWarning)]


@pytest.fixture(scope="module")
def traj():
    return an.trajectory.sinusoidal(10.0, rate_hz=100.0)


def test_euler_dcm_in_degrees_warns_and_the_factor_restores_the_si_call():
    euler = np.array([[0.1, -0.2, 1.5], [0.05, 0.1, -2.5]])
    _, caught = _unit_warnings(lambda: an.astro.euler_dcm(np.asarray(euler, dtype=float) * 57.29577951308232))
    assert [(w.parameter, w.unit) for w in caught] == [("beta", "deg")]
    # the factor converts back to the SI call
    fixed = an.astro.euler_dcm(np.asarray(euler, dtype=float) * 57.29577951308232 * caught[0].factor)
    assert np.allclose(fixed, an.astro.euler_dcm(euler), atol=1e-12)


def test_gnss_simulate_latitude_in_degrees_is_an_error_and_longitude_warns(traj):
    eph = an.gnss.ephemeris.Ephemerides.nominal(0.0, 600.0)
    t = np.arange(0.0, 10.0, 1.0)
    lla = np.tile(traj.lla[0], (len(t), 1))
    lat_deg = np.array(lla, dtype=float)
    lat_deg[:, 0] = lat_deg[:, 0] * 57.29577951308232
    with pytest.raises(an.InputError) as e:
        an.gnss.observations.simulate(eph, t, lat_deg, np.zeros((10, 3)), seed=1)
    assert (e.value.parameter, e.value.index) == ("lla", 0)
    lon_deg = np.array(lla, dtype=float)
    lon_deg[:, 1] = lon_deg[:, 1] * 57.29577951308232
    _, caught = _unit_warnings(lambda: an.gnss.observations.simulate(eph, t, lon_deg, np.zeros((10, 3)), seed=1))
    assert [(w.parameter, w.unit) for w in caught] == [("lla", "deg")]


def test_spp_with_a_naive_datetime_outside_the_ephemerides_names_obs():
    eph = an.gnss.ephemeris.Ephemerides.nominal(0.0, 600.0)
    t = np.arange(0.0, 10.0, 1.0)
    lla = np.tile([np.deg2rad(55.75), np.deg2rad(37.6), 200.0], (len(t), 1))
    obs = an.gnss.observations.simulate(eph, t, lla, np.zeros((10, 3)), seed=1)
    # 2024-01-01 is a Monday: GPS time (from Sunday 2023-12-31) 86400 s, a day after the sets
    obs = obs.assign(time_s=pd.Timestamp("2024-01-01 00:00:00") + pd.to_timedelta(obs["time_s"], unit="s"))
    with pytest.raises(an.InputError, match="does not overlap the ephemerides") as e:
        an.gnss.spp.solve(eph, obs)
    assert e.value.parameter == "obs"


def test_corrupt_carries_only_time_s_and_ignores_a_renamed_time_column(traj):
    ideal = traj.ideal_imu("increments")
    clean = an.imu.corrupt(ideal, errors="tactical", dt=0.01, kind="increments", seed=7)
    renamed = an.imu.corrupt(ideal.rename(columns={"time_s": "time"}), errors="tactical", dt=0.01, kind="increments", seed=7)
    assert "time_s" not in renamed.columns and "time" not in renamed.columns
    pd.testing.assert_frame_equal(renamed, clean.drop(columns=["time_s"]))


def test_fit_allan_table_with_na_in_tau_names_the_table():
    omega = an.noise.synth.model_b(seed=3, n=2048, tau0=1.0)
    table = an.noise.allan.allan_variance(omega, tau0=1.0)
    table = table.astype({c: "Float64" for c in ["tau_s", "var", "dev", "edf", "dev_lo", "dev_hi"]})
    table.loc[table.index[5], "tau_s"] = pd.NA
    with pytest.raises(an.InputError, match="tau_s") as e:
        an.noise.allan.fit_allan_table(table, n_samples=2048)
    assert (e.value.parameter, e.value.index) == ("table", 5)


def test_integrate_static_increments_in_degrees_warns_on_a_short_tactical_record():
    still = an.trajectory.stationary(10.0, rate_hz=100.0)
    imu = an.imu.corrupt(still.ideal_imu("increments"), errors="tactical", dt=0.01, kind="increments", seed=7)
    cols = ["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]
    # the oracle: the record's mean rate in °/s lies beyond the 15 % band about Earth rate
    # (its noise moves a 10 s mean), so only the noise-aware band sees it
    mean = np.linalg.norm((imu[cols].to_numpy() / 0.01).mean(axis=0)) / DEG
    assert abs(mean / (7.292115e-5 / DEG) - 1) > 0.15
    in_deg = imu.assign(**{c: imu[c] * 57.29577951308232 for c in cols})
    _, caught = _unit_warnings(lambda: an.strapdown.integrate(in_deg, **still.initial_state()))
    assert [(w.parameter, w.unit) for w in caught] == [("imu", "deg/s")]
    _, silent = _unit_warnings(lambda: an.strapdown.integrate(imu, **still.initial_state()))
    assert silent == []


@pytest.mark.parametrize("time", ["naive", "tz", "timedelta"])
def test_trajectory_constructor_reads_time_types_like_from_dataframe(traj, time):
    td = pd.to_timedelta(traj.df["time_s"], unit="s")
    column = {"naive": pd.Timestamp("2024-01-01") + td, "tz": pd.Timestamp("2024-01-01", tz="UTC") + td, "timedelta": td}[time]
    got = an.trajectory.Trajectory(traj.df.assign(time_s=column))
    assert np.array_equal(got.time, traj.df["time_s"].to_numpy())  # the seconds the table was built from
    assert (got.epoch is None) == (time == "timedelta")
    ref = an.trajectory.Trajectory.from_dataframe(traj.df.assign(time_s=column))
    assert np.array_equal(got.time, ref.time) and got.epoch == ref.epoch


def test_trajectory_constructor_reads_na_as_nan(traj):
    cols = [c for c in traj.df.columns]
    na = traj.df.astype({c: "Float64" for c in cols})
    na.loc[na.index[5], "vn_mps"] = pd.NA
    nan = traj.df.copy()
    nan.loc[nan.index[5], "vn_mps"] = np.nan
    a, b = an.trajectory.Trajectory(na), an.trajectory.Trajectory(nan)
    assert np.array_equal(a.vel_ned, b.vel_ned, equal_nan=True) and np.isnan(a.vel_ned[5, 0])
    # a missing latitude is rejected in both, at its row
    na.loc[na.index[5], "lat_rad"] = pd.NA
    nan.loc[nan.index[5], "lat_rad"] = np.nan
    for df in (na, nan):
        with pytest.raises(an.InputError) as e:
            an.trajectory.Trajectory(df)
        assert (e.value.parameter, e.value.index) == ("df", 5)


def test_trajectory_latitude_in_degrees_is_an_error_and_longitude_warns(traj):
    df = traj.df
    with pytest.raises(an.InputError, match="latitude") as e:
        an.trajectory.Trajectory(df.assign(lat_rad=df["lat_rad"] * 57.29577951308232))
    assert (e.value.parameter, e.value.index) == ("df", 0)
    _, caught = _unit_warnings(lambda: an.trajectory.Trajectory(df.assign(lon_rad=df["lon_rad"] * 57.29577951308232)))
    assert [(w.parameter, w.unit) for w in caught] == [("df", "deg")]


def test_nav_table_latitude_in_degrees_is_an_error_and_longitude_warns(traj):
    time, lla, vel_ned, q_nb = traj.time, traj.lla, traj.vel_ned, traj.q_nb
    lat = np.array(lla, dtype=float)
    lat[:, 0] = lat[:, 0] * 57.29577951308232
    with pytest.raises(an.InputError) as e:
        an.trajectory.nav_table(time, lat, vel_ned, q_nb)
    assert (e.value.parameter, e.value.index) == ("lla", 0)
    lon = np.array(lla, dtype=float)
    lon[:, 1] = lon[:, 1] * 57.29577951308232
    _, caught = _unit_warnings(lambda: an.trajectory.nav_table(time, lon, vel_ned, q_nb))
    assert [(w.parameter, w.unit) for w in caught] == [("lla", "deg")]


def test_trajectory_errors_with_longitude_in_degrees_warns(traj):
    ideal = traj.ideal_imu("increments")
    nav = an.strapdown.integrate(ideal, **traj.initial_state())
    _, caught = _unit_warnings(lambda: traj.errors(nav.assign(lon_rad=nav["lon_rad"] * 57.29577951308232)))
    assert [(w.parameter, w.unit) for w in caught] == [("nav", "deg")]


@pytest.mark.parametrize("lost", ["rename", "drop"])
def test_from_dataframe_with_a_partial_quaternion_names_the_missing_column(traj, lost):
    df = traj.df.rename(columns={"qw": "QW"}) if lost == "rename" else traj.df.drop(columns=["qw"])
    with pytest.raises(an.InputError, match=r"\['qw'\]") as e:
        an.trajectory.Trajectory.from_dataframe(df)
    assert e.value.parameter == "df"
    # no quaternion column at all still reads the Euler angles (scipy's z-y-x: yaw, pitch, roll)
    euler = an.trajectory.Trajectory.from_dataframe(traj.df.drop(columns=["qw", "qx", "qy", "qz"]))
    want = Rotation.from_euler("ZYX", traj.df[["yaw_rad", "pitch_rad", "roll_rad"]].to_numpy()).as_quat(scalar_first=True)
    got = euler.q_nb * np.sign(euler.q_nb[:, :1] * want[:, :1])
    assert np.allclose(got, want, atol=1e-12)


def test_acceleration_noise_overflow_names_the_input_and_a_bool_is_a_type_error():
    with pytest.raises(TypeError, match="T"):
        an.cai.acceleration_noise(sigma_phi=1, T=True, k=5e-324)
    with pytest.raises(an.InputError) as e:
        an.cai.acceleration_noise(sigma_phi=1, T=1.0, k=5e-324)  # 1/(5e-324 · 1²) overflows
    assert e.value.parameter == "T"
    assert an.cai.acceleration_noise(sigma_phi=0.01, T=0.1, k=1.61e7) == pytest.approx(0.01 / (1.61e7 * 0.1**2), rel=1e-15)


# ---- findings of the CI fuzz share (seed 20261202) after the table and height changes ----

def test_schuler_test_names_h_for_a_height_out_of_range():
    # was an InputError naming 'lla', which schuler_test does not take
    with pytest.raises(an.InputError, match="height 9.22.*e\\+18 m is outside") as e:
        an.diagnostics.schuler_test(v0=3.5, hours=3.8, h=9223372036854775808)
    assert e.value.parameter == "h"


@pytest.mark.parametrize("bad", [0.5, an.filter.Layout()])
def test_an_observation_table_that_is_no_dataframe_is_a_type_error(bad, tmp_path):
    from atomnav.gnss import rinex  # needs georinex, a test dependency

    # was AttributeError: 'float' object has no attribute 'iloc'
    with pytest.raises(TypeError, match="obs: expected DataFrame"):
        an.gnss.observations.obs_arrays(bad)
    with pytest.raises(TypeError, match="obs: expected DataFrame"):
        rinex.write_obs(tmp_path / "x.obs", bad)
