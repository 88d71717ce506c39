"""The aided-INS configuration (:class:`atomnav.filter.InsSetup`): checked by the core,
options by name through the core's lists, dict/JSON round trip, state blocks and the
initial error read from the core, no public call with more than 8 positional parameters."""

import inspect
import json

import numpy as np
import pytest

import atomnav as an
from atomnav import _core
from atomnav.filter import BiasModel, InsSetup, Layout, STANDARD_BLOCKS, INS15, position_aided_ins
from atomnav.filter import aided, engine

LAT, LON, H = 0.8, 0.2, 100.0


def _fields(**extra):
    return {**dict(t0=0.0, lla0=[LAT, LON, H], vel0=[0, 0, 0], q0=[1, 0, 0, 0], kind="rates", p0=np.eye(15),
                   accel_psd=1e-8, gyro_psd=1e-12), **extra}


@pytest.mark.parametrize("option, bad, parameter", [
    ("vertical", "baro", "vertical"),
    ("kind", "velocity", "kind"),
    ("ellipsoid", "GRS67", "ellipsoid"),
    ("accel_bias", BiasModel("flicker"), "accel_bias"),
    ("gyro_bias", BiasModel("pink"), "gyro_bias"),
])
def test_one_bad_value_per_option_names_its_parameter(option, bad, parameter):
    with pytest.raises(an.InputError) as e:
        InsSetup(**_fields(**{option: bad}))
    assert e.value.parameter == parameter


@pytest.mark.parametrize("option, bad", [("predict_every", 0), ("accel_psd", -1.0), ("gate", 0.0), ("baro_psd", -1.0)])
def test_bad_numbers_are_rejected_once_by_the_core(option, bad):
    extra = {"vertical": "damped"} if option == "baro_psd" else {}
    with pytest.raises(an.InputError) as e:
        InsSetup(**_fields(**{option: bad}, **extra))
    assert e.value.parameter == option


def test_p0_must_be_positive_definite():
    p0 = np.eye(15)
    p0[3, 3] = -1.0
    with pytest.raises(an.InputError) as e:
        InsSetup(**{**_fields(), "p0": p0})
    assert e.value.parameter == "p0"


def test_dict_and_json_round_trip():
    s = InsSetup(**_fields(vertical="damped", zeta=0.5, baro_bias=BiasModel("gauss_markov", tau=100.0, sigma=2.0),
                           baro_bias_sigma0=5.0, accel_bias=BiasModel("random_walk", psd=1e-9), gate=9.0))
    d = s.to_dict()
    assert d["baro_bias"] == {"kind": "gauss_markov", "psd": 0.0, "tau": 100.0, "sigma": 2.0}
    assert json.loads(s.to_json())["p0"][3][3] == 1.0
    assert InsSetup.from_dict(d) == s
    assert InsSetup.from_json(s.to_json()) == s
    with pytest.raises(an.InputError) as e:
        InsSetup.from_dict({**d, "zeta_v": 1.0})
    assert e.value.parameter == "zeta_v"


def test_engine_keeps_its_setup():
    ins = position_aided_ins(0.0, [LAT, LON, H], [0, 0, 0], [1, 0, 0, 0], "rates", [0.5], [[LAT, LON, H]], np.eye(3)[None],
                             p0=np.eye(15), accel_psd=1e-8, gyro_psd=1e-12, mode="open")
    assert ins.setup.mode == "open" and InsSetup.from_json(ins.setup.to_json()) == ins.setup


def test_state_blocks_and_options_come_from_the_core():
    assert STANDARD_BLOCKS == dict(_core.STATE_BLOCKS)
    assert INS15 == tuple(_core.INS15)
    assert Layout().size == sum(STANDARD_BLOCKS[b] for b in INS15) == 15
    assert aided.VERTICAL == ("free", "damped")
    assert engine.BIAS_KINDS == ("random_constant", "random_walk", "gauss_markov")


def test_initial_error_against_the_small_error_relations():
    """Independent oracle: with a diagonal P0 the error is σ_i·u_i, the position shift
    δr_N/(M + h), δr_E/((N + h) cos φ), −δr_D (Groves 2013, Eq. 2.119), the attitude
    q̂ = q(−ψ) ⊗ q."""
    sig = np.array([3.0, 4.0, 5.0, 0.1, 0.2, 0.3, 1e-4, 2e-4, 3e-3])
    p0 = np.diag(np.r_[sig ** 2, np.ones(6)])
    u = np.array([0.5, -1.0, 2.0, 1.5, -0.25, 0.75, -2.0, 1.0, 0.1])
    lla, vel, q = _core.initial_error([LAT, LON, H], [1.0, 2.0, 3.0], [1.0, 0.0, 0.0, 0.0], p0, u)
    d = sig * u
    m, n = an.earth.radii(LAT)
    # the difference lla − lla_true carries the rounding of lat (ulp 1.1e-16 rad): absolute tolerance
    np.testing.assert_allclose(lla - [LAT, LON, H], [d[0] / (m + H), d[1] / ((n + H) * np.cos(LAT)), -d[2]], rtol=0, atol=1e-15)
    np.testing.assert_allclose(vel, np.array([1.0, 2.0, 3.0]) + d[3:6], rtol=0, atol=1e-15)
    a = np.linalg.norm(d[6:9])
    np.testing.assert_allclose(q, np.r_[np.cos(a / 2), -np.sin(a / 2) * d[6:9] / a], rtol=0, atol=1e-15)
    with pytest.raises(an.InputError) as e:
        _core.initial_error([LAT, LON, H], [0, 0, 0], [1, 0, 0, 0], np.eye(5), u)
    assert e.value.parameter == "p0"


def _positional(fn) -> int:
    kinds = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    return sum(p.kind in kinds for p in inspect.signature(fn).parameters.values())


@pytest.mark.parametrize("module", [aided, engine], ids=lambda m: m.__name__)
def test_no_public_call_takes_more_than_8_positional_parameters(module):
    calls = [(n, f) for n, f in vars(module).items() if not n.startswith("_") and callable(f)
             and getattr(f, "__module__", None) == module.__name__]
    calls += [(f"{n}.__init__", f.__init__) for n, f in calls if inspect.isclass(f)]
    too_many = [n for n, f in calls if _positional(f) > 9 - ("__init__" not in n)]
    assert too_many == []
