"""The noise boundary never kills the Python process: sizes from input are checked before
anything is allocated, bad lists and integers are InputErrors naming the parameter, and
every option name is checked once, by the Rust core."""

from __future__ import annotations

import json

import numpy as np
import pytest

import atomnav
from atomnav import _core
from atomnav.noise import allan, arma, filters
from atomnav.noise.filters import ArimaStateSpace, ArmaFilterConfig

Y = np.random.default_rng(5).normal(size=200)


def _input_error(parameter, fn, *args, index=None, **kw):
    with pytest.raises(atomnav.InputError) as e:
        fn(*args, **kw)
    assert e.value.parameter == parameter, str(e.value)
    assert e.value.index == index, str(e.value)
    return e.value


def test_stream_sized_beyond_memory_is_an_error_or_lazy():
    # a ring of 3m+1 = 3e9 phase points (2**32 after rounding, 32 GiB): either refused
    # with MemoryError naming m and the size, or reserved without being touched
    try:
        s = _core.AllanStream([10**9], 1.0)
    except MemoryError as e:
        assert str(e).startswith("m: cannot allocate 34359738368 bytes"), str(e)
    else:
        s.update(Y)
        assert len(s.result("allan")[0]) == 0


def test_stream_factor_beyond_the_address_space():
    for m in ([2**62], [4, 2**63]):
        e = _input_error("m", _core.AllanStream, m, 1.0, index=len(m) - 1)
        assert "3m+1" in str(e)
    _input_error("m", allan.AllanStream, [2**62], 1.0, index=0)


@pytest.mark.parametrize("m, index", [([], None), ([1, 0], 1), ([-1], 0), ([1, 2**64], 1), ([2**63, 1], 0)])
def test_bad_factor_lists(m, index):
    _input_error("m", _core.allan_var, Y, 1.0, m=m, index=index)
    _input_error("m", allan.allan_variance, Y, 1.0, m=m, index=index)
    if m:
        _input_error("m", _core.AllanStream, m, 1.0, index=index)


def test_factor_too_large_for_the_record_names_its_index():
    _input_error("m", allan.allan_variance, Y, 1.0, m=[1, 2, 150], index=2)


def test_non_integer_factors_are_type_errors():
    with pytest.raises(TypeError, match="^m: "):
        allan.allan_variance(Y, 1.0, m=[1.5])
    with pytest.raises(TypeError, match="^m: "):
        _core.allan_var(Y, 1.0, m=[1.5])


def test_edf_and_fit_counts():
    _input_error("np", _core.allan_edf, "allan", "white_fm", -1, [1])
    _input_error("m", _core.allan_edf, "modified", "white_fm", 100, [1, 0], index=1)
    t = allan.allan_variance(Y, 1.0)
    _input_error("n_samples", allan.fit_allan_table, t, 2**64)
    _input_error("n_samples", allan.fit_allan_table, t, 0)


@pytest.mark.parametrize("d", [2**63, -1, 9])
def test_differencing_order_is_checked(d):
    _input_error("d", ArimaStateSpace, (0.1,), (), 1.0, d)
    _input_error("d", ArmaFilterConfig, (0.1,), (), 1.0, d=d)


# one bad value per option; `.parameter` is the parameter the caller passed
BAD_OPTIONS = [
    ("kind", lambda: allan.allan_variance(Y, 1.0, kind="overlapping")),
    ("data_type", lambda: allan.allan_variance(Y, 1.0, data_type="frequency")),
    ("noise", lambda: allan.allan_variance(Y, 1.0, noise="pink")),
    ("m", lambda: allan.allan_variance(Y, 1.0, m="octaves")),
    ("kind", lambda: allan.AllanStream([1, 2], 1.0).result("adev")),
    ("data_type", lambda: allan.AllanStream([1, 2], 1.0, data_type="freq")),
    ("noise_form", lambda: ArimaStateSpace((0.1,), (0.2,), 1.0, noise_form="statsmodels")),
    ("noise_form", lambda: ArmaFilterConfig((0.1,), (0.2,), 1.0, noise_form="statsmodels")),
    ("adaptive", lambda: filters.kalman(Y, ArimaStateSpace.paper(), adaptive="eq17")),
    ("adaptive", lambda: filters.KalmanStream(ArimaStateSpace.paper(), adaptive="eq17")),
    ("x0", lambda: filters.kalman(Y, ArimaStateSpace.paper(), x0="last")),
    ("b", lambda: filters.sage_husa(Y, ArimaStateSpace.paper(), b=1.0)),
]


@pytest.mark.parametrize("parameter, call", BAD_OPTIONS, ids=[f"{p}-{i}" for i, (p, _) in enumerate(BAD_OPTIONS)])
def test_bad_option_names_its_parameter(parameter, call):
    _input_error(parameter, call)


