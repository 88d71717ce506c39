"""A damaged or mismatched RINEX file raises a ValueError that names the file, the line
and the field: a record cut short (observation and navigation), an unknown RINEX
version, epochs out of order, and a navigation file that does not cover the
observations. Each file is a real station file (tests/data/rinex_stations) with one
defect made here; the expected line is counted on the damaged text itself.
"""

from __future__ import annotations

import gzip
import re
from pathlib import Path

import pytest

from atomnav import InputError
from atomnav.gnss import rinex

D = Path(__file__).parent / "data" / "rinex_stations"
OBS = D / "ESBC00DNK_R_20201770000_01D_30S_MO_cut.rnx.gz"
NAV = D / "ESBC00DNK_R_20201770000_01D_MN_cut12h.rnx.gz"


def _lines(path: Path) -> list[str]:
    return gzip.decompress(path.read_bytes()).decode().splitlines()


def _write(tmp_path: Path, name: str, lines: list[str]) -> Path:
    p = tmp_path / name
    p.write_text("\n".join(lines) + "\n")
    return p


def _epochs(lines: list[str]) -> list[int]:
    return [k for k, line in enumerate(lines) if line.startswith(">")]


@pytest.fixture(scope="module")
def eph():
    return rinex.read_nav(NAV)


def _raises(call, path: Path, line: int, field: str):
    with pytest.raises(ValueError) as e:
        call()
    message = str(e.value)
    assert isinstance(e.value, InputError) and e.value.parameter == "path"
    assert str(path) in message and re.search(rf"line {line}\b", message) and field in message, message


def test_observation_record_cut_short(tmp_path, eph):
    lines = _lines(OBS)
    second = _epochs(lines)[1]
    p = _write(tmp_path, "cut.rnx", lines[:second + 11])          # the file ends 10 satellites into epoch 2
    _raises(lambda: rinex.read_obs(p, eph), p, second + 1, "number of satellites")


def test_navigation_record_cut_short(tmp_path):
    lines = _lines(NAV)
    end = next(k for k, line in enumerate(lines) if "END OF HEADER" in line)
    p = _write(tmp_path, "cut.nav", lines[:end + 1] + [lines[end + 1], lines[end + 2][:30]])  # G01's record cut in line 2
    _raises(lambda: rinex.read_nav(p), p, end + 2, "field ")


def test_navigation_field_that_is_not_a_number(tmp_path):
    lines = _lines(NAV)
    end = next(k for k, line in enumerate(lines) if "END OF HEADER" in line)
    lines[end + 4] = lines[end + 4][:4] + "x.y" + lines[end + 4][7:]     # Toe of G01 garbled
    p = _write(tmp_path, "garbled.nav", lines)
    _raises(lambda: rinex.read_nav(p), p, end + 2, "toe")


@pytest.mark.parametrize("kind", ["obs", "nav"])
def test_unknown_rinex_version(tmp_path, eph, kind):
    lines = _lines(OBS if kind == "obs" else NAV)
    lines[0] = "     7.01" + lines[0][9:]
    p = _write(tmp_path, f"v7.{kind}", lines)
    call = (lambda: rinex.read_obs(p, eph)) if kind == "obs" else (lambda: rinex.read_nav(p))
    _raises(call, p, 1, "RINEX VERSION")


def test_epochs_out_of_order(tmp_path, eph):
    lines = _lines(OBS)
    e = _epochs(lines)
    swapped = lines[:e[1]] + lines[e[2]:e[3]] + lines[e[1]:e[2]] + lines[e[3]:]
    p = _write(tmp_path, "order.rnx", swapped)
    later = e[1] + (e[3] - e[2])                                       # where the earlier epoch now sits
    _raises(lambda: rinex.read_obs(p, eph), p, later + 1, "EPOCH")


def test_navigation_that_does_not_cover_the_observations(eph):
    """DELF's observations of 2021-01-01 with ESBC's navigation records of 2020-06-25."""
    obs = D / "delf0010_cut.21o.gz"
    header = next(k for k, line in enumerate(_lines(obs)) if "END OF HEADER" in line) + 1
    with pytest.raises(InputError) as e:
        rinex.read_obs(obs, eph)
    message = str(e.value)
    assert str(obs) in message and str(NAV) in message and f"line {header + 1}" in message and "EPOCH" in message
