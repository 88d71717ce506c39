"""atomnav.io: a user's IMU log and reference trajectory, read from CSV, Parquet or a
DataFrame with their own column names and units. The oracle of every round trip is the
simulator's exact output (``Trajectory.ideal_imu``, the trajectory's own table) written
in the user's units with numpy and read back; gap reports are checked against gaps cut
out by hand; every bad input is an InputError with its argument and row asserted."""

import pickle
import re
import warnings

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav import InputError
from atomnav.io import read_imu, read_trajectory
from atomnav.trajectory import IMU_COLUMNS

# independent of atomnav.units: standard gravity (CGPM 1901) and the degree
G0 = 9.80665
MICRO_G = 1e-6 * G0
DEG = np.pi / 180.0
RATES_COLUMNS = dict(time="Time [ms]", gyro_x="Gyro X (deg/s)", gyro_y="Gyro Y (deg/s)", gyro_z="Gyro Z (deg/s)",
                     accel_x="Acc X (ug)", accel_y="Acc Y (ug)", accel_z="Acc Z (ug)")
INCREMENTS_COLUMNS = dict(time="t_ns", gyro_x="dA1", gyro_y="dA2", gyro_z="dA3", accel_x="dV1", accel_y="dV2", accel_z="dV3")


@pytest.fixture(scope="module")
def traj():
    return an.trajectory.sinusoidal(60.0)


@pytest.fixture(scope="module")
def rates(traj):
    return traj.ideal_imu("rates")


@pytest.fixture(scope="module")
def increments(traj):
    return traj.ideal_imu("increments")


def _rates_log(ideal: pd.DataFrame) -> pd.DataFrame:
    """The ideal rates as a user's log: ms, deg/s, µg, own names, shuffled, an extra column."""
    c = RATES_COLUMNS
    out = pd.DataFrame({c["time"]: ideal["time_s"] * 1e3, "temperature_C": 21.5})
    for axis in "xyz":
        out[c[f"accel_{axis}"]] = ideal[f"accel_{axis}_mps2"] / MICRO_G
        out[c[f"gyro_{axis}"]] = ideal[f"gyro_{axis}_rad_s"] / DEG
    return out


def _increments_log(ideal: pd.DataFrame) -> pd.DataFrame:
    """The ideal increments as a user's log: integer ns, deg, m/s."""
    c = INCREMENTS_COLUMNS
    out = pd.DataFrame({c["time"]: np.rint(ideal["time_s"].to_numpy() * 1e9).astype(np.int64)})
    for axis in "xyz":
        out[c[f"gyro_{axis}"]] = ideal[f"dtheta_{axis}_rad"] / DEG
        out[c[f"accel_{axis}"]] = ideal[f"dv_{axis}_mps"]
    return out


RATES_UNITS = {"gyro": "deg/s", "accel": "µg"}
INCREMENTS_UNITS = {"gyro": "deg", "accel": "m/s"}


def _write(df: pd.DataFrame, path) -> None:
    if str(path).endswith(".csv"):
        df.to_csv(path, index=False)
    else:
        df.to_parquet(path, index=False)


def _same_navigation(a: pd.DataFrame, b: pd.DataFrame) -> None:
    """Two strapdown solutions of inputs equal to 1e-12 relative: equal to 1e-9 (rad, m, m/s)."""
    np.testing.assert_allclose(a.to_numpy(), b.to_numpy(), rtol=0, atol=1e-9)


# ---- round trips -----------------------------------------------------------------------------

