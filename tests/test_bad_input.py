"""Issue 2 acceptance: bad input raises ValueError naming the field and the first
offending index; divergence raises NumericalError keeping what was computed."""

import numpy as np
import pandas as pd
import pytest

import atomnav as an


@pytest.fixture(scope="module")
def traj():
    return an.trajectory.sinusoidal(2.0, rate_hz=100.0)


@pytest.fixture
def imu(traj):
    return traj.ideal_imu("increments")


def _integrate(traj, imu, **kw):
    return an.strapdown.integrate(imu, **traj.initial_state(), **kw)


def test_nan_sample_names_field_and_index(traj, imu):
    imu.loc[17, "dtheta_y_rad"] = np.nan
    with pytest.raises(ValueError, match=r"imu: column .dtheta_y_rad.*index 17"):
        _integrate(traj, imu)


def test_inf_sample_names_field_and_index(traj, imu):
    imu.loc[42, "dv_z_mps"] = np.inf
    with pytest.raises(ValueError, match=r"imu: column .dv_z_mps.*index 42"):
        _integrate(traj, imu)


def test_wrong_array_shape(traj, imu):
    with pytest.raises(ValueError, match=r"imu: expected shape \(N, 7\)"):
        _integrate(traj, imu.to_numpy()[:, :6], kind="increments")


def test_missing_column(traj, imu):
    with pytest.raises(ValueError, match="dv_y_mps"):
        _integrate(traj, imu.drop(columns="dv_y_mps"))


def test_duplicated_time_stamp(traj, imu):
    imu.loc[5, "time_s"] = imu.loc[4, "time_s"]
    with pytest.raises(ValueError, match=r"time.*duplicated.*index 5"):
        _integrate(traj, imu)


def test_decreasing_time_stamp(traj, imu):
    imu.loc[9, "time_s"] = imu.loc[7, "time_s"]
    with pytest.raises(ValueError, match=r"time.*decreasing.*index 9"):
        _integrate(traj, imu)


def test_first_increment_not_after_initial_time(traj, imu):
    imu.loc[0, "time_s"] = traj.time[0]
    with pytest.raises(ValueError, match=r"time.*index 0"):
        _integrate(traj, imu)


@pytest.mark.parametrize("rate", [0.0, -100.0, np.nan])
def test_non_positive_sampling_rate(rate):
    with pytest.raises(ValueError, match="rate_hz: must be finite and > 0"):
        an.trajectory.sinusoidal(10.0, rate_hz=rate)


def test_latitude_out_of_range_in_generator():
    with pytest.raises(ValueError, match=r"origin: latitude 2(\.0)? rad at index 0"):
        an.trajectory.stationary(10.0, 10.0, origin=(2.0, 0.0, 0.0))


def test_latitude_out_of_range_in_conversion():
    with pytest.raises(ValueError, match=r"lla: latitude -1.6 rad at index 1"):
        an.earth.lla_to_ecef([[0.1, 0.0, 0.0], [-1.6, 0.0, 0.0]])


def test_latitude_out_of_range_in_user_trajectory(traj):
    df = traj.df.copy()
    df.loc[3, "lat_rad"] = 1.8
    with pytest.raises(ValueError, match=r"df: column 'lat_rad': latitude 1.8 rad at index 3"):
        an.trajectory.Trajectory.from_dataframe(df)


def test_user_trajectory_time_not_increasing(traj):
    df = traj.df.copy()
    df.loc[6, "time_s"] = df.loc[5, "time_s"]
    with pytest.raises(ValueError, match=r"time_s.*duplicated.*index 6"):
        an.trajectory.Trajectory.from_dataframe(df)


@pytest.mark.parametrize(
    "kwargs, field",
    [(dict(kind="samples"), "kind"), (dict(vertical="baro"), "vertical"), (dict(ellipsoid="GRS67"), "ellipsoid")],
)
def test_unknown_option(traj, imu, kwargs, field):
    with pytest.raises(ValueError, match=f"{field}.*unknown"):
        _integrate(traj, imu, **kwargs)


def test_damped_vertical_needs_reference(traj, imu):
    with pytest.raises(ValueError, match="h_ref"):
        _integrate(traj, imu, vertical="damped")


def test_nan_in_reference_altitude(traj, imu):
    h = np.full(len(imu), 100.0)
    h[11] = np.nan
    with pytest.raises(ValueError, match=r"h_ref.*index 11"):
        _integrate(traj, imu, vertical="damped", h_ref=h)


def test_time_outside_motion_span():
    m = an.trajectory.sinusoidal(1.0, 10.0).motion
    with pytest.raises(ValueError, match=r"time 5(\.0)? at index 2 is outside"):
        m.truth(np.array([0.0, 0.5, 5.0]))


def test_bad_row_in_a_later_block_leaves_the_stream_unchanged():
    """The core checks each 4096-row block just before integrating it: a NaN in a later
    block still names its index in the record, and the streaming object is left where
    the chunk started, so the corrected chunk gives what a fresh object gives."""
    long = an.trajectory.sinusoidal(200.0, rate_hz=100.0)
    good = long.ideal_imu("increments")
    bad = good.copy()
    bad.loc[10_000, "dv_y_mps"] = np.nan
    sd = an.strapdown.Strapdown(**long.initial_state())
    with pytest.raises(ValueError, match=r"imu: column .dv_y_mps.*index 10000"):
        sd.run(bad)
    fresh = an.strapdown.Strapdown(**long.initial_state())
    pd.testing.assert_frame_equal(sd.run(good), fresh.run(good))


@pytest.mark.parametrize("growth_from, chunk", [(0, None), (9000, None), (9000, 4000)])
def test_divergence_keeps_computed_rows(growth_from, chunk, monkeypatch):
    """An accelerometer stream growing tenfold every 8 samples from `growth_from` (finite,
    so input checks pass) overflows the solution ~1200 samples later: NumericalError names
    the sample, and the rows before it are kept (also when they span several of the
    core's 4096-row blocks, or several `integrate` chunks)."""
    if chunk:
        monkeypatch.setattr(an.strapdown, "CHUNK", chunk)
    long = an.trajectory.stationary(1400.0, 10.0)
    imu = long.ideal_imu("increments")
    imu["dv_x_mps"] += 10.0 ** np.minimum(np.maximum(np.arange(len(imu)) - growth_from, 0) / 8.0, 300.0)
    with pytest.raises(an.NumericalError, match=r"diverged at sample (\d+)") as info:
        an.strapdown.integrate(imu, **long.initial_state(), progress=False)
    k = int(__import__("re").search(r"sample (\d+)", str(info.value)).group(1))
    partial = info.value.partial
    assert growth_from + 10 < k < len(imu) and len(partial) == k
    np.testing.assert_array_equal(partial["time_s"], imu["time_s"].iloc[:k])
    assert np.all(np.abs(partial["lat_rad"]) <= np.pi / 2)


@pytest.mark.parametrize("out, why", [(np.empty((14, 10)), r"out: expected a \(14, >= \d+\) table"),
                                      (np.empty((14, 400))[:, ::2], "out: must be a C-contiguous"),
                                      (np.empty((13, 200)), r"out: expected a \(14")])
def test_run_into_rejects_a_bad_table(traj, imu, out, why):
    from atomnav.strapdown import _imu_arrays
    sd = an.strapdown.Strapdown(**traj.initial_state())
    t, g, a = _imu_arrays(imu, "increments")
    with pytest.raises(ValueError, match=why):
        sd._core.run_into(t, g, a, out)
