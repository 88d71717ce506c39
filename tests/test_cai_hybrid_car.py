"""Issue 5, car Monte Carlo (seed 003 Fig. 9, spec atom-strapdown §2.8 ``car_mc``), kinematic mode."""

import numpy as np
import pytest

from atomnav import cai


@pytest.fixture(scope="module", params=[pytest.param(8, id="8-runs"), pytest.param(100, id="100-runs", marks=pytest.mark.slow)])
def car(request):
    return cai.car_mc(request.param, progress=False)


def test_velocity_gain_at_25s_is_at_least_30(car):
    r = car.improvement([25.0]).query("quantity == 'velocity' and axis == 'norm'")["ratio"].iloc[0]
    assert r >= 30, r


def _jump(car, a, b):
    """Hybrid velocity-error RMS and gyro-bias-error RMS over runs: value at the window start
    and maximum inside [a, b] s (spec §4: both increase within the spike windows)."""
    rms = car.rms("hybrid")["vel_norm_mps"].to_numpy()
    gb = np.sqrt(np.mean((car.bias[:, :, 3:] - car.bias_true[:, :, 3:]) ** 2, axis=(0, 2)))
    k, inside = car.epoch(a), (car.time > a) & (car.time <= b)
    return (rms[k], rms[inside].max()), (gb[k], gb[inside].max())


def test_error_jumps_at_the_26s_shock(car):
    (v0, v1), (g0, g1) = _jump(car, 25.5, 27.0)
    assert v1 > 1.1 * v0 and g1 > g0, (v0, v1, g0, g1)


def test_error_rises_in_the_33_35s_vibration_window(car):
    # the ×2 vibration of 33-35 s is a weak effect: resolved with 100 runs only
    if car.runs < 100:
        pytest.skip("needs the full 100-run Monte Carlo (-m slow)")
    (v0, v1), (g0, g1) = _jump(car, 32.5, 35.5)
    assert v1 > v0 and g1 > g0, (v0, v1, g0, g1)


def test_accelerometer_bias_tracks_the_random_walk_inside_3_sigma(car):
    err = car.bias[:, :, :3] - car.bias_true[:, :, :3]
    inside = np.abs(err) <= 3 * car.sigma[:, :, 9:12]
    assert inside.mean() >= 0.95, inside.mean()


def test_fringe_slip_fraction_is_between_1_and_40_percent(car):
    f = car.phase_exceedance()
    assert 0.01 <= f <= 0.40, f


def test_nees_inside_the_95_percent_band_for_85_percent_of_epochs(car):
    assert car.nees_inside(0.95) >= 0.85, car.nees_inside(0.95)
