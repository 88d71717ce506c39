"""The RINEX writer: a small simulated RINEX 3 observation and navigation file pair is
written, read back and solved, by atomnav and by RTKLIB's rnx2rtkp; malformed files give
InputError naming the path."""

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import atomnav as an

import atomnav.gnss as g
from atomnav import InputError
from atomnav.gnss import rinex

LLA = np.array([np.radians(55.75), np.radians(37.6), 200.0])


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    d = tmp_path_factory.mktemp("rinex")
    eph = g.Ephemerides.nominal(0.0, 600.0, seed=1)
    t = np.arange(0.0, 60.0, 10.0)
    obs = g.simulate(eph, t, np.tile(LLA, (len(t), 1)), np.zeros((len(t), 3)), tau_gps=-340e-9, seed=2)
    return eph, obs, rinex.write_nav(d / "sim.nav.rnx", eph), rinex.write_obs(d / "sim.obs.rnx", obs)


def test_rinex_round_trip_gives_the_same_solution(files):
    eph, obs, nav_path, obs_path = files
    eph2 = rinex.read_nav(nav_path)
    assert eph2.satellites == eph.satellites
    np.testing.assert_array_equal(eph2.ionosphere, eph.ionosphere)      # GPSA/GPSB
    assert [eph2.channel(f"R{k:02d}") for k in range(1, 25)] == [eph.channel(f"R{k:02d}") for k in range(1, 25)]
    obs2 = rinex.read_obs(obs_path, eph2).table
    ref = obs.sort_values(["time_s", "sat"]).reset_index(drop=True)
    assert list(obs2.sat) == list(ref.sat)
    assert np.abs(obs2.code_m - ref.code_m).max() <= 5e-4              # F14.3
    assert np.abs(obs2.rate_mps - ref.rate_mps).max() < 1e-3            # Doppler to 1 mHz
    a, b = g.solve(eph, obs).epochs, g.solve(eph2, obs2).epochs
    assert np.abs(a[["x_m", "y_m", "z_m"]].to_numpy() - b[["x_m", "y_m", "z_m"]].to_numpy()).max() < 0.01
    assert np.abs(b.tau_gps_s + 340e-9).max() < 40e-9


def test_malformed_navigation_file_is_rejected(tmp_path):
    p = tmp_path / "bad.nav"
    p.write_text("this is not a RINEX file\n")
    with pytest.raises(InputError, match="line 1: not a RINEX file") as e:
        rinex.read_nav(p)
    assert e.value.parameter == "path"


def test_malformed_observation_file_is_rejected(files, tmp_path):
    eph, _, _, obs_path = files
    lines = obs_path.read_text().splitlines()
    p = tmp_path / "bad.obs"
    p.write_text("\n".join(["garbage" * 10] + lines[1:]) + "\n")      # no RINEX VERSION / TYPE line
    with pytest.raises(InputError, match="line 1: not a RINEX file") as e:
        rinex.read_obs(p, eph)
    assert e.value.parameter == "path"


def test_missing_file_is_an_os_error(tmp_path):
    with pytest.raises(FileNotFoundError):
        rinex.read_nav(tmp_path / "absent.nav")


def test_path_of_the_wrong_type_names_path():
    with pytest.raises(TypeError, match="path"):
        rinex.read_nav(1.0)


@pytest.mark.skipif(shutil.which("rnx2rtkp") is None, reason="RTKLIB's rnx2rtkp is not installed")
@pytest.mark.parametrize("week_start", [rinex.WEEK_START, pd.Timestamp("2024-12-29").to_pydatetime()])
def test_rtklib_reads_the_written_files_to_the_same_position(tmp_path, week_start):
    """GPS with 1 mm code noise, written for two different GPS weeks: RTKLIB's single point
    of the written pair (broadcast orbits and clocks, the files' Klobuchar set,
    Saastamoinen) lands within 2 cm of the simulated position, as atomnav's does."""
    eph = g.Ephemerides.nominal(0.0, 600.0, seed=1, glonass=False)
    t = np.arange(0.0, 60.0, 10.0)
    obs = g.simulate(eph, t, np.tile(LLA, (len(t), 1)), np.zeros((len(t), 3)), g.GnssOptions(sigma_code=1e-3), seed=2)
    nav = rinex.write_nav(tmp_path / "sim.nav.rnx", eph, week_start=week_start)
    ob = rinex.write_obs(tmp_path / "sim.obs.rnx", obs, week_start=week_start)
    conf = Path(__file__).parent / "data" / "rinex_stations" / "rtklib_spp_gps.conf"
    subprocess.run(["rnx2rtkp", "-k", str(conf), "-o", str(tmp_path / "sim.pos"), str(ob), str(nav)], check=True,
                   capture_output=True)
    pos = pd.read_csv(tmp_path / "sim.pos", sep=r"\s+", comment="%", header=None)
    truth = an.earth.lla_to_ecef(LLA)
    week = (pd.Timestamp(week_start) - pd.Timestamp("1980-01-06")).days // 7
    assert len(pos) == len(t) and (pos.iloc[:, 0] == week).all() and np.allclose(pos.iloc[:, 1] % 604800, t)
    assert np.linalg.norm(pos.iloc[:, 2:5].to_numpy() - truth, axis=1).max() < 0.02
    mine = g.solve(rinex.read_nav(nav), rinex.read_obs(ob, rinex.read_nav(nav)).table).epochs
    assert np.linalg.norm(mine[["x_m", "y_m", "z_m"]].to_numpy() - truth, axis=1).max() < 0.02
