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
    """Quaternion(s) q_nb from Euler angles.

    Parameters
    ----------
    euler : array_like (N, 3) or (3,)
        (roll, pitch, yaw) rows in rad, z-y-x sequence.

    Returns
    -------
    ndarray (N, 4) or (4,)
        q_nb, scalar first, one per row (a single row for a single row in).

    Warns
    -----
    atomnav.UnitWarning
        An angle beyond 2π, likely in degrees.
    """
    return _wrap(lambda e: _core.quat_from_euler_rows(plausibility.angles(e, "euler")), euler, 3, "euler", True)


def euler_from_quat(q):
    """(roll, pitch, yaw) of quaternion rows.

    Every function of this module taking quaternions, except :func:`quat_normalize` and
    :func:`quat_multiply`, needs unit norm within :data:`ROTATION_TOLERANCE`.

    Parameters
    ----------
    q : array_like (N, 4) or (4,)
        Quaternion(s) q_nb, scalar first, unit norm within :data:`ROTATION_TOLERANCE`.

    Returns
    -------
    ndarray (N, 3) or (3,)
        (roll, pitch, yaw) in rad; yaw in (−π, π].
    """
    return _wrap(_core.euler_from_quat_rows, q, 4, "q", True)


def dcm_from_quat(q):
    """Direction cosine matrices C(q).

    Parameters
    ----------
    q : array_like (N, 4) or (4,)
        Quaternion(s) q_nb, scalar first, unit norm within :data:`ROTATION_TOLERANCE`.

    Returns
    -------
    ndarray (N, 3, 3) or (3, 3)
        C_nb (``v_n = C v_b``); (3, 3) for one quaternion.
    """
    return _wrap(_core.dcm_from_quat_rows, q, 4, "q", True)


def quat_from_dcm(dcm):
    """Quaternion(s) of rotation matrices; scalar part ≥ 0.

    Parameters
    ----------
    dcm : array_like (N, 3, 3) or (3, 3)
        Rotation matrices: each orthonormal within :data:`ROTATION_TOLERANCE` and with
        determinant +1.

    Returns
    -------
    ndarray (N, 4) or (4,)
        Quaternions, scalar first, scalar part ≥ 0.

    Raises
    ------
    InputError
        Naming ``dcm`` and the first matrix that is not a rotation: a reflection such as
        ``diag(1, 1, -1)`` or any other matrix.
    """
    m = as_floats(dcm, "dcm")
    single = m.shape == (3, 3)
    m = np.ascontiguousarray(m[None] if single else m)
    if m.ndim != 3 or m.shape[1:] != (3, 3):
        raise input_error("dcm", f"expected shape (N, 3, 3), got {np.shape(dcm)}")
    r = _core.quat_from_dcm_rows(m)
    return r[0] if single else r


def quat_from_rotvec(rotvec):
    """Quaternion(s) of rotation vectors, the exponential map.

    Parameters
    ----------
    rotvec : array_like (N, 3) or (3,)
        Rotation vectors (rad): axis times angle.

    Returns
    -------
    ndarray (N, 4) or (4,)
        Unit quaternions, scalar first.
    """
    return _wrap(_core.quat_from_rotvec_rows, rotvec, 3, "rotvec", True)


def rotvec_from_quat(q):
    """Rotation vector(s) of quaternions.

    Parameters
    ----------
    q : array_like (N, 4) or (4,)
        Quaternion(s) q_nb, scalar first, unit norm within :data:`ROTATION_TOLERANCE`.

    Returns
    -------
    ndarray (N, 3) or (3,)
        Rotation vectors (rad), angle in [0, π].
    """
    return _wrap(_core.rotvec_from_quat_rows, q, 4, "q", True)


def dcm_from_euler(euler):
    """Direction cosine matrices of Euler angles, C_nb = Rz(yaw) Ry(pitch) Rx(roll).

    Parameters
    ----------
    euler : array_like (N, 3) or (3,)
        (roll, pitch, yaw) rows in rad.

    Returns
    -------
    ndarray (N, 3, 3) or (3, 3)
        C_nb.
    """
    return dcm_from_quat(quat_from_euler(euler))


def euler_from_dcm(dcm):
    """Euler angles of rotation matrices (via :func:`quat_from_dcm`).

    Parameters
    ----------
    dcm : array_like (N, 3, 3) or (3, 3)
        Rotation matrices, checked as by :func:`quat_from_dcm`.

    Returns
    -------
    ndarray (N, 3) or (3,)
        (roll, pitch, yaw) in rad; yaw in (−π, π].
    """
    return euler_from_quat(quat_from_dcm(dcm))


def dcm_from_rotvec(rotvec):
    """Rotation matrices of rotation vectors (the exponential map).

    Parameters
    ----------
    rotvec : array_like (N, 3) or (3,)
        Rotation vectors (rad).

    Returns
    -------
    ndarray (N, 3, 3) or (3, 3)
        Rotation matrices.
    """
    return dcm_from_quat(quat_from_rotvec(rotvec))


def rotvec_from_dcm(dcm):
    """Rotation vectors of rotation matrices (via :func:`quat_from_dcm`).

    Parameters
    ----------
    dcm : array_like (N, 3, 3) or (3, 3)
        Rotation matrices, checked as by :func:`quat_from_dcm`.

    Returns
    -------
    ndarray (N, 3) or (3,)
        Rotation vectors (rad), angle in [0, π].
    """
    return rotvec_from_quat(quat_from_dcm(dcm))


def quat_multiply(a, b):
    """Hamilton product a ⊗ b, row by row: C(a ⊗ b) = C(a) C(b).

    Parameters
    ----------
    a, b : array_like (N, 4) or (4,)
        Quaternions, scalar first, with the same number of rows (any norm).

    Returns
    -------
    ndarray (N, 4) or (4,)
        The products; (4,) when both are single quaternions.
    """
    a, b = as_floats(a, "a"), as_floats(b, "b")
    single = _single(a, 4) and _single(b, 4)
    r = _core.quat_mul_rows(rows(a, 4, "a"), rows(b, 4, "b"))
    return r[0] if single else r


def quat_normalize(q):
    """Unit quaternion(s).

    Parameters
    ----------
    q : array_like (N, 4) or (4,)
        Quaternions, scalar first, of any non-zero finite norm.

    Returns
    -------
    ndarray (N, 4) or (4,)
        ``q`` divided by its norm.

    Raises
    ------
    InputError
        Naming ``q`` and its row: a zero (or non-finite-norm) quaternion.
    """
    return _wrap(_core.quat_normalize_rows, q, 4, "q", True)


def skew(v):
    """Skew-symmetric matrices [v×] with [v×] u = v × u.

    Parameters
    ----------
    v : array_like (N, 3) or (3,)
        Vectors.

    Returns
    -------
    ndarray (N, 3, 3) or (3, 3)
        [v×], one per row.
    """
    return _wrap(_core.skew_rows, v, 3, "v", True)


def attitude_error_angle(q_a, q_b):
    """Angle of the rotation between two attitude series, row by row.

    Parameters
    ----------
    q_a, q_b : array_like (N, 4) or (4,)
        Quaternions, scalar first, unit norm within :data:`ROTATION_TOLERANCE`, with the
        same number of rows.

    Returns
    -------
    ndarray (N,)
        Angle (rad) of the rotation between ``q_a`` and ``q_b`` in each row.
    """
    return _core.quat_angle_rows(rows(q_a, 4, "q_a"), rows(q_b, 4, "q_b"))[:, 0]
