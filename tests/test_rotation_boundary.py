"""A quaternion that names no rotation (zero, or of non-finite norm) is an InputError
naming `q` and its row, never a silent NaN row."""

from __future__ import annotations

import numpy as np
import pytest

import atomnav
from atomnav import InputError, _core, rotation

GOOD = [1.0, 0.0, 0.0, 0.0]


@pytest.mark.parametrize("bad", [[0.0, 0.0, 0.0, 0.0], [1e300, 1e300, 0.0, 0.0]])
@pytest.mark.parametrize("fn", [_core.dcm_from_quat_rows, _core.euler_from_quat_rows, _core.rotvec_from_quat_rows,
                                _core.quat_normalize_rows])
def test_no_rotation_row_is_rejected(fn, bad):
    with pytest.raises(atomnav.InputError) as e:
        fn(np.array([GOOD, GOOD, bad]))
    assert (e.value.parameter, e.value.index) == ("q", 2)


def test_python_wrappers_and_angle():
    with pytest.raises(atomnav.InputError) as e:
        rotation.dcm_from_quat([0.0, 0.0, 0.0, 0.0])
    assert (e.value.parameter, e.value.index) == ("q", 0)
    with pytest.raises(atomnav.InputError) as e:
        rotation.attitude_error_angle([GOOD, GOOD], [GOOD, [0.0] * 4])
    assert (e.value.parameter, e.value.index) == ("q_b", 1)
    with pytest.raises(atomnav.InputError) as e:
        rotation.quat_from_dcm(np.zeros((2, 3)))
    assert e.value.parameter == "dcm"


def test_a_quaternion_off_unit_norm_is_no_rotation_but_normalize_rescales_it():
    # [2, 0, 0, 0] is no rotation: only quat_normalize turns it into the rotation of its direction
    with pytest.raises(InputError, match="not a rotation") as e:
        rotation.dcm_from_quat([2.0, 0.0, 0.0, 0.0])
    assert e.value.parameter == "q"
    np.testing.assert_allclose(rotation.dcm_from_quat(rotation.quat_normalize([2.0, 0.0, 0.0, 0.0])), np.eye(3), atol=0)
