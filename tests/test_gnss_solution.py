"""RTKLIB solution files (atomnav.gnss.solution.read_pos): the recorded walk's file, and
the same epochs rewritten in RTKLIB's other time and position formats.

Oracles: the facts of the walk's SOURCE.md (349 fixed and 187 float epochs; GNSS and IMU
stamped on the same GPS time scale), the file's own text, RTKLIB's format (Takasu 2013,
Appendix B.2: covariances written as sign(c)·√|c|, up axis, UTC = GPST − leap seconds,
JST = UTC + 9 h), and an independent WGS-84 ECEF conversion written here (Groves 2013,
Eq. 2.112)."""

from __future__ import annotations

import gzip
import io
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav.gnss import solution

DATA = Path(__file__).parent / "data" / "real_walk"
POS = DATA / "gnss_1730_sf.pos.gz"
A, E2 = 6378137.0, 6.69437999014e-3  # WGS-84 semi-major axis (m) and first eccentricity squared


def _text() -> str:
    with gzip.open(POS, "rt") as f:
        return f.read()


def _lines():
    text = _text().splitlines()
    header = [ln for ln in text if ln.startswith("%")]
    body = [ln for ln in text if ln.strip() and not ln.startswith("%")]
    return header, body


def _read(text: str, **kw):
    return solution.read_pos(io.StringIO(text), **kw)


@pytest.fixture(scope="module")
def walk():
    return solution.read_pos(POS)


def test_walk_counts_and_first_epoch_from_the_text(walk):
    assert walk.counts().to_dict() == {"fix": 349, "float": 187}
    _, body = _lines()
    f = body[0].split()
    row = walk.data.iloc[0]
    assert row["lat_rad"] == np.radians(float(f[2])) and row["lon_rad"] == np.radians(float(f[3]))
    assert row["h_m"] == float(f[4]) and row["n_sats"] == int(float(f[6])) and row["quality"] == "fix"
    assert row["cov_nn_m2"] == pytest.approx(float(f[7]) ** 2, rel=1e-15)
    assert row["cov_dd_m2"] == pytest.approx(float(f[9]) ** 2, rel=1e-15)
    # velocity north, east, up in the file; down here
    assert (row["vn_mps"], row["ve_mps"], row["vd_mps"]) == (float(f[15]), float(f[16]), -float(f[17]))
    assert row["cov_vnn_m2s2"] == pytest.approx(float(f[18]) ** 2, rel=1e-15)
    assert walk.time_scale == "GPST" and len(walk.data) == len(body)


def test_walk_time_is_on_the_imu_clock(walk):
    """The IMU stamps are GPS-scale seconds since 1970 (SOURCE.md): with the default epoch
    the GNSS epochs fall inside the IMU record (a leap-second mistake would be 18 s off)."""
    imu_t = pd.read_csv(DATA / "imu_1730_sf.csv.gz", header=None, usecols=[0])[0].to_numpy()
    t = walk.data["time_s"].to_numpy()
    assert imu_t[0] - 2.0 < t[0] < imu_t[0] + 2.0 and imu_t[-1] - 2.0 < t[-1] < imu_t[-1] + 2.0
    assert np.all(np.diff(t) > 0)
    np.testing.assert_allclose(np.diff(t), 0.25, atol=2e-3)  # 4 Hz


def _retimed(fn, label: str) -> str:
    """The walk's file with every time rewritten by fn(Timestamp) -> text fields and the
    time label of the column header replaced."""
    header, body = _lines()
    out = header[:-1] + [header[-1].replace("GPST", label, 1)]
    for ln in body:
        f = ln.split()
        t = pd.Timestamp(f"{f[0].replace('/', '-')} {f[1]}")
        out.append(" ".join([fn(t), *f[2:]]))
    return "\n".join(out) + "\n"


def test_utc_and_jst_are_converted_to_gps_time(walk):
    stamp = lambda t: t.strftime("%Y/%m/%d %H:%M:%S.%f")[:-3]  # noqa: E731
    utc = _read(_retimed(lambda t: stamp(t - pd.Timedelta(seconds=18)), "UTC"))
    jst = _read(_retimed(lambda t: stamp(t - pd.Timedelta(seconds=18) + pd.Timedelta(hours=9)), "JST"))
    for other in (utc, jst):
        np.testing.assert_allclose(other.data["time_s"], walk.data["time_s"], rtol=0, atol=1e-6)
    assert utc.time_scale == "UTC" and jst.time_scale == "JST"
    assert solution.gps_minus_utc(pd.Timestamp("2016-12-31 23:59:59")) == 17
    assert solution.gps_minus_utc(pd.Timestamp("2017-01-01")) == 18


