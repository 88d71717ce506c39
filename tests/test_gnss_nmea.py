"""NMEA 0183 logs (atomnav.gnss.read_nmea) against the same solution in RTKLIB's ``.pos``
format.

Oracle: RTKLIB's ``rnx2rtkp`` wrote one kinematic (fix and float) and one single-point
solution of a real GEONET station twice, as ``.pos`` (GPS time, ellipsoidal height) and as
NMEA (UTC, altitude above the geoid plus geoid separation); ``tests/data/rtklib_0759``.
The ``.pos`` reader is checked on its own in test_gnss_solution.py. Both readings must
agree to the files' rounding, which exercises the UTC → GPS leap seconds (13 s in 2005),
the midnight date roll-over, the height sum and the quality mapping. Edited logs (a
truncated line, a wrong checksum) are built here with the NMEA checksum (XOR of the
characters between ``$`` and ``*``), computed independently of pynmea2.
"""

from __future__ import annotations

import io
from functools import reduce
from pathlib import Path

import numpy as np
import pytest

import atomnav as an
from atomnav.gnss import nmea, read_nmea, read_pos
from atomnav.gnss.solution import SIGMA_GAINS

DATA = Path(__file__).parent / "data" / "rtklib_0759"
R_EARTH = 6.378e6  # m, to turn an angle difference into a distance (upper bound)


def _sentence(body: str) -> str:
    """``$body*hh`` with the NMEA checksum."""
    return f"${body}*{reduce(lambda a, c: a ^ ord(c), body, 0):02X}"


def _lines(name: str) -> list[str]:
    return (DATA / name).read_text().splitlines()


def _read(lines: list[str], **kw):
    return read_nmea(io.StringIO("\n".join(lines) + "\n"), **kw)


@pytest.mark.parametrize("stem, qualities", [("rtk_0759", {"fix": 23, "float": 38}), ("spp_0759", {"single": 11})])
def test_nmea_and_pos_of_one_solution_agree(stem, qualities):
    pos = read_pos(DATA / f"{stem}.pos").data
    got = read_nmea(DATA / f"{stem}.nmea")
    d = got.data
    assert got.skipped == 0 and got.time_scale == "UTC"
    assert d["quality"].value_counts().to_dict() == qualities
    assert (d["quality"].to_numpy() == pos["quality"].to_numpy()).all()
    assert (d["q"].to_numpy() == pos["q"].to_numpy()).all()
    # NMEA time has 2 decimals, .pos 3: the same GPS-time epochs within 5 ms
    assert np.abs(d["time_s"].to_numpy() - pos["time_s"].to_numpy()).max() <= 5e-3
    # latitude/longitude: 1e-7 arc minute in NMEA (0.19 mm), 1e-9° in .pos (0.11 mm)
    assert np.abs(d["lat_rad"] - pos["lat_rad"]).max() * R_EARTH < 3.5e-4
    assert np.abs(d["lon_rad"] - pos["lon_rad"]).max() * R_EARTH < 3.5e-4
    # ellipsoidal height = altitude + geoid separation (1 mm each) vs 0.1 mm
    assert np.abs(d["h_m"] - pos["h_m"]).max() < 1.2e-3
    assert (d["n_sats"].to_numpy() == pos["n_sats"].to_numpy()).all()


def test_first_epoch_is_the_day_before_in_utc():
    """RTKLIB writes 2005-04-02 00:00:00 GPST as 23:59:47 UTC on 2005-04-01 (13 leap
    seconds); the next epoch, 00:00:17 UTC, takes the next day from its RMC."""
    t = read_nmea(DATA / "rtk_0759.nmea", epoch="2005-04-02").data["time_s"].to_numpy()
    assert t[0] == pytest.approx(0.0, abs=5e-3)
    assert np.diff(t) == pytest.approx(30.0, abs=1e-2)


def test_log_without_rmc_takes_the_date_and_rolls_over_at_midnight():
    gga_only = [ln for ln in _lines("rtk_0759.nmea") if "GGA" in ln]
    with_rmc = read_nmea(DATA / "rtk_0759.nmea").data
    got = _read(gga_only, date="2005-04-01").data
    np.testing.assert_array_equal(got["time_s"], with_rmc["time_s"])
    assert "speed_mps" not in got
    with pytest.raises(an.InputError) as e:
        _read(gga_only)
    assert e.value.parameter == "date"


