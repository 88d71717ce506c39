"""RINEX through georinex: a small simulated RINEX 3 observation and navigation file pair
is written, read back and solved; malformed files give InputError naming the path."""

import numpy as np
import pytest

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
