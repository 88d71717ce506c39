"""A rotation given as input is checked as a rotation, by one core check, and a strapdown
state is checked the same way by the constructor and by ``reset`` (each case is a
mistake a user made, with the exact call)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import atomnav as an
from atomnav import InputError


@pytest.mark.parametrize("dcm", [np.diag([1.0, 1.0, -1.0]), np.ones((3, 3)), 1.01 * np.eye(3)])
def test_quat_from_dcm_rejects_a_matrix_that_is_no_rotation(dcm):
    # before: diag(1, 1, -1) gave [0.707, 0, 0, 0] (not unit) and ones((3, 3)) the identity
    with pytest.raises(InputError, match="not a rotation matrix at index 0") as e:
        an.rotation.quat_from_dcm(dcm)
    assert e.value.parameter == "dcm"


def test_quat_from_dcm_names_the_first_bad_matrix_of_a_stack():
    good = Rotation.from_euler("ZYX", [0.3, -0.2, 0.1]).as_matrix()
    with pytest.raises(InputError, match="at index 2") as e:
        an.rotation.quat_from_dcm(np.stack([good, good, np.diag([1.0, 1.0, -1.0])]))
    assert e.value.index == 2


def test_a_rotation_within_the_tolerance_is_accepted_and_matches_scipy():
    # a DCM stored in single precision (error ~1e-7) is within ROTATION_TOLERANCE
    r = Rotation.from_euler("ZYX", [1.2, -0.4, 0.25])
    dcm = r.as_matrix().astype(np.float32).astype(float)
    q = an.rotation.quat_from_dcm(dcm)
    w, x, y, z = q
    want = r.as_quat()  # scipy: scalar last
    want = want if want[3] >= 0 else -want
    np.testing.assert_allclose([x, y, z, w], want, atol=1e-6)


@pytest.mark.parametrize("fn", [an.rotation.euler_from_quat, an.rotation.dcm_from_quat, an.rotation.rotvec_from_quat])
def test_a_quaternion_off_unit_norm_is_rejected(fn):
    with pytest.raises(InputError, match="not a rotation") as e:
        fn([1.0, 0.1, 0.1, 0.1])
    assert e.value.parameter == "q"


@pytest.fixture(scope="module")
def initial():
    return an.trajectory.sinusoidal(1.0, rate_hz=100.0).initial_state()


@pytest.mark.parametrize(
    "field, value, parameter, match",
    [
        ("q_nb", [1.0, 0.1, 0.1, 0.1], "q_nb", "norm 1.01"),  # norm 1.015: was accepted and rescaled
        ("lla", None, "lla", "height 20000000 m is outside"),  # h = 2e7 m: was accepted
        ("vel_ned", [0.0, np.nan, 0.0], "vel_ned", "non-finite"),
    ],
)
def test_constructor_integrate_and_reset_reject_the_same_state(initial, field, value, parameter, match):
    if field == "lla":
        value = [initial["lla"][0], initial["lla"][1], 2e7]
    bad = {**initial, field: value}
    meas = an.trajectory.sinusoidal(1.0, rate_hz=100.0).ideal_imu("increments")
    with pytest.raises(InputError, match=match) as e:
        an.strapdown.Strapdown(**bad)
    assert e.value.parameter == parameter
    with pytest.raises(InputError, match=match) as e:
        an.strapdown.integrate(meas, **bad)
    assert e.value.parameter == parameter
    sd = an.strapdown.Strapdown(**initial)
    before = sd.state()
    with pytest.raises(InputError, match=match) as e:
        sd.reset(bad)
    assert e.value.parameter == "state"  # reset's argument
    assert sd.state().equals(before)


def test_zeta_of_the_baro_loop_is_named_zeta(initial):
    with pytest.raises(InputError) as e:
        an.strapdown.Strapdown(**initial, vertical="damped", zeta=-1)
    assert e.value.parameter == "zeta"