def test_table_sigma_scales_with_hdop_and_fixes_use_it_as_is():
    sol = read_nmea(DATA / "rtk_0759.nmea")
    d = sol.data
    fix = d["quality"] == "fix"
    # RTKLIB writes HDOP 1.0: the table's σ, vertical twice the horizontal
    assert np.allclose(d.loc[fix, "cov_nn_m2"], nmea.NMEA_SIGMA_M["fix"] ** 2)
    assert np.allclose(d.loc[~fix, "cov_ee_m2"], nmea.NMEA_SIGMA_M["float"] ** 2)
    assert np.allclose(d.loc[fix, "cov_dd_m2"], (2 * nmea.NMEA_SIGMA_M["fix"]) ** 2)
    assert (d["sigma_source"] == "table").all()
    fixes = sol.position_fixes()
    assert fixes.cov[:, 0, 0] == pytest.approx(d["cov_nn_m2"].to_numpy())
    only_fix = read_nmea(DATA / "rtk_0759.nmea", sigma={"fix": 0.05}).position_fixes()
    assert len(only_fix.time) == int(fix.sum())
    assert only_fix.cov[:, 1, 1] == pytest.approx(0.05**2)
    # an HDOP of 2.5 scales the table σ
    lines = _lines("spp_0759.nmea")
    k = next(i for i, ln in enumerate(lines) if "GGA" in ln)
    fields = lines[k][1:lines[k].index("*")].split(",")
    fields[8] = "2.5"
    lines[k] = _sentence(",".join(fields))
    assert _read(lines).data["cov_nn_m2"].iloc[0] == pytest.approx((2.5 * nmea.NMEA_SIGMA_M["single"]) ** 2)


def test_gst_sigma_is_inflated_like_a_pos_file():
    lines = _lines("rtk_0759.nmea")
    k = next(i for i, ln in enumerate(lines) if "GGA" in ln)
    time = lines[k].split(",")[1]
    lines.insert(k + 1, _sentence(f"GPGST,{time},0.5,0.12,0.08,10.0,0.11,0.09,0.25"))
    d = _read(lines).data
    q = d["quality"].iloc[0]
    gain = SIGMA_GAINS[q]
    assert d["sigma_source"].tolist()[:2] == ["GST", "table"]
    assert d["cov_nn_m2"].iloc[0] == pytest.approx((0.11 * gain) ** 2)
    assert d["cov_ee_m2"].iloc[0] == pytest.approx((0.09 * gain) ** 2)
    assert d["cov_dd_m2"].iloc[0] == pytest.approx((0.25 * gain) ** 2)


def test_no_fix_epochs_are_skipped_and_counted():
    lines = _lines("spp_0759.nmea")
    lines.insert(2, _sentence("GPGGA,,,,,,,,,,,,,,"))
    lines.insert(2, _sentence("GPGGA,235950.00,3509.6521008,N,13936.8295461,E,0,00,,,M,,M,,"))
    sol = _read(lines)
    assert sol.skipped == 2 and len(sol.data) == 11


def _edited(edit):
    lines = _lines("rtk_0759.nmea")
    k = 4  # the third epoch's RMC is line 5, its GGA line 6
    return edit(lines, k), k


@pytest.mark.parametrize("edit, words, line", [
    (lambda ls, k: ls[:k + 1] + [ls[k + 1][:40]] + ls[k + 2:], "checksum", 2),  # truncated GGA
    (lambda ls, k: ls[:k + 1] + [ls[k + 1][:-2] + "00"] + ls[k + 2:], "checksum", 2),  # wrong checksum
    (lambda ls, k: ls[:k + 1] + [_sentence(ls[k + 1][1:ls[k + 1].index("*")].replace(",E,4,", ",E,9,")
                                           .replace(",E,5,", ",E,9,"))] + ls[k + 2:], "quality", 2),
    # the third and fourth epochs swapped: the third's GGA, now on line k + 4, goes back in time
    (lambda ls, k: ls[:k] + ls[k + 2:k + 4] + ls[k:k + 2] + ls[k + 4:], "increase", 4),
])
def test_bad_lines_name_source_and_line(edit, words, line):
    lines, k = _edited(edit)
    with pytest.raises(an.InputError) as e:
        _read(lines)
    assert e.value.parameter == "source" and words in str(e.value)
    assert e.value.index == k + line and f"line {k + line}" in str(e.value)


@pytest.mark.parametrize("sigma", [{"rtk": 0.1}, {"fix": 0.0}, {"fix": float("nan")}, {"fix": "0.1"}])
def test_bad_sigma_names_sigma(sigma):
    with pytest.raises(an.InputError) as e:
        read_nmea(DATA / "rtk_0759.nmea", sigma=sigma)
    assert e.value.parameter == "sigma"


def test_log_without_a_fix_names_source():
    with pytest.raises(an.InputError) as e:
        _read([_sentence("GPGGA,,,,,,,,,,,,,,"), "some text"])
    assert e.value.parameter == "source"


def test_wrong_types_raise_type_error():
    with pytest.raises(TypeError, match="sigma"):
        read_nmea(DATA / "rtk_0759.nmea", sigma="fraction")
    with pytest.raises(TypeError, match="source"):
        read_nmea(3.0)


def test_a_file_name_with_a_null_byte_names_source():
    with pytest.raises(an.InputError) as e:
        read_nmea("\x00")
    assert e.value.parameter == "source"
