"""Rotations in every representation atomnav uses, vectorised over rows.

Conventions: Hamilton quaternions, scalar first ``[w, x, y, z]``, unit norm; ``q_nb``
rotates body vectors into the navigation frame (``v_n = C(q_nb) v_b``). Euler angles are
``(roll, pitch, yaw)`` in rad, z-y-x sequence: ``C_nb = Rz(yaw) Ry(pitch) Rx(roll)``.
Composition: ``C(a ⊗ b) = C(a) C(b)``. Single rows in, single rows out.
"""

from __future__ import annotations

import numpy as np

from . import _core, plausibility
from ._validate import as_floats, input_error, rows

#: How far a rotation given as input may be from an exact one: |‖q‖ − 1| for a quaternion,
#: max |RᵀR − I| for a matrix (which must also have det +1). Every function taking a
#: rotation checks it (:func:`quat_normalize` is the one that rescales any quaternion).
ROTATION_TOLERANCE = _core.ROTATION_TOLERANCE


def _single(a: np.ndarray, width: int) -> bool:
    """Whether ``a`` (already read by ``as_floats``: ragged input is a TypeError naming
    the argument there) is one row of ``width`` values."""
    return a.ndim == 1 and a.shape[0] == width


def _wrap(fn, x, width, name, out_single):
    a = as_floats(x, name)
    r = fn(rows(a, width, name))
    return r[0] if _single(a, width) and out_single else r


def quat_from_euler(euler):
    """Quaternion(s) q_nb (N, 4) from (roll, pitch, yaw) rows in rad (N, 3). An angle
    beyond 2π is likely in degrees: a :class:`atomnav.UnitWarning`."""
    return _wrap(lambda e: _core.quat_from_euler_rows(plausibility.angles(e, "euler")), euler, 3, "euler", True)


def euler_from_quat(q):
    """(roll, pitch, yaw) in rad of quaternion rows; yaw in (−π, π]. Every function of
    this module taking quaternions, except :func:`quat_normalize` and
    :func:`quat_multiply`, needs unit norm within :data:`ROTATION_TOLERANCE`."""
    return _wrap(_core.euler_from_quat_rows, q, 4, "q", True)


def dcm_from_quat(q):
    """Direction cosine matrices C(q), shape (N, 3, 3) (or (3, 3) for one quaternion)."""
    return _wrap(_core.dcm_from_quat_rows, q, 4, "q", True)


def quat_from_dcm(dcm):
    """Quaternion(s) of rotation matrices (N, 3, 3) or (3, 3); scalar part ≥ 0.

    Each matrix must be a rotation: orthonormal within :data:`ROTATION_TOLERANCE` and
    with determinant +1. A reflection such as ``diag(1, 1, -1)`` or any other matrix is
    an :class:`InputError` naming ``dcm`` and the first such matrix."""
    m = as_floats(dcm, "dcm")
    single = m.shape == (3, 3)
    m = np.ascontiguousarray(m[None] if single else m)
    if m.ndim != 3 or m.shape[1:] != (3, 3):
        raise input_error("dcm", f"expected shape (N, 3, 3), got {np.shape(dcm)}")
    r = _core.quat_from_dcm_rows(m)
    return r[0] if single else r


def quat_from_rotvec(rotvec):
    """Quaternion(s) of rotation vectors (rad), the exponential map."""
    return _wrap(_core.quat_from_rotvec_rows, rotvec, 3, "rotvec", True)


def rotvec_from_quat(q):
    """Rotation vector(s) (rad) of quaternions, angle in [0, π]."""
    return _wrap(_core.rotvec_from_quat_rows, q, 4, "q", True)


def dcm_from_euler(euler):
    return dcm_from_quat(quat_from_euler(euler))


def euler_from_dcm(dcm):
    return euler_from_quat(quat_from_dcm(dcm))


def dcm_from_rotvec(rotvec):
    return dcm_from_quat(quat_from_rotvec(rotvec))


def rotvec_from_dcm(dcm):
    return rotvec_from_quat(quat_from_dcm(dcm))


def quat_multiply(a, b):
    """Hamilton product a ⊗ b, row by row."""
    a, b = as_floats(a, "a"), as_floats(b, "b")
    single = _single(a, 4) and _single(b, 4)
    r = _core.quat_mul_rows(rows(a, 4, "a"), rows(b, 4, "b"))
    return r[0] if single else r


def quat_normalize(q):
    """Unit quaternion(s); a zero (or non-finite-norm) quaternion raises
    :class:`atomnav.InputError` naming ``q`` and its row."""
    return _wrap(_core.quat_normalize_rows, q, 4, "q", True)


def skew(v):
    """Skew-symmetric matrices [v×] with [v×] u = v × u."""
    return _wrap(_core.skew_rows, v, 3, "v", True)


def attitude_error_angle(q_a, q_b):
    """Angle (rad) of the rotation between two attitude series, row by row (N,)."""
    return _core.quat_angle_rows(rows(q_a, 4, "q_a"), rows(q_b, 4, "q_b"))[:, 0]
