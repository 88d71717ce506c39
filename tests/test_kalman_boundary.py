"""Bad input to the linear Kalman functions raises atomnav.InputError naming the
parameter (or MemoryError naming the size), never kills the process or returns NaN."""

import numpy as np
import pytest

from atomnav import InputError, _core
from atomnav.filter import (BiasModel, KalmanFilter, dare, Layout, Scenario, chi2_band, closed_loop_matrix, covariance_analysis, discretize,
                            kalman_recursion, monte_carlo, riccati_scalar, rts_smooth)
from atomnav.filter.analysis import true_error_analysis


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


def test_covariance_analysis_of_an_empty_scenario_does_not_panic():
    # no steps, one epoch: the analysis of the start alone (it panicked on an empty stack)
    z = np.zeros((0, 2, 2))
    df = covariance_analysis(Scenario(z, z, np.zeros(0), np.eye(2), np.eye(2), np.eye(2), [False]))
    assert df.shape == (1, 3)
    np.testing.assert_array_equal(df.iloc[0, 1:].to_numpy(), [1.0, 1.0])


def test_discretize_with_a_denormal_step_is_finite():
    phi, qd = discretize([[0.0, 1.0], [0.0, 0.0]], np.eye(2), 5e-324)
    assert np.isfinite(phi).all() and np.isfinite(qd).all()
    np.testing.assert_array_equal(phi, [[1.0, 5e-324], [0.0, 1.0]])  # exp(F dt) of the double integrator


@pytest.mark.parametrize("steps", [2**31, 2**62])
def test_predict_many_huge_steps_is_checked(steps):
    # 2**62 predictions would have run for centuries
    kf = KalmanFilter(np.eye(2), mode="open")
    with pytest.raises(InputError) as e:
        kf.predict(np.eye(2), np.eye(2), steps=steps)
    assert e.value.parameter == "steps"


@pytest.mark.parametrize("blocks, error", [([["x"]], TypeError), ([("clock", 2**64)], InputError), ([("clock", -1)], InputError),
                                           ([("a", 10_000), ("b", 1)], InputError)])
def test_layout_sizes_are_checked(blocks, error):
    with pytest.raises(error, match="blocks"):
        Layout(blocks)


@pytest.mark.parametrize("blocks", [[("clock", 2**64)], [("clock", -1)]])
def test_core_layout_sizes_are_input_errors_not_overflow(blocks):
    with pytest.raises(InputError) as e:
        _core.layout_ranges(blocks)
    assert e.value.parameter == "blocks"


@pytest.mark.parametrize("kw, parameter", [(dict(dof=0.000113, runs=0), "dof"), (dict(dof=3, runs=0), "runs"),
                                           (dict(dof=3, runs=10, p=1.5), "p"), (dict(dof=3, runs=10, p=0.0), "p")])
def test_chi2_band_rejects_what_would_be_nan(kw, parameter):
    with pytest.raises((InputError, TypeError)) as e:
        chi2_band(**kw)
    if e.type is InputError:
        assert e.value.parameter == parameter


@pytest.mark.parametrize("call, error, parameter", [
    (lambda: covariance_analysis(np.zeros(2)), TypeError, "scenario"),
    (lambda: true_error_analysis(19, np.eye(1), np.zeros(1)), TypeError, "scenario"),
    (lambda: monte_carlo(None, runs=2, seed=0), TypeError, "scenario"),
    (lambda: closed_loop_matrix(77.7, np.zeros((6, 6)), 77.7), InputError, "h"),
    (lambda: rts_smooth([[[0.8, 0.9, 1.2]]] * 5, np.zeros((5, 3)), [[1.0, [2.0]]], np.zeros((5, 3)), np.zeros((5, 3, 3))),
     TypeError, "p_prior"),
    (lambda: BiasModel.from_json("pz90_02_to_wgs84"), InputError, "text"),
    (lambda: Scenario([[[1.0]], [[1.0, 2.0]]], np.zeros((2, 1, 1)), [1.0, 1.0], 1.0, 1.0, 1.0, [True] * 3), TypeError, "f"),
    (lambda: _core.Scenario(np.zeros((1, 1, 1)), np.ones((1, 1, 1)), np.ones(1), np.eye(1), np.eye(1), np.eye(1),
                            [True, True]).monte_carlo(-1, [0], "closed"), InputError, "master_seed"),
])
def test_fuzz_findings_name_the_parameter(call, error, parameter):
    with pytest.raises(error, match=parameter) as e:
        call()
    if error is InputError:
        assert e.value.parameter == parameter


def test_closed_loop_matrix_of_none_is_not_nan():
    with pytest.raises(TypeError, match="phi: expected numbers, got None"):
        closed_loop_matrix(None, 1.0, 1.0)


def test_undetectable_dare_names_phi():
    # an unobserved unstable mode (h = 0, phi = 95): the error names a real parameter
    with pytest.raises(InputError) as e:
        dare(95.09288499673711, 95.09288499673711, np.float32(0), 95.09288499673711)
    assert e.value.parameter == "phi"
