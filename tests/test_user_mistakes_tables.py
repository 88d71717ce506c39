"""The mistakes people make with pandas tables, time types and argument types never give a
silent wrong answer: each is the clean call's exact result, or an error naming the argument
the user gave (and the column). The oracle of every "same result" test is the clean call
on a float-seconds table with the documented columns."""

import warnings

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav import InputError
from atomnav.imu import GaussMarkov, ImuErrors

TABLE_KW = dict(errors="tactical", dt=0.01, kind="increments", seed=7)


@pytest.fixture(scope="module")
def traj():
    return an.trajectory.sinusoidal(10.0, rate_hz=100.0)


@pytest.fixture(scope="module")
def meas(traj):
    return an.imu.corrupt(traj.ideal_imu("increments"), **TABLE_KW)


@pytest.fixture(scope="module")
def clean(traj, meas):
    return an.strapdown.integrate(meas, **traj.initial_state())


def _integrate(traj, imu, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # unit-plausibility checks are not what these tests are about
        return an.strapdown.integrate(imu, **{**traj.initial_state(), **kw})


# ---- columns by name ----------------------------------------------------------------------

def test_duplicated_column_is_an_input_error_naming_imu_and_the_column(traj, meas):
    with pytest.raises(InputError, match="dv_x_mps") as e:
        an.strapdown.integrate(pd.concat([meas, meas[["dv_x_mps"]]], axis=1), **traj.initial_state())
    assert e.value.parameter == "imu"


def test_duplicated_column_in_corrupt_names_accel(traj):
    ideal = traj.ideal_imu("increments")
    with pytest.raises(InputError, match="dtheta_z_rad") as e:
        an.imu.corrupt(pd.concat([ideal, ideal[["dtheta_z_rad"]]], axis=1), **TABLE_KW)
    assert e.value.parameter == "accel"


def test_multiindex_level_matching_several_columns_is_ambiguous(traj, meas):
    two = pd.concat({"a": meas, "b": meas}, axis=1).swaplevel(axis=1)
    with pytest.raises(InputError, match="time_s.*ambiguous") as e:
        an.strapdown.integrate(two, **traj.initial_state())
    assert e.value.parameter == "imu"


def test_missing_column_lists_missing_and_expected(traj, meas):
    with pytest.raises(InputError, match=r"missing column\(s\) \['dv_z_mps'\]; expected \['time_s', 'dtheta_x_rad'") as e:
        an.strapdown.integrate(meas.drop(columns="dv_z_mps"), **traj.initial_state())
    assert e.value.parameter == "imu"


def test_reordered_columns_with_extras_give_the_identical_result(traj, meas, clean):
    messy = meas[list(meas.columns[::-1])].assign(note="lab run 3", temperature_c=21.5)
    pd.testing.assert_frame_equal(an.strapdown.integrate(messy, **traj.initial_state()), clean, check_exact=True)
    ideal = traj.ideal_imu("increments")
    pd.testing.assert_frame_equal(an.imu.corrupt(ideal[list(ideal.columns[::-1])].assign(note="x"), **TABLE_KW)[meas.columns],
                                  meas, check_exact=True)


def test_plain_array_is_read_in_the_documented_column_order(traj, meas, clean):
    cols = an.trajectory.IMU_COLUMNS["increments"]
    pd.testing.assert_frame_equal(an.strapdown.integrate(meas[cols].to_numpy(), **traj.initial_state(), kind="increments"), clean, check_exact=True)
    with pytest.raises(InputError, match=r"imu: expected shape \(N, 7\) with the columns"):
        an.strapdown.integrate(meas.to_numpy(), **traj.initial_state(), kind="increments")


# ---- nullable dtypes and strings --------------------------------------------------------

def test_pd_na_is_the_same_input_error_in_corrupt_and_integrate(traj, meas):
    ideal = traj.ideal_imu("increments").astype("Float64")
    ideal.loc[5, "dtheta_y_rad"] = pd.NA
    with pytest.raises(InputError, match="dtheta_y_rad") as c:
        an.imu.corrupt(ideal, **TABLE_KW)
    m = meas.astype("Float64")
    m.loc[5, "dtheta_y_rad"] = pd.NA
    with pytest.raises(InputError, match="dtheta_y_rad") as i:
        an.strapdown.integrate(m, **traj.initial_state())
    assert (c.value.parameter, c.value.index) == ("accel", 5)
    assert (i.value.parameter, i.value.index) == ("imu", 5)


def test_nullable_table_without_missing_values_gives_the_clean_result(traj, meas, clean):
    pd.testing.assert_frame_equal(an.strapdown.integrate(meas.astype("Float64"), **traj.initial_state()), clean, check_exact=True)


def test_all_string_imu_table_is_a_type_error_naming_imu_and_a_column(traj, meas):
    with pytest.raises(TypeError, match="imu: column 'time_s' holds"):
        an.strapdown.integrate(meas.astype(str), **traj.initial_state())
    with pytest.raises(TypeError, match="imu: column 'dv_y_mps' holds"):
        an.strapdown.integrate(meas.astype({"dv_y_mps": str}), **traj.initial_state())


def test_object_time_column_is_a_type_error_naming_the_column(traj):
    df = traj.df.astype({"time_s": str})
    with pytest.raises(TypeError, match="df: column 'time_s'"):
        an.trajectory.Trajectory.from_dataframe(df)


# ---- time types ---------------------------------------------------------------------------

def _with_time(meas, convert):
    out = meas.copy()
    out["time_s"] = convert(out["time_s"])
    return out


def test_datetime64_time_column_counts_from_the_epoch(traj, meas, clean):
    dt = _with_time(meas, lambda t: pd.Timestamp("2024-05-01 12:00") + pd.to_timedelta(t, unit="s"))
    got = _integrate(traj, dt, epoch=pd.Timestamp("2024-05-01 12:00"))
    pd.testing.assert_frame_equal(got, clean, check_exact=True)
    # t0 given as the datetime is the epoch itself
    pd.testing.assert_frame_equal(_integrate(traj, dt, t0=pd.Timestamp("2024-05-01 12:00")), clean, check_exact=True)


def test_tz_aware_time_column_gives_the_same_solution(traj, meas, clean):
    tz = _with_time(meas, lambda t: (pd.Timestamp("2024-05-01 12:00", tz="UTC") + pd.to_timedelta(t, unit="s")).dt.tz_convert("Europe/Moscow"))
    pd.testing.assert_frame_equal(_integrate(traj, tz, epoch=pd.Timestamp("2024-05-01 15:00", tz="Europe/Moscow")), clean, check_exact=True)
    with pytest.raises(InputError, match="tz-aware") as e:
        _integrate(traj, tz, epoch=pd.Timestamp("2024-05-01 12:00"))
    assert e.value.parameter == "imu"


def test_timedelta64_time_column_is_read_as_seconds(traj, meas, clean):
    td = _with_time(meas, lambda t: pd.to_timedelta(t, unit="s"))
    pd.testing.assert_frame_equal(_integrate(traj, td), clean, check_exact=True)


def test_datetime64_without_an_epoch_is_a_type_error_not_nanoseconds(traj, meas):
    dt = _with_time(meas, lambda t: pd.to_datetime(t, unit="s"))
    with pytest.raises(TypeError, match="imu: column 'time_s' holds datetimes"):
        an.strapdown.integrate(dt, **traj.initial_state())


def test_trajectory_from_datetime_table_keeps_seconds_and_its_epoch(traj, meas, clean):
    start = pd.Timestamp("2024-05-01 12:00")
    df = _with_time(traj.df, lambda t: start + pd.to_timedelta(t, unit="s"))
    user = an.trajectory.Trajectory.from_dataframe(df)
    np.testing.assert_array_equal(user.time, traj.time)     # not 1.7e18 "seconds"
    assert user.epoch == start
    # the IMU stamped in the same datetimes integrates against the trajectory's epoch ...
    nav = an.strapdown.integrate(_with_time(meas, lambda t: start + pd.to_timedelta(t, unit="s")), **user.initial_state())
    pd.testing.assert_frame_equal(nav, clean, check_exact=True)
    # ... and a solution in datetimes compares with it as the float one does
    nav_dt = _with_time(nav, lambda t: start + pd.to_timedelta(t, unit="s"))
    pd.testing.assert_frame_equal(user.errors(nav_dt), traj.errors(clean), check_exact=True)
    with pytest.raises(TypeError, match="nav: column 'time_s' holds datetimes"):
        traj.errors(nav_dt)                                    # a float trajectory has no epoch


def test_trajectory_epoch_argument_offsets_the_seconds(traj):
    start = pd.Timestamp("2024-05-01 12:00")
    df = _with_time(traj.df, lambda t: start + pd.to_timedelta(t, unit="s"))
    user = an.trajectory.Trajectory.from_dataframe(df, epoch=start - pd.Timedelta(seconds=100))
    np.testing.assert_array_equal(user.time, (np.arange(len(traj)) + 10_000.0) / 100.0)  # (k + 10⁴)/100 s, correctly rounded


def test_gnss_observation_datetimes_are_gps_time_of_the_week():
    from atomnav.gnss import ephemeris, observations, spp

    eph = ephemeris.Ephemerides.nominal(0.0, 3600.0)
    lla = np.tile([0.97, 0.65, 200.0], (3, 1))
    obs = observations.simulate(eph, [100.0, 101.0, 102.0], lla, np.zeros((3, 3)), seed=1)
    ref = spp.solve(eph, obs).epochs
    week = pd.Timestamp("2017-01-22")  # a Sunday, start of GPS week 1933
    dt = _with_time(obs, lambda t: week + pd.to_timedelta(t, unit="s"))
    pd.testing.assert_frame_equal(spp.solve(eph, dt).epochs, ref, check_exact=True)
    with pytest.raises(InputError, match="tz-aware") as e:
        spp.solve(eph, _with_time(dt, lambda t: t.dt.tz_localize("UTC")))
    assert e.value.parameter == "obs"
    with pytest.raises(InputError, match="code_m") as e:
        spp.solve(eph, pd.concat([obs, obs[["code_m"]]], axis=1))
    assert e.value.parameter == "obs"


# ---- wrong types ----------------------------------------------------------------------------

@pytest.mark.parametrize("before, after, name", [("1", "0.5", "before"), (1.0, "1e-4", "after"), (np.array(["1", "2"]), [0.5, 0.5], "before"),
                                                 (np.array(["1"], dtype=object), [0.5], "before"), (b"1", 0.5, "before")])
def test_numeric_strings_are_type_errors(before, after, name):
    with pytest.raises(TypeError, match=name):
        an.noise.allan.improvement_ratio(before, after)


def test_non_bool_flags_are_type_errors(traj, meas):
    with pytest.raises(TypeError, match="progress"):
        an.strapdown.integrate(meas, **traj.initial_state(), progress="yes")
    kf = an.filter.KalmanFilter(np.eye(2), mode="open")
    with pytest.raises(TypeError, match="sequential"):
        kf.update([0.1], [[1.0, 0.0]], [[1.0]], sequential="no")


def test_numeric_string_field_of_an_error_model_is_a_type_error(traj):
    errors = ImuErrors.preset("tactical")
    errors.gyro.white = "1e-4"
    with pytest.raises(TypeError, match="gyro.white"):
        an.imu.corrupt(traj.ideal_imu("increments"), **{**TABLE_KW, "errors": errors})


def test_gauss_markov_tuple_is_read_as_gauss_markov(traj):
    ideal = traj.ideal_imu("increments")
    as_tuple, as_class = ImuErrors.preset("tactical"), ImuErrors.preset("tactical")
    as_tuple.gyro.gauss_markov = (1e-5, 100.0)
    as_class.gyro.gauss_markov = GaussMarkov(1e-5, 100.0)
    pd.testing.assert_frame_equal(an.imu.corrupt(ideal, **{**TABLE_KW, "errors": as_tuple}),
                                  an.imu.corrupt(ideal, **{**TABLE_KW, "errors": as_class}), check_exact=True)
    assert as_tuple.summary().equals(as_class.summary())
    as_tuple.gyro.gauss_markov = {"sigma": 1e-5}
    with pytest.raises(TypeError, match="gyro.gauss_markov"):
        an.imu.corrupt(ideal, **{**TABLE_KW, "errors": as_tuple})


# ---- leaks and parameter names -------------------------------------------------------------------

def test_repr_of_an_empty_trajectory(traj):
    assert repr(an.trajectory.Trajectory(traj.df.iloc[:0])) == "Trajectory(user data, 0 samples)"


def test_ragged_euler_is_a_type_error_naming_euler():
    with pytest.raises(TypeError, match="euler"):
        an.rotation.quat_from_euler([[0, 0, 0], [0, 0]])


@pytest.mark.parametrize("field, value, parameter", [("lla", [3.0, 0.0, 0.0], "lla"), ("q_nb", [1.0, 0.1, 0.1, 0.1], "q_nb"),
                                                      ("vel_ned", [np.nan, 0.0, 0.0], "vel_ned")])
def test_initial_state_errors_name_the_argument(traj, meas, field, value, parameter):
    with pytest.raises(InputError) as e:
        an.strapdown.integrate(meas, **{**traj.initial_state(), field: value})
    assert e.value.parameter == parameter


def test_negative_zeta_names_zeta(traj, meas):
    with pytest.raises(InputError) as e:
        an.strapdown.integrate(meas, **traj.initial_state(), vertical="damped", zeta=-1.0, h_ref=traj.df["h_m"].to_numpy()[1:])
    assert e.value.parameter == "zeta"


def test_bad_imu_row_names_imu_and_the_column(traj, meas):
    bad = meas.copy()
    bad.loc[7, "dv_y_mps"] = np.inf
    with pytest.raises(InputError, match="imu: column 'dv_y_mps'") as e:
        an.strapdown.integrate(bad, **traj.initial_state())
    assert e.value.index == 7
    bad = meas.copy()
    bad.loc[9, "time_s"] = bad.loc[8, "time_s"]
    with pytest.raises(InputError, match="imu: column 'time_s'") as e:
        an.strapdown.integrate(bad, **traj.initial_state())
    assert e.value.index == 9