def test_gps_week_and_seconds_and_epochs(walk):
    def week_tow(t):
        s = (t - pd.Timestamp("1980-01-06")) / pd.Timedelta(seconds=1)
        return f"{int(s // 604800)} {s % 604800:.3f}"

    tow = _read(_retimed(week_tow, "GPST"))
    np.testing.assert_allclose(tow.data["time_s"], walk.data["time_s"], rtol=0, atol=1e-6)
    gps = solution.read_pos(POS, epoch="gps")
    offset = (pd.Timestamp("1980-01-06") - pd.Timestamp("1970-01-01")) / pd.Timedelta(seconds=1)
    np.testing.assert_allclose(gps.data["time_s"] + offset, walk.data["time_s"], rtol=0, atol=1e-6)
    mine = solution.read_pos(POS, epoch="2025-08-28 17:30:00")
    assert mine.data["time_s"].iloc[0] == pytest.approx(39.749, abs=1e-6)


def _ecef(lat, lon, h):
    n = A / np.sqrt(1 - E2 * np.sin(lat) ** 2)
    return np.array([(n + h) * np.cos(lat) * np.cos(lon), (n + h) * np.cos(lat) * np.sin(lon), (n * (1 - E2) + h) * np.sin(lat)])


def _c_ne(lat, lon):
    """C_n^e: columns north, east, down in ECEF."""
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    return np.array([[-sl * co, -so, -cl * co], [-sl * so, co, -cl * so], [cl, 0.0, -sl]])


def _sqvar(c):
    return np.sign(c) * np.sqrt(abs(c))


def test_ecef_solution_with_correlated_covariance():
    lat, lon, h = np.radians(40.0966916), np.radians(-105.1471665), 1601.435
    cov_ned = np.array([[0.04, 0.01, -0.005], [0.01, 0.09, 0.02], [-0.005, 0.02, 0.25]])
    c_ne = _c_ne(lat, lon)
    cov_e = c_ne @ cov_ned @ c_ne.T
    xyz = _ecef(lat, lon, h)
    head = "%  GPST                  x-ecef(m)      y-ecef(m)      z-ecef(m)   Q  ns   sdx(m)   sdy(m)   sdz(m)  sdxy(m)  sdyz(m)  sdzx(m) age(s)  ratio"
    rows = [f"2025/08/28 17:30:{39 + k}.000 {xyz[0]:.4f} {xyz[1]:.4f} {xyz[2]:.4f} 2 12 "
            + " ".join(f"{v:.12f}" for v in [*np.sqrt(np.diag(cov_e)), _sqvar(cov_e[0, 1]), _sqvar(cov_e[1, 2]), _sqvar(cov_e[2, 0])])
            + " 1.0 0.0" for k in range(3)]
    got = _read("\n".join([head, *rows]) + "\n")
    d = got.data.iloc[0]
    assert d["lat_rad"] == pytest.approx(lat, abs=1e-10) and d["lon_rad"] == pytest.approx(lon, abs=1e-10)
    assert d["h_m"] == pytest.approx(h, abs=1e-4) and d["quality"] == "float"
    back = np.array([[d["cov_nn_m2"], d["cov_ne_m2"], d["cov_dn_m2"]], [d["cov_ne_m2"], d["cov_ee_m2"], d["cov_ed_m2"]],
                     [d["cov_dn_m2"], d["cov_ed_m2"], d["cov_dd_m2"]]])
    np.testing.assert_allclose(back, cov_ned, atol=1e-10)
    assert not got.has_velocity


