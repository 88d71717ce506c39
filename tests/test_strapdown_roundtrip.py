"""Issue 2 acceptance: an ideal IMU from a sinusoidal trajectory at 100 Hz, integrated back
by the strapdown, reproduces the trajectory."""

import numpy as np
import pandas as pd
import pytest

import atomnav as an


def _run(traj, kind, **kw):
    imu = traj.ideal_imu(kind)
    nav = an.strapdown.integrate(imu, **traj.initial_state(), kind=kind, **kw)
    if kind == "increments":
        nav = pd.concat([traj.df.iloc[:1], nav], ignore_index=True)
    return traj.errors(nav)


@pytest.fixture(scope="module")
def ten_minutes():
    return an.trajectory.sinusoidal(600.0, rate_hz=100.0)


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_ten_minutes_free_vertical(ten_minutes, kind):
    err = _run(ten_minutes, kind)
    last = err.iloc[-1]
    pos = np.linalg.norm(last[["dpos_n_m", "dpos_e_m", "dpos_d_m"]])
    att = np.linalg.norm(last[["psi_n_rad", "psi_e_rad", "psi_d_rad"]])
    assert pos < 0.05, f"{kind}: 3-D position error {pos} m after 10 min"
    assert att < 1e-6, f"{kind}: attitude error {att} rad after 10 min"


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_one_hour_with_height_held(kind):
    traj = an.trajectory.sinusoidal(3600.0, rate_hz=100.0)
    h_ref = traj.df["h_m"].to_numpy()
    if kind == "increments":
        h_ref = h_ref[1:]
    err = _run(traj, kind, vertical="damped", h_ref=h_ref)
    horiz = np.hypot(err["dpos_n_m"], err["dpos_e_m"]).max()
    assert horiz < 0.05, f"{kind}: horizontal error {horiz} m within 1 h"


@pytest.mark.parametrize("kind", ["rates", "increments"])
@pytest.mark.parametrize("chunk", [777, 4099])
def test_streaming_equals_batch(ten_minutes, kind, chunk):
    """Chunks that do not line up with the core's 4096-row pipeline blocks give the batch
    result bit for bit (the coning/sculling history and the rate priming carry over)."""
    imu = ten_minutes.ideal_imu(kind).iloc[:10_000]
    batch = an.strapdown.integrate(imu, **ten_minutes.initial_state(), kind=kind)
    sd = an.strapdown.Strapdown(**ten_minutes.initial_state(), kind=kind)
    chunks = pd.concat([sd.run(imu.iloc[i:i + chunk]) for i in range(0, len(imu), chunk)], ignore_index=True)
    np.testing.assert_array_equal(batch.to_numpy(), chunks.to_numpy())


def test_integrate_in_chunks_equals_one_call(ten_minutes, monkeypatch):
    """`integrate` fills one table chunk by chunk (`CHUNK` rows per call into Rust): the
    result does not depend on the chunk size."""
    imu = ten_minutes.ideal_imu("increments").iloc[:10_000]
    whole = an.strapdown.integrate(imu, **ten_minutes.initial_state())
    monkeypatch.setattr(an.strapdown, "CHUNK", 3001)
    chunked = an.strapdown.integrate(imu, **ten_minutes.initial_state(), progress=True)
    np.testing.assert_array_equal(whole.to_numpy(), chunked.to_numpy())


def test_trajectory_csv_round_trip(tmp_path, ten_minutes):
    path = ten_minutes.to_csv(tmp_path / "traj.csv")
    back = an.trajectory.Trajectory.from_csv(path)
    np.testing.assert_allclose(back.df.to_numpy(), ten_minutes.df.to_numpy(), rtol=0, atol=1e-12)
    euler_only = ten_minutes.df.drop(columns=["qw", "qx", "qy", "qz"])
    back2 = an.trajectory.Trajectory.from_dataframe(euler_only)
    np.testing.assert_allclose(back2.q_nb, ten_minutes.q_nb, atol=1e-12)
    with pytest.raises(ValueError, match="no motion model"):
        back.ideal_imu()


def test_ideal_specific_force_at_rest_is_minus_gravity():
    """Independent check of the IMU generator: at rest, level, heading 0, the
    accelerometer reads −γ on body z and the gyro reads Earth rate Ω(cos φ, 0, −sin φ)."""
    lat = np.deg2rad(40.0)
    traj = an.trajectory.stationary(1.0, 10.0, origin=(lat, 0.3, 100.0))
    imu = traj.ideal_imu("rates")
    g = an.earth.gravity(lat, 100.0)
    om = an.earth.ellipsoid()["omega"]
    np.testing.assert_allclose(imu[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy()[0], [0, 0, -g], atol=1e-12)
    np.testing.assert_allclose(imu[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]].to_numpy()[0], [om * np.cos(lat), 0, -om * np.sin(lat)], atol=1e-18)


def test_increments_integrate_rates():
    """Increments equal the integral of the rates (Simpson on a 10x finer rate grid)."""
    fine = an.trajectory.car(rate_hz=2000.0)
    coarse = an.trajectory.car(rate_hz=200.0)
    r = fine.ideal_imu("rates")
    inc = coarse.ideal_imu("increments")
    cols = ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s", "accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]
    y = r[cols].to_numpy()
    k = 10 * 26 * 200 // 10  # interval ending at 26 s, inside the shock
    seg = y[(k - 1) * 10 : k * 10 + 1]
    simpson = (2000.0 ** -1) / 3 * (seg[0] + seg[-1] + 4 * seg[1:-1:2].sum(0) + 2 * seg[2:-1:2].sum(0))
    np.testing.assert_allclose(inc.iloc[k - 1, 1:].to_numpy(), simpson, rtol=1e-6, atol=1e-12)