@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_rates_in_ms_deg_s_and_micro_g_read_back_to_the_simulator_output(tmp_path, traj, rates, suffix):
    path = tmp_path / f"imu{suffix}"
    _write(_rates_log(rates), path)
    log = read_imu(path, columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms")
    assert list(log.data.columns) == IMU_COLUMNS["rates"] and log.kind == "rates" and log.epoch is None
    np.testing.assert_allclose(log.data.to_numpy(), rates[IMU_COLUMNS["rates"]].to_numpy(), rtol=1e-12, atol=0)
    _same_navigation(an.strapdown.integrate(log.data, **traj.initial_state()),
                     an.strapdown.integrate(rates, **traj.initial_state(), kind="rates"))


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_increments_in_integer_ns_and_deg_read_back_and_integrate_like_the_original(tmp_path, traj, increments, suffix):
    path = tmp_path / f"imu{suffix}"
    _write(_increments_log(increments), path)
    log = read_imu(path, columns=INCREMENTS_COLUMNS, units=INCREMENTS_UNITS, kind="increments", time_unit="ns")
    assert list(log.data.columns) == IMU_COLUMNS["increments"]
    np.testing.assert_allclose(log.data.to_numpy(), increments[IMU_COLUMNS["increments"]].to_numpy(), rtol=1e-12, atol=0)
    _same_navigation(an.strapdown.integrate(log.data, **traj.initial_state()),
                     an.strapdown.integrate(increments, **traj.initial_state(), kind="increments"))
    np.testing.assert_array_equal(log.time, log.data["time_s"].to_numpy())
    np.testing.assert_array_equal(log.gyro, log.data[IMU_COLUMNS["increments"][1:4]].to_numpy())
    np.testing.assert_array_equal(log.accel, log.data[IMU_COLUMNS["increments"][4:]].to_numpy())


@pytest.mark.parametrize("unit, scale", [("g", G0), ("m/s^2", 1.0), ("m/s²", 1.0), ("mps2", 1.0), ("ug", MICRO_G), ("\u03bcg", MICRO_G),
                                         ("mg", 1e-3 * G0)])
def test_every_accel_unit_has_its_factor(rates, unit, scale):
    df = _rates_log(rates)
    for axis in "xyz":
        df[RATES_COLUMNS[f"accel_{axis}"]] = rates[f"accel_{axis}_mps2"] / scale
    log = read_imu(df, columns=RATES_COLUMNS, units={"gyro": "deg/s", "accel": unit}, kind="rates", time_unit="ms")
    np.testing.assert_allclose(log.data[IMU_COLUMNS["rates"][4:]].to_numpy(), rates[IMU_COLUMNS["rates"][4:]].to_numpy(), rtol=1e-12)


def test_gyro_in_deg_per_hour(rates):
    df = _rates_log(rates)
    for axis in "xyz":
        df[RATES_COLUMNS[f"gyro_{axis}"]] = rates[f"gyro_{axis}_rad_s"] * 3600.0 * 180.0 / np.pi
    log = read_imu(df, columns=RATES_COLUMNS, units={"gyro": "deg/h", "accel": "ug"}, kind="rates", time_unit="ms")
    np.testing.assert_allclose(log.gyro, rates[IMU_COLUMNS["rates"][1:4]].to_numpy(), rtol=1e-12)


def test_iso_datetimes_in_a_csv_count_from_the_first_sample_or_the_epoch(tmp_path, rates):
    start = pd.Timestamp("2026-03-01T12:00:00Z")
    df = _rates_log(rates)
    df[RATES_COLUMNS["time"]] = (start + pd.to_timedelta(np.rint(rates["time_s"].to_numpy() * 1e9).astype(np.int64), "ns")).strftime(
        "%Y-%m-%dT%H:%M:%S.%fZ")
    path = tmp_path / "imu.csv"
    df.to_csv(path, index=False)
    log = read_imu(path, columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="datetime")
    assert log.epoch == start
    np.testing.assert_allclose(log.time, rates["time_s"].to_numpy(), rtol=1e-12, atol=1e-12)
    earlier = read_imu(path, columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="datetime",
                       epoch=start - pd.Timedelta(seconds=100))
    np.testing.assert_allclose(earlier.time, rates["time_s"].to_numpy() + 100.0, rtol=1e-12)


def test_datetime64_parquet_column(tmp_path, rates):
    start = pd.Timestamp("2026-03-01 12:00:00")
    df = _rates_log(rates)
    df[RATES_COLUMNS["time"]] = start + pd.to_timedelta(np.rint(rates["time_s"].to_numpy() * 1e9).astype(np.int64), "ns")
    df.to_parquet(tmp_path / "imu.parquet")
    log = read_imu(tmp_path / "imu.parquet", columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="datetime")
    assert log.epoch == start
    np.testing.assert_allclose(log.time, rates["time_s"].to_numpy(), rtol=1e-12, atol=1e-12)
    with pytest.raises(InputError, match="holds datetimes") as e:
        read_imu(tmp_path / "imu.parquet", columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="s")
    assert e.value.parameter == "time_unit"


def test_read_options_go_to_pandas(tmp_path, rates):
    path = tmp_path / "imu.csv"
    _rates_log(rates).to_csv(path, index=False, sep=";")
    log = read_imu(path, columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms", sep=";")
    np.testing.assert_allclose(log.data.to_numpy(), rates[IMU_COLUMNS["rates"]].to_numpy(), rtol=1e-12, atol=0)


def test_log_and_report_pickle(rates):
    log = read_imu(_rates_log(rates), columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms")
    copy = pickle.loads(pickle.dumps(log))
    pd.testing.assert_frame_equal(copy.data, log.data, check_exact=True)
    pd.testing.assert_frame_equal(copy.report.gaps, log.report.gaps, check_exact=True)
    assert (copy.kind, copy.report.samples, copy.report.median_interval_s) == (log.kind, log.report.samples, log.report.median_interval_s)


# ---- sampling report -------------------------------------------------------------------------

def _cut(ideal: pd.DataFrame) -> pd.DataFrame:
    """The log without rows 1000..1004 (5 samples) and 3000 (1 sample)."""
    return _rates_log(ideal).drop(index=[*range(1000, 1005), 3000]).reset_index(drop=True)


def test_report_of_a_clean_log(rates):
    report = read_imu(_rates_log(rates), columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms").report
    t = rates["time_s"].to_numpy()
    assert report.samples == len(t)
    assert (report.start_s, report.end_s) == pytest.approx((t[0], t[-1]), rel=1e-12, abs=1e-12)
    assert report.median_interval_s == pytest.approx(0.01, rel=1e-9)
    assert report.rate_hz == pytest.approx(100.0, rel=1e-9)
    assert report.max_gap_s == pytest.approx(0.015, rel=1e-9)
    assert report.gaps.empty


def test_report_lists_the_gaps_cut_out(rates):
    t = rates["time_s"].to_numpy()
    log = read_imu(_cut(rates), columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms")
    gaps = log.report.gaps
    assert log.report.samples == len(t) - 6
    assert list(gaps["row"]) == [1000, 3000 - 5]  # the data rows after each gap, counted in the cut log
    np.testing.assert_allclose(gaps["start_s"], [t[999], t[2999]], rtol=1e-12)
    np.testing.assert_allclose(gaps["end_s"], [t[1005], t[3001]], rtol=1e-12)
    np.testing.assert_allclose(gaps["length_s"], [0.06, 0.02], rtol=1e-9)
    assert list(gaps["missing_samples"]) == [5, 1]
    assert "2 gap(s)" in str(log.report)
    # nothing is dropped or reordered: the rows read are the rows given
    np.testing.assert_allclose(log.time, np.delete(t, [*range(1000, 1005), 3000]), rtol=1e-12, atol=1e-15)


def test_a_gap_beyond_max_gap_is_an_error_naming_the_time_column_and_the_row(rates):
    with pytest.raises(InputError, match=r"Time \[ms\].*gap of 0\.06 s before data row 1000.*max_gap = 0\.05") as e:
        read_imu(_cut(rates), columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms", max_gap=0.05)
    assert (e.value.parameter, e.value.index) == ("source", 1000)
    with pytest.raises(InputError, match=r"gap of 0\.06 s before data row 1000 .*\(2 such gap\(s\)\)") as e:
        read_imu(_cut(rates), columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms", max_gap=0.015)
    assert e.value.index == 1000  # the first gap of the two


def test_on_gap_report_lists_instead(rates):
    log = read_imu(_cut(rates), columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms", max_gap=0.05, on_gap="report")
    assert log.report.max_gap_s == 0.05
    assert list(log.report.gaps["row"]) == [1000]


# ---- bad input -------------------------------------------------------------------------------

def _read(df, **kw):
    args = dict(columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms")
    return read_imu(df, **{**args, **kw})


def test_a_column_not_in_the_source_names_columns_and_lists_the_source_columns(rates):
    with pytest.raises(InputError, match=r"'Gyro Y \(deg/s\)'.*not in the source; its columns are") as e:
        _read(_rates_log(rates).drop(columns=RATES_COLUMNS["gyro_y"]))
    assert e.value.parameter == "columns"


def test_a_misnamed_or_missing_field_names_columns(rates):
    with pytest.raises(InputError, match=r"unknown name\(s\) \['gyro_X'\]") as e:
        _read(_rates_log(rates), columns={**{k: v for k, v in RATES_COLUMNS.items() if k != "gyro_x"}, "gyro_X": "Gyro X (deg/s)"})
    assert e.value.parameter == "columns"
    with pytest.raises(InputError, match=r"no column given for \['accel_z'\]") as e:
        _read(_rates_log(rates), columns={k: v for k, v in RATES_COLUMNS.items() if k != "accel_z"})
    assert e.value.parameter == "columns"
    with pytest.raises(InputError, match="'gyro_x' and 'gyro_y' both name the column") as e:
        _read(_rates_log(rates), columns={**RATES_COLUMNS, "gyro_y": RATES_COLUMNS["gyro_x"]})
    assert e.value.parameter == "columns"


@pytest.mark.parametrize("units, field, accepted", [
    ({"gyro": "deg/sec", "accel": "ug"}, "gyro", "'rad/s', 'deg/s', 'deg/h'"),
    ({"gyro": "deg/s", "accel": "G"}, "accel", "'m/s²', 'm/s^2', 'mps2', 'g'"),
    ({"gyro": "deg", "accel": "ug"}, "gyro", "'rad/s', 'deg/s'"),  # an increments unit for rates
])
def test_an_unknown_unit_names_the_field_and_lists_the_accepted_units(rates, units, field, accepted):
    with pytest.raises(InputError, match=re.escape(f"'{field}': unknown unit ") + ".*" + re.escape(f"accepted units are [{accepted}")) as e:
        _read(_rates_log(rates), units=units)
    assert e.value.parameter == "units"


def test_a_missing_unit_or_quantity_names_units(rates):
    with pytest.raises(InputError, match="no unit given for 'accel'") as e:
        _read(_rates_log(rates), units={"gyro": "deg/s"})
    assert e.value.parameter == "units"
    with pytest.raises(InputError, match=r"unknown quantity \['temperature'\]") as e:
        _read(_rates_log(rates), units={**RATES_UNITS, "temperature": "C"})
    assert e.value.parameter == "units"


def test_time_unit_kind_and_on_gap_are_checked(rates):
    for kw, name in ((dict(time_unit="min"), "time_unit"), (dict(kind="rate"), "kind"), (dict(on_gap="warn"), "on_gap"),
                     (dict(max_gap=-1.0), "max_gap"), (dict(epoch=pd.Timestamp("2026-01-01")), "epoch")):
        with pytest.raises(InputError) as e:
            _read(_rates_log(rates), **kw)
        assert e.value.parameter == name, kw


def test_a_duplicated_time_stamp_names_the_time_column_and_the_file_row(tmp_path, rates):
    df = _rates_log(rates)
    df.loc[700, RATES_COLUMNS["time"]] = df.loc[699, RATES_COLUMNS["time"]]
    path = tmp_path / "imu.csv"
    df.to_csv(path, index=False)
    with pytest.raises(InputError, match=r"time column 'Time \[ms\]' is not strictly increasing: data row 700 .* repeats") as e:
        read_imu(path, columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms")
    assert (e.value.parameter, e.value.index) == ("source", 700)
    lines = path.read_text().splitlines()  # data row k is line k + 2 of the file (1-based, one header line)
    assert lines[700 + 1].split(",")[0] == lines[699 + 1].split(",")[0]


def test_a_time_stamp_going_back_names_its_row(rates):
    df = _rates_log(rates)
    df.loc[[400, 401]] = df.loc[[401, 400]].to_numpy()  # two rows swapped: never reordered silently
    with pytest.raises(InputError, match="data row 401 .* goes back") as e:
        _read(df)
    assert (e.value.parameter, e.value.index) == ("source", 401)


@pytest.mark.parametrize("field, row", [("accel_y", 123), ("time", 5), ("gyro_z", 0)])
def test_a_nan_names_the_column_and_the_row(tmp_path, rates, field, row):
    df = _rates_log(rates)
    df.loc[row, RATES_COLUMNS[field]] = np.nan
    path = tmp_path / "imu.csv"
    df.to_csv(path, index=False)
    with pytest.raises(InputError, match=re.escape(f"column '{RATES_COLUMNS[field]}': a missing value (NaN) at data row {row}")) as e:
        read_imu(path, columns=RATES_COLUMNS, units=RATES_UNITS, kind="rates", time_unit="ms")
    assert (e.value.parameter, e.value.index) == ("source", row)


def test_text_in_a_sensor_column_is_a_type_error_naming_the_column(rates):
    df = _rates_log(rates)
    df[RATES_COLUMNS["gyro_x"]] = df[RATES_COLUMNS["gyro_x"]].astype(str)
    with pytest.raises(TypeError, match=r"source: column 'Gyro X \(deg/s\)'"):
        _read(df)


def test_unreadable_sources(tmp_path, rates):
    with pytest.raises(InputError, match="cannot tell the format") as e:
        _read(tmp_path / "imu.dat")
    assert e.value.parameter == "source"
    with pytest.raises(FileNotFoundError):
        _read(tmp_path / "absent.csv")
    (tmp_path / "bad.parquet").write_text("not parquet")
    with pytest.raises(InputError, match="not a readable Parquet table") as e:
        _read(tmp_path / "bad.parquet")
    with pytest.raises(InputError, match="at least 2 rows") as e:
        _read(_rates_log(rates).iloc[:1])
    assert e.value.parameter == "source"
    with pytest.raises(TypeError, match="source"):
        _read(rates.to_numpy())


def test_unparsable_datetime_names_the_row(tmp_path, rates):
    df = _rates_log(rates).iloc[:10].copy()
    df[RATES_COLUMNS["time"]] = [f"2026-03-01T12:00:00.{k:02d}0" for k in range(10)]
    df.loc[6, RATES_COLUMNS["time"]] = "yesterday"
    with pytest.raises(InputError, match="'yesterday' at data row 6") as e:
        _read(df, time_unit="datetime")
    assert (e.value.parameter, e.value.index) == ("source", 6)


# ---- reference trajectories ------------------------------------------------------------------

TRAJ_COLUMNS = dict(time="t", lat="Lat", lon="Lon", h="Alt", vn="VN", ve="VE", vd="VD")


def _traj_log(traj, attitude: str) -> pd.DataFrame:
    d = traj.df
    out = pd.DataFrame({"t": d["time_s"], "Lat": np.degrees(d["lat_rad"]), "Lon": np.degrees(d["lon_rad"]), "Alt": d["h_m"],
                        "VN": d["vn_mps"], "VE": d["ve_mps"], "VD": d["vd_mps"]})
    if attitude == "euler":
        out["R"], out["P"], out["Y"] = np.degrees(d["roll_rad"]), np.degrees(d["pitch_rad"]), np.degrees(d["yaw_rad"])
    else:
        out["q0"], out["q1"], out["q2"], out["q3"] = d["qw"], d["qx"], d["qy"], d["qz"]
    return out


EULER = dict(roll="R", pitch="P", yaw="Y")
QUATERNION = dict(qw="q0", qx="q1", qy="q2", qz="q3")


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
@pytest.mark.parametrize("attitude", ["euler", "quaternion"])
def test_trajectory_in_degrees_reads_back_to_the_truth(tmp_path, traj, suffix, attitude):
    path = tmp_path / f"ref{suffix}"
    _write(_traj_log(traj, attitude), path)
    columns = {**TRAJ_COLUMNS, **(EULER if attitude == "euler" else QUATERNION)}
    units = {"lat": "deg", "lon": "deg", **({"euler": "deg"} if attitude == "euler" else {})}
    ref = read_trajectory(path, columns=columns, units=units)
    assert isinstance(ref, an.trajectory.Trajectory)
    np.testing.assert_allclose(ref.df[an.trajectory.COLUMNS].to_numpy(), traj.df[an.trajectory.COLUMNS].to_numpy(), rtol=1e-12, atol=1e-14)
    err = ref.errors(an.strapdown.integrate(traj.ideal_imu("increments"), **ref.initial_state()))
    truth = traj.errors(an.strapdown.integrate(traj.ideal_imu("increments"), **traj.initial_state()))
    np.testing.assert_allclose(err.to_numpy(), truth.to_numpy(), rtol=0, atol=1e-6)


def test_trajectory_datetimes_keep_the_epoch(traj):
    start = pd.Timestamp("2026-03-01 12:00:00", tz="UTC")
    df = _traj_log(traj, "quaternion")
    df["t"] = start + pd.to_timedelta(np.rint(df["t"].to_numpy() * 1e9).astype(np.int64), "ns")
    ref = read_trajectory(df, columns={**TRAJ_COLUMNS, **QUATERNION}, units={"lat": "deg", "lon": "deg"}, time_unit="datetime")
    assert ref.epoch == start
    np.testing.assert_allclose(ref.time, traj.time, rtol=1e-12, atol=1e-12)


def test_trajectory_units_are_never_guessed(traj):
    df = _traj_log(traj, "euler")
    for units, missing in (({"lon": "deg", "euler": "deg"}, "lat"), ({"lat": "deg", "lon": "deg"}, "euler")):
        with pytest.raises(InputError, match=f"no unit given for '{missing}'") as e:
            read_trajectory(df, columns={**TRAJ_COLUMNS, **EULER}, units=units)
        assert e.value.parameter == "units"
    with pytest.raises(InputError, match=r"'lat': unknown unit 'degrees'.*\['rad', 'deg'\]") as e:
        read_trajectory(df, columns={**TRAJ_COLUMNS, **EULER}, units={"lat": "degrees", "lon": "deg", "euler": "deg"})
    assert e.value.parameter == "units"


def test_trajectory_attitude_is_one_form(traj):
    df = _traj_log(traj, "quaternion")
    with pytest.raises(InputError, match="mix the quaternion") as e:
        read_trajectory(df, columns={**TRAJ_COLUMNS, **QUATERNION, "roll": "q0"}, units={"lat": "deg", "lon": "deg"})
    assert e.value.parameter == "columns"
    with pytest.raises(InputError, match=r"no column given for \['qz'\]") as e:
        read_trajectory(df, columns={**TRAJ_COLUMNS, **{k: v for k, v in QUATERNION.items() if k != "qz"}}, units={"lat": "deg", "lon": "deg"})
    assert e.value.parameter == "columns"


def _bad_trajectory(traj, column, row, value):
    df = _traj_log(traj, "quaternion")
    df.loc[row, column] = value
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", an.UnitWarning)
        with pytest.raises(InputError) as e:
            read_trajectory(df, columns={**TRAJ_COLUMNS, **QUATERNION}, units={"lat": "deg", "lon": "deg"})
    return e.value


def test_latitude_beyond_90_degrees_names_the_row(traj):
    e = _bad_trajectory(traj, "Lat", 17, 90.5)
    assert (e.parameter, e.index) == ("source", 17) and "column 'Lat' (lat_rad)" in str(e) and "data row 17" in str(e)


@pytest.mark.parametrize("h", [-1.0e4 - 1.0, 1.0e6 + 1.0])
def test_height_outside_the_core_range_names_the_row(traj, h):
    e = _bad_trajectory(traj, "Alt", 33, h)
    assert (e.parameter, e.index) == ("source", 33) and "'Alt' (h)" in str(e)
    assert an.earth.HEIGHT_RANGE == (-1.0e4, 1.0e6)


def test_non_unit_quaternion_names_the_row(traj):
    q = traj.df.loc[44, ["qw", "qx", "qy", "qz"]].to_numpy()
    e = _bad_trajectory(traj, "q0", 44, q[0] + 10 * an.rotation.ROTATION_TOLERANCE)
    assert (e.parameter, e.index) == ("source", 44) and "quaternion" in str(e)


def test_trajectory_nan_and_time_order_name_the_row(traj):
    e = _bad_trajectory(traj, "VE", 8, np.nan)
    assert (e.parameter, e.index) == ("source", 8) and "'VE'" in str(e)
    e = _bad_trajectory(traj, "t", 9, traj.time[8])
    assert (e.parameter, e.index) == ("source", 9) and "'t'" in str(e)


# ---- one default for kind ---------------------------------------------------------------------

def test_kind_none_reads_the_table_columns_in_integrate_and_corrupt(traj, rates, increments):
    init = traj.initial_state()
    pd.testing.assert_frame_equal(an.strapdown.integrate(rates, **init), an.strapdown.integrate(rates, **init, kind="rates"),
                                  check_exact=True)
    pd.testing.assert_frame_equal(an.strapdown.integrate(increments, **init),
                                  an.strapdown.integrate(increments, **init, kind="increments"), check_exact=True)
    for ideal, kind in ((rates, "rates"), (increments, "increments")):
        pd.testing.assert_frame_equal(an.imu.corrupt(ideal, errors="tactical", dt=0.01, seed=3),
                                      an.imu.corrupt(ideal, errors="tactical", dt=0.01, kind=kind, seed=3), check_exact=True)


def test_stateful_objects_fix_the_kind_at_their_first_table(traj, rates, increments):
    init = traj.initial_state()
    sd = an.strapdown.Strapdown(**init)
    assert sd.kind is None
    first = sd.run(rates.iloc[:3000])
    assert sd.kind == "rates"
    whole = an.strapdown.integrate(rates, **init, kind="rates")
    pd.testing.assert_frame_equal(pd.concat([first, sd.run(rates.iloc[3000:])]), whole, check_exact=True)
    copy = pickle.loads(pickle.dumps(an.strapdown.Strapdown(**init)))
    pd.testing.assert_frame_equal(copy.run(rates), whole, check_exact=True)
    sim = an.imu.ImuSimulator("tactical", 0.01, seed=3)
    assert sim.kind is None
    pd.testing.assert_frame_equal(sim.corrupt(increments), an.imu.ImuSimulator("tactical", 0.01, "increments", seed=3).corrupt(increments),
                                  check_exact=True)
    assert sim.kind == "increments"


def test_kind_none_with_both_sets_or_neither_names_the_table(traj, rates, increments):
    both = pd.concat([rates, increments.drop(columns="time_s")], axis=1)
    for table, why in ((both, "columns of both IMU kinds"), (rates[["time_s"]], "no IMU columns")):
        with pytest.raises(InputError, match=f"imu: has {why}.*rates .*'gyro_x_rad_s'.*increments .*'dtheta_x_rad'") as e:
            an.strapdown.integrate(table, **traj.initial_state())
        assert e.value.parameter == "imu"
        with pytest.raises(InputError, match=why) as e:
            an.imu.corrupt(table, errors="tactical", dt=0.01)
        assert e.value.parameter == "accel"


def test_a_plain_array_needs_kind(traj, rates):
    message = 'a plain array needs kind="rates" or "increments"'
    cases = [lambda: an.strapdown.integrate(rates[IMU_COLUMNS["rates"]].to_numpy(), **traj.initial_state()),
             lambda: an.strapdown.Strapdown(**traj.initial_state()).run(rates[IMU_COLUMNS["rates"]].to_numpy()),
             lambda: an.imu.corrupt(np.zeros((5, 3)), np.zeros((5, 3)), errors="tactical", dt=0.01),
             lambda: an.imu.ImuSimulator("tactical", 0.01).corrupt(np.zeros((5, 3)), np.zeros((5, 3))),
             lambda: an.cai.cai_aided_ins(*traj.initial_state().values(), an.cai.seed003_sensor(), [1.0], phase=np.zeros((1, 6)),
                                          noise=np.zeros((1, 6)))]
    for call in cases:
        with pytest.raises(InputError, match=message) as e:
            call()
        assert e.value.parameter == "kind"


def test_a_plain_array_in_the_documented_order_equals_the_table(traj, rates):
    init = traj.initial_state()
    pd.testing.assert_frame_equal(an.strapdown.integrate(rates[IMU_COLUMNS["rates"]].to_numpy(), **init, kind="rates"),
                                  an.strapdown.integrate(rates, **init), check_exact=True)


@pytest.mark.parametrize("kind", ["rates", "increments"])
def test_a_plain_array_in_the_stream_order_time_accel_gyro_does_not_pass_silently(traj, kind):
    """imu.COLUMNS lists the accelerometer first; an (N, 7) array built in that order would
    integrate to a height error of kilometres. Its gyro block has the mean magnitude of
    gravity (checked here against 9.80665 m/s² itself), so it is refused."""
    ideal = traj.ideal_imu(kind)
    accel, gyro = an.imu.COLUMNS[kind]
    scale = 1.0 if kind == "rates" else 1.0 / 0.01
    assert np.linalg.norm(ideal[accel].to_numpy() * scale, axis=1).mean() == pytest.approx(G0, rel=0.01)
    with pytest.raises(InputError, match="columns 1-3 look like the accelerometer") as e:
        an.strapdown.integrate(ideal[["time_s", *accel, *gyro]].to_numpy(), **traj.initial_state(), kind=kind)
    assert e.value.parameter == "imu"


def test_the_order_check_passes_free_fall_and_fast_rotation(traj):
    """No false alarm where the gyro block is not near gravity or the accel block is: a
    satellite-like record (|f| ≈ 0, slow rotation) and a fast but Earth-bound one."""
    t = np.arange(200) * 0.01
    still = np.column_stack([t, np.full((200, 3), 1e-3), np.full((200, 3), 1e-6)])
    spin = np.column_stack([t, np.tile([0.0, 0.0, 8.0], (200, 1)), np.tile([0.0, 0.0, -9.8], (200, 1))])
    for arr in (still, spin):
        assert an.plausibility.swapped_blocks(arr[:, 0], arr[:, 1:4], arr[:, 4:7], "rates") is None