def test_signed_covariances_and_degree_minute_second_positions(walk):
    header, body = _lines()
    f = body[0].split()
    f[10], f[11], f[12] = "-0.5000000", "0.3000000", "-0.2000000"  # sdne, sdeu, sdun
    lat, lon = float(f[2]), float(f[3])

    def dms(x):
        d = int(abs(x))
        m = int((abs(x) - d) * 60)
        s = (abs(x) - d - m / 60) * 3600
        return f"{'-' if x < 0 else ''}{d} {m:02d} {s:.7f}"

    head = header[-1].replace("latitude(deg)", "latitude(d'\")").replace("longitude(deg)", "longitude(d'\")")
    line = " ".join([f[0], f[1], dms(lat), dms(lon), *f[4:]])
    got = _read(head + "\n" + line + "\n").data.iloc[0]
    assert got["lat_rad"] == pytest.approx(np.radians(lat), abs=1e-11)
    assert got["lon_rad"] == pytest.approx(np.radians(lon), abs=1e-11)
    # NEU → NED: the up axis changes sign, so do the east-up and up-north covariances
    assert got["cov_ne_m2"] == pytest.approx(-0.25) and got["cov_ed_m2"] == pytest.approx(-0.09)
    assert got["cov_dn_m2"] == pytest.approx(0.04)


def test_fixes_scale_the_file_sigma_by_quality(walk):
    fixes = walk.position_fixes()
    d = walk.data
    assert len(fixes) == len(d)
    flt = np.flatnonzero(d["quality"].to_numpy() == "float")[0]
    assert fixes.cov[flt, 0, 0] == pytest.approx(4.0 * d["cov_nn_m2"].iloc[flt])  # float: σ × 2
    only_fixed = walk.position_fixes({"fix": 1.0})
    assert len(only_fixed) == 349
    np.testing.assert_array_equal(only_fixed.time, d.loc[d["quality"] == "fix", "time_s"].to_numpy())
    vel = walk.velocity_fixes({"fix": 3.0})
    assert vel.cov[0, 1, 1] == pytest.approx(9.0 * d["cov_vee_m2s2"].iloc[0])
    np.testing.assert_array_equal(vel.value[:, 2], d.loc[d["quality"] == "fix", "vd_mps"].to_numpy())


@pytest.mark.parametrize("gains", [{"fixed": 1.0}, {"fix": 0.0}, {"fix": float("nan")}])
def test_bad_gains_name_gains(walk, gains):
    with pytest.raises(an.InputError) as e:
        walk.position_fixes(gains)
    assert e.value.parameter == "gains"


def _broken(edit):
    header, body = _lines()
    body = list(body)
    edit(body)
    return "\n".join(header + body) + "\n"


def _set_field(body, row, col, value):
    f = body[row].split()
    f[col] = value
    body[row] = " ".join(f)


@pytest.mark.parametrize("edit, line, words", [
    (lambda b: _set_field(b, 4, 5, "9.0000000"), 5, "unknown solution quality Q = 9"),
    (lambda b: b.__setitem__(6, " ".join(b[6].split()[:12])), 7, "truncated"),
    (lambda b: _set_field(b, 8, 4, "16O1.4"), 9, "not a number"),
    (lambda b: b.__setitem__(10, b[9]), 11, "does not increase"),
    (lambda b: _set_field(b, 2, 1, "17:30:99.999"), 3, "not an RTKLIB time"),
])
def test_bad_lines_name_source_and_line(edit, line, words):
    header, _ = _lines()
    with pytest.raises(an.InputError, match=words) as e:
        _read(_broken(edit))
    assert e.value.parameter == "source" and e.value.index == len(header) + line


def test_extra_trailing_fields_are_ignored(walk):
    """Programs writing RTKLIB's format append their own columns (as the walk's source
    filter does); RTKLIB reads the named fields and ignores the rest."""
    got = _read(_broken(lambda b: b.__setitem__(6, b[6] + " 1.0 2.0")))
    pd.testing.assert_frame_equal(got.data, walk.data, check_exact=True)


def test_bad_header_and_epoch():
    _, body = _lines()
    with pytest.raises(an.InputError, match="no RTKLIB column header"):
        _read("\n".join(body[:5]) + "\n")
    with pytest.raises(an.InputError, match="e-baseline"):
        _read("%  GPST  e-baseline(m) n-baseline(m) u-baseline(m) Q ns\n")
    with pytest.raises(an.InputError) as e:
        solution.read_pos(POS, epoch="yesterday-ish")
    assert e.value.parameter == "epoch"
    with pytest.raises(an.InputError) as e:
        solution.read_pos(POS, epoch=pd.Timestamp("2025-01-01", tz="UTC"))
    assert e.value.parameter == "epoch"
