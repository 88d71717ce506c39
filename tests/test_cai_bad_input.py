"""Bad input → ValueError naming the field (and the shot where one is involved)."""

import numpy as np
import pytest

from atomnav import InputError, cai

N = 201
T_IMU = np.arange(N) * 1e-3
F = np.tile([0.0, 0.0, -9.8], (N, 1))
W = np.zeros((N, 3))
CH = cai.Channels.cyclic()


def predict(**kw):
    args = dict(t=T_IMU, specific_force=F, angular_rate=W, shots=[0.01, 0.07], T=0.025, channels=CH)
    args.update(kw)
    return cai.predict_phase(args.pop("t"), args.pop("specific_force"), args.pop("angular_rate"), args.pop("shots"),
                             args.pop("T"), args.pop("channels"), **args)


@pytest.mark.parametrize("T", [0.0, -0.01])
def test_nonpositive_T(T):
    with pytest.raises(ValueError, match="T: must be finite and > 0"):
        predict(T=T)


def test_pulse_times_outside_record():
    with pytest.raises(ValueError, match=r"shots: shot 1: pulse times .* outside the IMU record"):
        predict(shots=[0.01, 0.16])


def test_zero_k():
    k = CH.k.copy()
    k[3] = 0
    with pytest.raises(ValueError, match=r"channels\[3\]\.k: zero wave vector"):
        predict(channels=cai.Channels(k, CH.lever, CH.c_sb, CH.v0))


@pytest.mark.parametrize("c", [0.0, 1.2, -0.5])
def test_contrast_outside_unit_interval(c):
    with pytest.raises(ValueError, match="contrast: must be in"):
        cai.readout(0.3, contrast=c)


def test_overlapping_shots():
    with pytest.raises(ValueError, match="shots: shot 2 starts at .* before shot 1 ends"):
        predict(shots=[0.01, 0.06, 0.1])


def test_nan_in_imu_stream_names_shot_and_field():
    w = W.copy()
    w[85, 1] = np.nan
    with pytest.raises(ValueError, match=r"angular_rate: non-finite value .* at index 85 .*used by shot 1"):
        predict(angular_rate=w)
    f = F.copy()
    f[20, 0] = np.inf
    with pytest.raises(ValueError, match=r"specific_force: non-finite value .* at index 20 .*used by shot 0"):
        predict(specific_force=f)


def test_unidentifiable_noise_triple_is_reported():
    p, psi = cai.simulate_fringe(300, seed=3)
    with pytest.raises(ValueError, match="jointly unidentifiable"):
        cai.identify_noise(p - 0.5, psi, np.full(300, 0.15), free=("p0", "phi", "A"))


# --- regressions of the boundary fuzz (exact arguments of the reports) --------------------


@pytest.mark.parametrize("substeps", [2**31, 2**63, 2**64, -1])
def test_huge_substep_count_is_checked_before_allocation(substeps):
    # 2**31 RK4 substeps per interval once allocated their grid and aborted the process
    with pytest.raises(InputError) as e:
        predict(substeps=substeps)
    assert e.value.parameter == "substeps"


@pytest.mark.parametrize("half_width", [2**63, 2**64, 2**31])
def test_huge_savgol_half_width_is_checked_not_wrapped(half_width):
    # 2**63 wrapped around in 2m + 1 and the stencil loop never ended
    with pytest.raises(InputError) as e:
        predict(omega_dot="savgol", savgol_half_width=half_width)
    assert e.value.parameter == "savgol_half_width"


@pytest.mark.parametrize("call, parameter", [
    (lambda: cai.in_shot_noise(cai.seed003_sensor(), 5e-324, 1e-11, 1e-12), "dt"),
    (lambda: cai.expected_phase_exceedance(cai.seed003_sensor(), 5e-324, 1e-11, 1e-12), "dt"),
    (lambda: cai.dynamic_range(5e-324), "T"),
])
def test_denormal_step_is_rejected_not_a_nan(call, parameter):
    with pytest.raises(InputError) as e:
        call()
    assert e.value.parameter == parameter


