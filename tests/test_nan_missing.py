"""NaN where the field means missing, finite input giving finite output, and stream =
batch: a Kalman update skips NaN components of z, the Allan family excludes NaN frequency
samples as allantools does, a constant series has zero variance, the Allan stream rejects
what the batch rejects, and the Earth and GLONASS models reject input outside their
validity instead of returning NaN."""

from __future__ import annotations

import numpy as np
import pytest

import atomnav
from atomnav import InputError
from atomnav.filter import KalmanFilter

# ---------------------------------------------------------------- Kalman update


def _system(seed=3, n=4, m=3):
    rng = np.random.default_rng(seed)
    a = rng.normal(size=(n, n))
    p0 = a @ a.T + n * np.eye(n)
    h = rng.normal(size=(m, n))
    b = rng.normal(size=(m, m))
    r = b @ b.T + m * np.eye(m)
    z = rng.normal(size=m)
    return p0, h, r, z


def _numpy_update(x, p, z, h, r):
    """Textbook update, Joseph form, in numpy (the oracle)."""
    s = h @ p @ h.T + r
    k = p @ h.T @ np.linalg.inv(s)
    y = z - h @ x
    a = np.eye(len(x)) - k @ h
    return x + k @ y, a @ p @ a.T + k @ r @ k.T, y, y @ np.linalg.solve(s, y)


@pytest.mark.parametrize("sequential", [False, True])
@pytest.mark.parametrize("j", [0, 1, 2])
def test_kalman_nan_component_equals_update_without_its_row(j, sequential):
    p0, h, r, z = _system()
    keep = [i for i in range(len(z)) if i != j]
    zn, hn, rn = z.copy(), h.copy(), r.copy()
    zn[j] = np.nan
    hn[j, 1] = np.nan  # the rows of H and R of a missing component are not read
    rn[j, j] = rn[j, 0] = rn[0, j] = np.nan if j else rn[j, j]
    kf = KalmanFilter(p0, mode="open")
    innov, nis, rejected = res = kf.update(zn, hn, rn, sequential=sequential)
    ref = KalmanFilter(p0, mode="open")
    ref.update(z[keep], h[keep], r[np.ix_(keep, keep)], sequential=sequential)
    np.testing.assert_allclose(kf.x, ref.x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(kf.p, ref.p, rtol=0, atol=1e-12)
    # and against the numpy oracle on the reduced system
    x_o, p_o, y_o, nis_o = _numpy_update(np.zeros(4), p0, z[keep], h[keep], r[np.ix_(keep, keep)])
    np.testing.assert_allclose(kf.x, x_o, rtol=0, atol=1e-12)
    np.testing.assert_allclose(kf.p, p_o, rtol=0, atol=1e-12)
    assert res.skipped == [j] and rejected == []
    assert np.isnan(innov[j]) and np.isfinite(np.delete(innov, j)).all()
    if sequential:
        assert np.isnan(nis[j]) and len(nis) == 3
        # the sum of the decorrelated rows' y²/s is the stacked NIS
        np.testing.assert_allclose(np.nansum(nis), nis_o, rtol=1e-12)
    else:
        np.testing.assert_allclose(innov[keep], y_o, rtol=1e-12)
        np.testing.assert_allclose(nis, [nis_o], rtol=1e-12)


def test_kalman_nan_component_equals_filterpy_on_the_reduced_system():
    filterpy = pytest.importorskip("filterpy.kalman")
    p0, h, r, z = _system(seed=11, n=5, m=4)
    z[[1, 3]] = np.nan
    keep = [0, 2]
    kf = KalmanFilter(p0, mode="open")
    kf.update(z, h, r)
    fp = filterpy.KalmanFilter(dim_x=5, dim_z=2)
    fp.x, fp.P = np.zeros(5), p0.copy()
    fp.update(z[keep], R=r[np.ix_(keep, keep)], H=h[keep])
    np.testing.assert_allclose(kf.x, fp.x, rtol=0, atol=1e-12)
    np.testing.assert_allclose(kf.p, fp.P, rtol=0, atol=1e-12)


@pytest.mark.parametrize("sequential", [False, True])
def test_kalman_all_nan_leaves_the_state_unchanged(sequential):
    p0, h, r, _ = _system()
    kf = KalmanFilter(p0, mode="open")
    res = kf.update([np.nan] * 3, h, r, sequential=sequential)
    assert res.skipped == [0, 1, 2] and res.rejected == []
    assert np.isnan(res.innovation).all() and np.isnan(res.nis).all()
    np.testing.assert_array_equal(kf.x, np.zeros(4))
    np.testing.assert_array_equal(kf.p, p0)


def test_kalman_gate_is_over_the_used_components():
    # z = [3, NaN] on a unit system: NIS of the used row 3²/(1 + 1) = 4.5
    kf = KalmanFilter(np.eye(2), mode="open")
    _, nis, rejected = kf.update([3.0, np.nan], np.eye(2), np.eye(2), gate=4.0)
    np.testing.assert_allclose(nis, [4.5], rtol=1e-15)
    assert rejected == [0]
    np.testing.assert_array_equal(kf.x, [0.0, 0.0])
    _, nis, rejected = kf.update([3.0, np.nan], np.eye(2), np.eye(2), gate=5.0)
    assert rejected == [] and kf.x[0] == pytest.approx(1.5, rel=1e-15)


@pytest.mark.parametrize("sequential", [False, True])
def test_kalman_non_finite_h_or_r_of_a_used_component_is_an_input_error(sequential):
    p0, h, r, z = _system()
    z[2] = np.nan
    bad_h = h.copy()
    bad_h[1, 0] = np.nan
    kf = KalmanFilter(p0, mode="open")
    with pytest.raises(InputError) as e:
        kf.update(z, bad_h, r, sequential=sequential)
    assert (e.value.parameter, e.value.index) == ("h", 1)
    bad_r = r.copy()
    bad_r[0, 1] = bad_r[1, 0] = np.inf
    with pytest.raises(InputError) as e:
        kf.update(z, h, bad_r, sequential=sequential)
    assert (e.value.parameter, e.value.index) == ("r", 0)
    with pytest.raises(InputError) as e:
        kf.update([0.0, np.inf, np.nan], h, r, sequential=sequential)
    assert (e.value.parameter, e.value.index) == ("z", 1)
    np.testing.assert_array_equal(kf.p, p0)


def test_kalman_update_result_unpacks_as_before_and_pickles():
    import pickle
    kf = KalmanFilter(np.eye(2), mode="open")
    res = kf.update([1.0, np.nan], np.eye(2), np.eye(2))
    assert len(res) == 3
    back = pickle.loads(pickle.dumps(res))
    assert back.skipped == [1] and np.array_equal(back[0], res.innovation, equal_nan=True)
