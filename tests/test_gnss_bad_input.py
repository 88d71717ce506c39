"""Bad input to the GNSS functions: a wrong type is a ``TypeError`` naming the parameter,
a bad value an ``atomnav.InputError`` naming a real parameter of the call (boundary fuzz
findings, with their arguments)."""

import numpy as np
import pandas as pd
import pytest

from atomnav import InputError, _core
from atomnav.gnss import Ephemerides, GnssOptions, glonass_propagate, rinex, scenarios, simulate, solve
from atomnav.gnss.observations import doppler_to_rate
from atomnav.gnss.options import split_options


@pytest.fixture(scope="module")
def eph():
    return Ephemerides.nominal(0.0, 60.0, glonass=True, seed=1)


@pytest.mark.parametrize("call, parameter", [
    (lambda e: Ephemerides(_core_obj=np.zeros((6, 15))), "_core_obj"),
    (lambda e: split_options(np.zeros((1, 3)), {}), "options"),
    (lambda e: rinex.write_nav(np.zeros((1, 3)), None), "path"),
    (lambda e: rinex.read_obs(np.zeros((1, 3)), None), "eph"),
    (lambda e: scenarios.build(1e-9), "sc"),
    (lambda e: scenarios.last_rms(np.zeros((1, 3))), "err"),
    (lambda e: solve(None, pd.DataFrame()), "eph"),
    (lambda e: simulate(e, [1.0], [[0.9, 0.6, 0.0]], [[0.0, 0.0, 0.0]], sat_outages=[("G01", 1.0)]), "sat_outages"),
    (lambda e: doppler_to_rate([1.0], [1.0], [0]), "sat"),
])
def test_wrong_types_are_type_errors_naming_the_parameter(eph, call, parameter):
    with pytest.raises(TypeError, match=parameter):
        call(eph)


@pytest.mark.parametrize("call, parameter", [
    (lambda e: scenarios.build("nope"), "sc"),
    (lambda e: scenarios.outage_summary(pd.DataFrame({"time_s": [1.0, 2.0], "horizontal_m": [1.0, 2.0]}), 67.5, -100.0), "start"),
    (lambda e: rinex.write_obs("x.obs", pd.DataFrame({"time_s": [1.0]})), "obs"),
    (lambda e: doppler_to_rate([1.0, 2.0], ["G01"], [0]), "sat"),
    (lambda e: e.top(-1, 0.0, [0.9, 0.6, 0.0]), "n"),
    (lambda e: Ephemerides.nominal(0.0, 10.0, seed=-1), "seed"),
    (lambda e: _core.GnssEphemerides.nominal(0.0, 10.0, seed=2**64), "seed"),
    (lambda e: GnssOptions(lever_arm=(0.0, 1.0)), "lever_arm"),
    (lambda e: GnssOptions(clock0=(0.0, np.nan)), "clock0"),
    (lambda e: glonass_propagate([1e7, 0, 0], [0, 3e3, 0], [0, 0, 0], np.nan), "dt"),
])
def test_bad_values_name_a_parameter_of_the_call(eph, call, parameter):
    with pytest.raises(InputError) as e:
        call(eph)
    assert e.value.parameter == parameter


def test_missing_rinex_file_is_an_os_error(eph, tmp_path):
    with pytest.raises(FileNotFoundError):
        rinex.read_obs(tmp_path / "absent.obs", eph)


def test_empty_error_table_is_rejected_and_an_empty_window_documented():
    err = pd.DataFrame({"time_s": [1.0, 2.0], "horizontal_m": [3.0, 4.0]})
    assert scenarios.last_rms(err, 10.0) == pytest.approx(np.sqrt(12.5))
    assert np.isnan(scenarios.last_rms(err, -5.0)) and "may be non-finite" in " ".join(scenarios.last_rms.__doc__.split())
    with pytest.raises(InputError, match="err"):
        scenarios.last_rms(err.iloc[:0])


@pytest.mark.parametrize("dt, step", [(1.0, 5e-324), (1e308, 1.0)])
def test_glonass_propagation_step_count_is_checked(dt, step):
    # 1 s in steps of 5e-324 s never ended
    with pytest.raises(InputError) as e:
        glonass_propagate([1e7, 2e7, 0.0], [0.0, 0.0, 3e3], [0.0, 0.0, 0.0], dt, step)
    assert e.value.parameter == "step"
