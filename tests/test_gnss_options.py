"""GNSS options (:class:`atomnav.gnss.GnssOptions`): one checked configuration for
simulation, single-point positioning and tight coupling; options by name through the
core's list; dict/JSON round trip; no public GNSS call with more than 8 positional
parameters."""

import inspect

import numpy as np
import pytest

import atomnav as an
from atomnav import _core, gnss
from atomnav.gnss import GnssOptions, observations, options, scenarios, spp, tight


def test_bad_formulation_names_its_parameter():
    with pytest.raises(an.InputError) as e:
        GnssOptions(formulation="double_difference")
    assert e.value.parameter == "formulation"
    assert gnss.FORMULATIONS == tuple(_core.OPTIONS["Formulation"]) == ("first_difference", "clock_states")


@pytest.mark.parametrize("field, bad, parameter", [
    ("sigma_code", 0.0, "sigma_code"), ("sigma_code_glonass", -1.0, "sigma_code_glonass"), ("sigma_rate", np.nan, "sigma_rate"),
    ("tau_psd", -1e-30, "tau_psd"), ("sigma_clock0", (1.0, 0.0), "sigma_clock0"), ("lever_arm", (0.0, np.inf, 0.0), "lever_arm"),
])
def test_bad_numbers_name_their_field(field, bad, parameter):
    with pytest.raises(an.InputError) as e:
        GnssOptions(**{field: bad})
    assert e.value.parameter == parameter


def test_dict_and_json_round_trip():
    o = GnssOptions(formulation="clock_states", lever_arm=(1.0, -0.5, -2.0), sigma_code_glonass=5.0, iono=False)
    assert GnssOptions.from_dict(o.to_dict()) == o
    assert GnssOptions.from_json(o.to_json()) == o
    assert o.to_dict()["lever_arm"] == [1.0, -0.5, -2.0]


def test_keywords_and_options_object_agree():
    eph = gnss.Ephemerides.nominal(0.0, 600.0, seed=1)
    lla = np.array([np.radians(55.75), np.radians(37.6), 200.0])
    t = np.array([100.0, 101.0])
    a = gnss.simulate(eph, t, np.tile(lla, (2, 1)), np.zeros((2, 3)), sigma_code=1.0, iono=False, seed=3)
    b = gnss.simulate(eph, t, np.tile(lla, (2, 1)), np.zeros((2, 3)), GnssOptions(sigma_code=1.0, iono=False), seed=3)
    assert a.equals(b)
    s1 = gnss.solve(eph, a, use_tau=False, iono=False).epochs
    s2 = gnss.solve(eph, a, GnssOptions(use_tau=False, iono=False)).epochs
    assert s1.equals(s2) and list(s1.columns) == list(_core.SPP_COLUMNS)
    with pytest.raises(TypeError, match="sigma_kode"):
        gnss.solve(eph, a, sigma_kode=1.0)


def _positional(fn) -> int:
    kinds = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    return sum(p.kind in kinds for p in inspect.signature(fn).parameters.values())


@pytest.mark.parametrize("module", [observations, options, scenarios, spp, tight], ids=lambda m: m.__name__)
def test_no_public_call_takes_more_than_8_positional_parameters(module):
    calls = [(n, f) for n, f in vars(module).items() if not n.startswith("_") and inspect.isfunction(f)
             and f.__module__ == module.__name__]
    assert [n for n, f in calls if _positional(f) > 8] == []