def test_option_lists_come_from_the_core():
    assert allan.KINDS == ("allan", "modified", "hadamard")
    assert allan.TAU_SETS == ("octave", "decade", "all")
    assert set(_core.OPTIONS["Adaptive"]) == {"fixed", "literal", "differenced", "sage_husa"}
    assert _core.OPTIONS["X0"] == ["zeros", "first"]


def test_filter_config_round_trips_and_runs():
    m = ArimaStateSpace.paper()
    cfg = ArmaFilterConfig.for_model(m, adaptive="sage_husa", b=0.97, adapt_q=True, x0="first")
    assert ArmaFilterConfig.from_json(cfg.to_json()) == cfg
    assert ArmaFilterConfig.from_dict(json.loads(json.dumps(cfg.to_dict()))) == cfg
    got = filters.filter_series(Y, cfg)
    ref = filters.sage_husa(Y, m, b=0.97, adapt_q=True, x0="first")
    np.testing.assert_array_equal(got.omega_hat, ref.omega_hat)
    s = filters.KalmanStream.from_config(cfg)
    np.testing.assert_array_equal(np.concatenate([s.update(c).omega_hat for c in np.array_split(Y, 3)]), ref.omega_hat)
    with pytest.raises(TypeError):
        ArmaFilterConfig((0.1,), (), 1.0, 1)  # everything after sigma2 is keyword-only


def test_confidence_outside_the_unit_interval():
    # confidence = 1.5 gave NaN interval bounds from finite input
    _input_error("confidence", allan.allan_variance, Y, 1.0, confidence=1.5)
    _input_error("confidence", allan.AllanStream, [1, 2], 1.0, confidence=1.5)
    _input_error("confidence", allan.allan_variance, Y, 1.0, confidence=0.0)


def test_stream_factor_given_as_a_float_is_a_type_error():
    with pytest.raises(TypeError, match="^m: "):
        allan.AllanStream(m=1e9, tau0=1.0)


@pytest.mark.parametrize("call", [
    lambda: filters.kalman(Y, "identity"),
    lambda: filters.sage_husa(Y, "navigation"),
    lambda: filters.KalmanStream("identity"),
    lambda: filters.steady_state_gain(4294967297, 1.0),
    lambda: filters.filter_series(Y, ArimaStateSpace.paper()),
    lambda: filters.KalmanStream.from_config(ArimaStateSpace.paper()),
    lambda: allan.ss_deg_per_sqrt_hour("diagonal"),
])
def test_wrong_instances_are_type_errors(call):
    # these raised AttributeError from inside the call
    with pytest.raises(TypeError, match="^(model|config|fit): expected "):
        call()


def test_acf_lag_count_is_an_integer():
    # fuzz seed 20261202: an empty array as nlags reached numpy's truth-value error
    z = np.random.default_rng(0).standard_normal(200)
    with pytest.raises(TypeError, match="^nlags: "):
        arma.acf_pacf(z, nlags=np.array([]))
    with pytest.raises(atomnav.InputError) as e:
        arma.acf_pacf(z, nlags=0)
    assert e.value.parameter == "nlags"
    assert len(arma.acf_pacf(z, nlags=5)) == 6


def test_fit_arguments_are_typed():
    # fuzz seeds 11 and 12: an array as the differenced flag reached numpy's truth-value
    # error; a Layout given as the Allan table raised the Layout's own error
    z = np.random.default_rng(0).standard_normal(200)
    with pytest.raises(TypeError, match="^differenced: "):
        arma.fit_arma(z, differenced=np.array([1.0, 2.0]))
    with pytest.raises(TypeError, match="^table: "):
        allan.fit_allan_table(atomnav.filter.engine.Layout(blocks=("position",)), 100)
    with pytest.raises(atomnav.InputError) as e:
        allan.fit_allan_table(allan.allan_variance(z, 1.0).drop(columns="var"), 200)
    assert e.value.parameter == "table"
    with pytest.raises(TypeError, match="^n_samples: "):
        allan.fit_allan_table(allan.allan_variance(z, 1.0), False)


def test_core_fit_flags_are_checked():
    # fuzz seed 13: a str of 6 characters as the five term flags gave pyo3's ValueError
    with pytest.raises(TypeError, match="^terms: "):
        _core.allan_fit([1], np.ones(1), np.ones(1), 8, "hybrid", 0.0, 1.0)
    with pytest.raises(atomnav.InputError) as e:
        _core.allan_fit([1], np.ones(1), np.ones(1), 8, [True] * 6, 0.0, 1.0)
    assert e.value.parameter == "terms"
