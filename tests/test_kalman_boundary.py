"""Bad input to the linear Kalman functions raises atomnav.InputError naming the
parameter (or MemoryError naming the size), never kills the process or returns NaN."""

import numpy as np
import pytest

from atomnav import InputError, _core
from atomnav.filter import KalmanFilter, Scenario, discretize, kalman_recursion, monte_carlo, riccati_scalar, rts_smooth


def test_kalman_recursion_huge_steps_is_checked_before_allocation():
    with pytest.raises(InputError) as e:
        kalman_recursion(1.0, 1.0, 1.0, 1.0, 1.0, steps=2**31)
    assert e.value.parameter == "steps"


@pytest.mark.parametrize("steps", [0, -1, 2**64])
def test_kalman_recursion_steps_out_of_range(steps):
    with pytest.raises(InputError) as e:
        kalman_recursion(1.0, 1.0, 1.0, 1.0, 1.0, steps)
    assert e.value.parameter == "steps"


def test_kalman_recursion_steps_must_be_an_int():
    with pytest.raises(TypeError, match="steps"):
        kalman_recursion(1.0, 1.0, 1.0, 1.0, 1.0, 3.5)


def test_kalman_recursion_numpy_int_steps():
    prior, post = kalman_recursion(1.0, 1.0, 1.0, 1.0, 1.0, np.int64(2))
    assert prior.shape == post.shape == (2, 1, 1)


def test_riccati_scalar_tiny_h_is_stable():
    # QR/h² overflows in the textbook form, √(QR)/|h| = 1e200 does not
    p_prior, p_post = riccati_scalar(1.0, 1.0, 1e-200)
    assert np.isfinite([p_prior, p_post]).all()
    assert p_prior == pytest.approx(1e200, rel=1e-12) and p_post == pytest.approx(1e200, rel=1e-12)


def test_riccati_scalar_h_beyond_range_names_h():
    with pytest.raises(InputError) as e:
        riccati_scalar(1.0, 1.0, 1e-310)
    assert e.value.parameter == "h"


def test_riccati_scalar_zero_q_is_not_nan():
    assert riccati_scalar(0.0, 1.0, 1.0) == (0.0, 0.0)


def test_empty_scenario_names_p0():
    z3, z2 = np.zeros((0, 0, 0)), np.zeros((0, 0))
    with pytest.raises(InputError) as e:
        Scenario(z3, z3, np.zeros(0), z2, z2, z2, [True])
    assert e.value.parameter == "p0"


def test_empty_kalman_filter_names_p0():
    with pytest.raises(InputError) as e:
        KalmanFilter(np.zeros((0, 0)))
    assert e.value.parameter == "p0"


@pytest.mark.parametrize("steps", [-1, 2**64])
def test_predict_steps_out_of_range(steps):
    kf = KalmanFilter(np.eye(2), mode="open")
    with pytest.raises(InputError) as e:
        kf.predict(np.eye(2), np.eye(2), steps=steps)
    assert e.value.parameter == "steps"


def test_sequential_update_indefinite_r_names_r():
    kf = KalmanFilter(np.eye(2), mode="open")
    with pytest.raises(InputError) as e:
        kf.update([0.0, 0.0], np.eye(2), [[1.0, 2.0], [2.0, 1.0]], sequential=True)
    assert e.value.parameter == "r"
    assert np.isfinite(kf.p).all()


def test_rts_mismatched_step_shapes_name_the_array():
    n = 3
    phi, p = np.repeat(np.eye(n)[None], 4, axis=0), np.repeat(np.eye(n)[None], 4, axis=0)
    x = np.zeros((4, n))
    with pytest.raises(InputError) as e:
        rts_smooth(phi, x, np.repeat(np.eye(2)[None], 4, axis=0), x, p)
    assert e.value.parameter == "p_prior"
    assert e.value.index == 0


def test_options_from_the_core():
    assert _core.OPTIONS["LoopMode"] == ["closed", "open"]
    assert _core.OPTIONS["Discretization"] == ["van_loan", "first_order"]


def _scenario(**kw):
    return Scenario(np.zeros((2, 1, 1)), np.ones((2, 1, 1)), [1.0, 1.0], [[1.0]], [[1.0]], [[1.0]], [True] * 3, **kw)


@pytest.mark.parametrize("call, parameter", [
    (lambda: KalmanFilter(np.eye(2), mode="feedback"), "mode"),
    (lambda: discretize([[0.0]], [[1.0]], 1.0, method="euler"), "method"),
    (lambda: _scenario(method="euler"), "method"),
    (lambda: monte_carlo(_scenario(), runs=2, seed=0, mode="feedback"), "mode"),
])
def test_bad_option_names_the_parameter(call, parameter):
    with pytest.raises(InputError) as e:
        call()
    assert e.value.parameter == parameter


def test_core_scenario_takes_at_most_8_positional_arguments():
    a = (np.zeros((1, 1, 1)), np.ones((1, 1, 1)), np.ones(1), np.eye(1), np.eye(1), np.eye(1), [True, True])
    with pytest.raises(TypeError):
        _core.Scenario(*a, "van_loan", False)
    assert _core.Scenario(*a, method="first_order", sequential=True) is not None