@pytest.mark.parametrize("call, parameter", [
    (lambda: cai.in_shot_noise({"a": 1}, 0.005, 1e-11, 1e-12), "sensor"),
    (lambda: cai.expected_phase_exceedance(np.zeros(3), 0.005, 1e-11, 1e-12), "sensor"),
    (lambda: cai.motion_imu(np.zeros(3), [0.0, 1.0]), "motion"),
    (lambda: cai.run_campaign(np.zeros(3), cai.ScenarioConfig(cai.seed003_sensor(), cai.seed003_filter())), "trajectory"),
    (lambda: cai.satellite_psd(None), "res"),
    (lambda: cai.satellite_steady_state("1.0"), "res"),
    (lambda: cai.readout([0.1], offset="x"), "offset"),
    (lambda: cai.convolution_phase(np.nan, 69.4, 1e-9, t_dark="paper", tau=841.6, k=" rates"), "t_dark"),
])
def test_wrong_types_are_type_errors_naming_the_parameter(call, parameter):
    with pytest.raises(TypeError, match=parameter):
        call()


@pytest.mark.parametrize("call, parameter", [
    (lambda: cai.readout_variance("nope", np.zeros((2, 3)), []), None),
    (lambda: cai.sagnac_phase(0.3, 0.3, 0.3, -1), "k"),
    (lambda: cai.invert_readout(np.zeros((5, 9)), contrast=np.full((15, 3), 9.0).tolist()), "contrast"),
    (lambda: cai.invert_readout(np.zeros(3), flank="up"), "flank"),
    (lambda: cai.simulate_fringe(-1), "n"),
    (lambda: cai.Channels(np.eye(3), 0.0, np.eye(3), 0.0, ["x"]), "names"),
    (lambda: cai.seed003_filter().p0(2), "n_extra"),
    (lambda: cai.capture_limits(0.025, v0=0.0), "v0"),
])
def test_bad_values_name_a_parameter_of_the_call(call, parameter):
    with pytest.raises((InputError, TypeError)) as e:
        call()
    if parameter is not None:
        assert e.type is InputError and e.value.parameter == parameter


def test_invert_readout_of_none_is_not_nan():
    # None became a NaN readout and a NaN phase
    with pytest.raises((InputError, TypeError)):
        cai.invert_readout(None, 0.0, contrast=1.0, flank="rising")


def test_a_bad_sensor_field_is_named_through_the_argument():
    sensor = cai.accelerometer_sensor(T=-65.2)
    with pytest.raises(InputError) as e:
        cai.in_shot_noise(sensor, 0.005, 1e-11, 1e-12)
    assert e.value.parameter == "sensor.T"


@pytest.mark.parametrize("call, error", [(lambda: cai.acceleration_noise(1, T=5e-324, k=5e-324), InputError),
                                         (lambda: cai.readout_jacobian(np.float32(1), None, None), TypeError)])
def test_no_zero_division_or_nan_from_tiny_or_missing_values(call, error):
    with pytest.raises(error):
        call()


@pytest.mark.parametrize("call, parameter", [
    (lambda: cai.predictor.scale_factors(T=1e308, k=100, v0=100.0), "T"),  # was OverflowError
    (lambda: cai.predictor.phase_noise(sigma_p=1e308), "sigma_p"),  # was inf, silently
    (lambda: cai.predictor.in_shot_noise_phase(1.0, 1.0, 1e300), "T"),  # was OverflowError
    (lambda: cai.predictor.sagnac_phase([[1.0, 0, 0]], [0, 1.0, 0], [0, 0, 1.0], 1e200), "T"),
    (lambda: cai.predictor.phase_seed000(np.eye(3)[:2], np.zeros((3, 3)), [0, 0, 1e-3], [0, 0, -9.8], 0.1), "vbar"),
])
def test_overflow_and_parameter_names_found_by_the_fuzz(call, parameter):
    """A finite input whose result overflows names that input; a core error about a
    wrapper's renamed argument names the wrapper's parameter."""
    with pytest.raises(InputError) as e:
        call()
    assert e.value.parameter == parameter


def test_negative_zero_noise_is_zero_noise():
    """σ = −0.0 passes the ≥ 0 check and must reach numpy's sampler as 0.0 (it rejects −0.0)."""
    p, _ = cai.noise_id.simulate_fringe(16, p0=0.5, sigma_p0=-0.0, sigma_phi=-0.0, sigma_A=-0.0, seed=1)
    p_ref, _ = cai.noise_id.simulate_fringe(16, p0=0.5, sigma_p0=0.0, sigma_phi=0.0, sigma_A=0.0, seed=1)
    assert np.array_equal(p, p_ref)
