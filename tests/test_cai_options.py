"""Every CAI option is checked once, by the core: one bad value per option raises
``atomnav.InputError`` naming the real parameter, and the option lists Python shows are the
core's (``_core.OPTIONS``). The CAI configurations round-trip through dict and JSON."""

import dataclasses

import numpy as np
import pytest

import atomnav as an
from atomnav import _core, cai

from test_cai_bad_input import predict as _predict


def _sensor(**kw):
    return cai.in_shot_noise(dataclasses.replace(cai.seed003_sensor(), **kw), 0.005, 1e-11, 1e-12)


def _aided_ins_data_kind(kind):
    from atomnav.filter.aided import InsSetup
    from atomnav.filter.engine import BiasModel

    rw = BiasModel("random_walk", psd=1e-10)
    ins = InsSetup(t0=0.0, lla0=(0.9, 0.1, 0.0), vel0=(0, 0, 0), q0=(1.0, 0, 0, 0), kind="rates", p0=cai.seed003_filter().p0(0),
                   accel_psd=1e-11, gyro_psd=1e-12, accel_bias=rw, gyro_bias=rw, predict_every=10).native
    table = np.zeros((1, 6))
    source = _core.cai_source(extra0=np.zeros(0), extra_var=None, sensor=cai.seed003_sensor()._native(), shots=np.array([0.1]),
                              data_kind=kind, data_a=table, data_b=table, incomplete_shots="skip")
    _core.aided_ins_from_sources(ins, [source])


def _campaign(**kw):
    motion = _core.Motion.stationary(np.array(cai.HANNOVER), 1.0, np.zeros(3))
    config = cai.ScenarioConfig(cai.seed003_sensor(), cai.seed003_filter(), **kw)
    cai.run_campaign(motion, config, runs=1, progress=False)


BAD = {
    "omega_dot (predictor)": (lambda: _predict(omega_dot="spline"), "omega_dot"),
    "interpolation (predictor)": (lambda: _predict(interpolation="quintic"), "interpolation"),
    "savgol_half_width (predictor)": (lambda: _predict(savgol_half_width=-1), "savgol_half_width"),
    # a field of the sensor argument is named through it (sensor.<field>)
    "omega_dot (sensor)": (lambda: _sensor(omega_dot="spline"), "sensor.omega_dot"),
    "omega_dot given (sensor)": (lambda: _sensor(omega_dot="given"), "sensor.omega_dot"),
    "interpolation (sensor)": (lambda: _sensor(interpolation="quintic"), "sensor.interpolation"),
    "force (sensor)": (lambda: _sensor(force="both"), "sensor.force"),
    "closed form kind": (lambda: _core.cai_phase_closed_form("taylor", np.eye(3), np.zeros((3, 3)), np.zeros(3), np.zeros(3),
                                                             np.zeros(3), None, 0.025), "kind"),
    "noise identification method": (lambda: cai.identify_noise(np.zeros(10), np.zeros(10), np.ones(10), method="bfgs"), "method"),
    "gravity (Monte Carlo)": (lambda: cai.car_mc(1, gravity="moon", progress=False), "gravity"),
    "gravity (covariance)": (lambda: cai.slalom_covariance("moon"), "gravity"),
    "phase source": (lambda: _campaign(phase_source="oracle"), "phase_source"),
    "data kind": (lambda: _aided_ins_data_kind("simulated"), "data_kind"),
}


@pytest.mark.parametrize("case", list(BAD), ids=list(BAD))
def test_bad_option_names_its_parameter(case):
    call, parameter = BAD[case]
    with pytest.raises(an.InputError) as e:
        call()
    assert e.value.parameter == parameter, str(e.value)


def test_option_lists_come_from_the_core():
    assert _core.OPTIONS["OmegaDot"] == ["zero", "pwl", "savgol", "given"]
    assert _core.OPTIONS["Interpolation"] == ["linear", "cubic"]
    assert _core.OPTIONS["Gravity"] == ["kinematic", "earth"]
    assert cai.sensor.FORCE_OPTIONS == ("bias", "direct")
    assert cai.scenarios.PHASE_SOURCE_OPTIONS == ("ideal", "reference")


def test_sensor_and_scenario_round_trip_through_json():
    s = dataclasses.replace(cai.seed003_sensor(lever=(0.0, 0.01, 0.1)), force="direct", force_tau=0.05, force_sigma=1e-4,
                            misalignment_psd=1e-12)
    back = cai.CaiSensor.from_json(s.to_json())
    assert back.to_dict() == s.to_dict()
    assert back.inflation == s.inflation and back.force == "direct"
    np.testing.assert_array_equal(back.channels.k, s.channels.k)
    # the rebuilt sensor is the same instrument for the core
    np.testing.assert_array_equal(cai.in_shot_noise(back, 0.005, 1e-11, 1e-12)[0], cai.in_shot_noise(s, 0.005, 1e-11, 1e-12)[0])
    cfg = cai.ScenarioConfig(s, cai.seed003_filter(), gravity="earth", truth_rate_hz=None, phase_source="reference", reference="navigation")
    again = cai.ScenarioConfig.from_json(cfg.to_json())
    assert again.to_dict() == cfg.to_dict()
    assert isinstance(again.sensor, cai.CaiSensor) and isinstance(again.setup, cai.FilterSetup)
    assert again.setup.sigma0 == cfg.setup.sigma0
    with pytest.raises(TypeError, match="unknown field"):
        cai.CaiSensor.from_dict({**s.to_dict(), "colour": "red"})


def test_direct_force_needs_its_parameters():
    with pytest.raises(an.InputError) as e:
        _sensor(force="direct")
    assert e.value.parameter == "sensor.force"
    with pytest.raises(an.InputError) as e:
        _sensor(force="direct", force_tau=-1.0, force_sigma=1e-4)
    assert e.value.parameter == "sensor.force_tau"


def test_shot_schedule_is_the_cores():
    s = cai.seed003_sensor()
    np.testing.assert_allclose(s.shots(0.0, 1.0), 0.05 * np.arange(20), atol=1e-15)
    s.shot_period = 0.1
    assert len(s.shots(0.0, 1.0)) == 10


def _positional(obj) -> int:
    import inspect

    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return 0
    kinds = (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    return sum(p.kind in kinds and p.name not in ("self", "cls") for p in sig.parameters.values())


def test_no_public_cai_callable_takes_more_than_eight_positional_parameters():
    import inspect

    names = [n for n in dir(cai) if not n.startswith("_") and callable(getattr(cai, n)) and not inspect.ismodule(getattr(cai, n))]
    core = [n for n in dir(_core) if n.startswith(("cai_", "Cai", "nav_errors"))] + ["Motion"]
    targets = [getattr(cai, n) for n in names] + [getattr(_core, n) for n in core]
    targets += [getattr(_core.Motion, n) for n in dir(_core.Motion) if not n.startswith("_")]
    too_many = [getattr(t, "__qualname__", str(t)) for t in targets if _positional(t) > 8]
    assert too_many == []
