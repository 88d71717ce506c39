"""NaN where the field means missing, finite input giving finite output, and stream =
batch: a Kalman update skips NaN components of z, the Allan family excludes NaN frequency
samples as allantools does, a constant series has zero variance, the Allan stream rejects
what the batch rejects, and the Earth and GLONASS models reject input outside their
validity instead of returning NaN."""

from __future__ import annotations

import numpy as np
import pytest

import allantools  # a test dependency (pyproject "test" extra)

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


# ---------------------------------------------------------------- Allan family with gaps

from atomnav.noise.allan import AllanStream, allan_variance  # noqa: E402

#: atomnav kind → allantools function (overlapping Allan, modified Allan, overlapping Hadamard)
AT = {"allan": allantools.oadev, "modified": allantools.mdev, "hadamard": allantools.ohdev}
#: rate samples one term spans (2m, 3m − 1, 3m)
SPAN = {"allan": lambda m: 2 * m, "modified": lambda m: 3 * m - 1, "hadamard": lambda m: 3 * m}


def _white_fm(n, seed):
    return np.random.default_rng(seed).normal(1e-3, 2e-4, n)


def _brute(y, m, kind):
    """Mean over every window of rate samples without NaN of the term of ``kind``, from
    the window's own phase x (x₀ = 0, x_{k+1} = x_k + y_k): the textbook sums term by term."""
    span, terms = SPAN[kind](m), []
    for j in range(len(y) - span + 1):
        w = y[j:j + span]
        if np.isnan(w).any():
            continue
        x = np.concatenate([[0.0], np.cumsum(w)])
        if kind == "allan":
            terms.append((x[2 * m] - 2 * x[m] + x[0]) ** 2 / (2 * m**2))
        elif kind == "hadamard":
            terms.append((x[3 * m] - 3 * x[2 * m] + 3 * x[m] - x[0]) ** 2 / (6 * m**2))
        else:
            v = sum(x[i + 2 * m] - 2 * x[i + m] + x[i] for i in range(m))
            terms.append(v**2 / (2 * m**4))
    return np.mean(terms), len(terms)


@pytest.mark.parametrize("kind", ["allan", "modified", "hadamard"])
def test_allan_leading_and_trailing_nan_equal_allantools(kind):
    # allantools trims leading and trailing NaN of frequency data (frequency2phase)
    tau0, ms = 0.5, [1, 2, 4, 8, 16]
    y = _white_fm(1000, 5)
    y[:3] = y[-2:] = np.nan
    t = allan_variance(y, tau0, m=ms, kind=kind)
    taus, dev, _, ns = AT[kind](y, rate=1 / tau0, data_type="freq", taus=np.array(ms) * tau0)
    np.testing.assert_allclose(t["tau_s"], taus, rtol=1e-15)
    np.testing.assert_allclose(t["var"], dev**2, rtol=1e-9)
    np.testing.assert_array_equal(t["n_terms"], ns)
    assert t.attrs["n_missing"] == 5


@pytest.mark.parametrize("kind", ["allan", "modified", "hadamard"])
def test_allan_interior_gaps_pool_allantools_over_the_gap_free_stretches(kind):
    # allantools returns NaN for interior NaN; atomnav leaves out the terms that span a
    # gap, i.e. pools allantools' result of each gap-free stretch by its number of terms
    tau0, ms = 0.5, [1, 2, 4, 8]
    y = _white_fm(1200, 6)
    gaps = [100, 101, 102, 430, 700, 701, 1100]  # every stretch is longer than 3·8 + 1
    y[gaps] = np.nan
    t = allan_variance(y, tau0, m=ms, kind=kind)
    assert np.isnan(AT[kind](y, rate=1 / tau0, data_type="freq", taus=np.array(ms) * tau0)[1]).all()
    stretches = [s for s in np.split(y, gaps) if s.size and not np.isnan(s).all()]
    stretches = [s[~np.isnan(s)] for s in stretches]
    num, den = np.zeros(len(ms)), np.zeros(len(ms))
    for s in stretches:
        _, dev, _, ns = AT[kind](s, rate=1 / tau0, data_type="freq", taus=np.array(ms) * tau0)
        assert len(ns) == len(ms)
        num += ns * dev**2
        den += ns
    np.testing.assert_allclose(t["var"], num / den, rtol=1e-9)
    np.testing.assert_array_equal(t["n_terms"], den)
    assert t.attrs["n_missing"] == len(gaps)


@pytest.mark.parametrize("kind", ["allan", "modified", "hadamard"])
def test_allan_random_gaps_equal_the_brute_force_oracle(kind):
    # random gaps, some stretches shorter than a term: the term-by-term definition
    rng = np.random.default_rng(9)
    y = _white_fm(400, 7)
    y[rng.choice(400, 40, replace=False)] = np.nan
    t = allan_variance(y, 1.0, m=[1, 2, 3], kind=kind)
    for m, var, n in zip(t["m"], t["var"], t["n_terms"]):
        want, n_want = _brute(y, m, kind)
        assert n == n_want
        assert var == pytest.approx(want, rel=1e-9)
    assert t.attrs["n_missing"] == 40


@pytest.mark.parametrize("kind", ["allan", "modified", "hadamard"])
def test_allan_constant_series_is_zero(kind):
    # a stuck or quantised sensor: allantools and Stable32 give 0 (allantools exactly
    # when the rounded mean is the value, as for 3.25; atomnav for any value, e.g.
    # 0.6851, whose rounded mean of 300 copies is not 0.6851)
    for value in (3.25, 0.6851):
        y = np.full(300, value)
        t = allan_variance(y, 0.1, kind=kind)
        np.testing.assert_array_equal(t["var"], 0.0)
        np.testing.assert_array_equal(t["dev"], 0.0)
        s = AllanStream(list(t["m"]), tau0=0.1)
        s.update(y)
        np.testing.assert_array_equal(s.result(kind)["var"], 0.0)
    _, dev, _, _ = AT[kind](np.full(300, 3.25), rate=10.0, data_type="freq", taus=t["tau_s"].to_numpy())
    np.testing.assert_array_equal(dev, 0.0)


@pytest.mark.parametrize("kind", ["allan", "modified", "hadamard"])
def test_allan_stream_with_gaps_equals_batch(kind):
    rng = np.random.default_rng(12)
    y = _white_fm(900, 8)
    y[rng.choice(900, 30, replace=False)] = np.nan
    y[:2] = np.nan
    ms = [1, 2, 4, 8]
    batch = allan_variance(y, 0.5, m=ms, kind=kind)
    s = AllanStream(ms, tau0=0.5)
    for chunk in np.array_split(y, 13):
        s.update(chunk)
    stream = s.result(kind)
    np.testing.assert_array_equal(stream["n_terms"], batch["n_terms"])
    np.testing.assert_allclose(stream["var"], batch["var"], rtol=1e-9)
    np.testing.assert_allclose(stream["edf"], batch["edf"], rtol=1e-12)
    assert stream.attrs["n_missing"] == batch.attrs["n_missing"] == 32


def test_allan_stream_and_batch_reject_the_same_factor():
    # AllanStream([1, 2, 4], tau0=1.0) fed 5 samples used to drop m = 4 silently
    s = AllanStream([1, 2, 4], tau0=1.0)
    s.update([1.0, 3.0, 2.0, 5.0, 4.0])
    with pytest.raises(InputError) as stream_error:
        s.result()
    with pytest.raises(InputError) as batch_error:
        allan_variance([1.0, 3.0, 2.0, 5.0, 4.0], 1.0, m=[1, 2, 4])
    for e in (stream_error, batch_error):
        assert (e.value.parameter, e.value.index) == ("m", 2)
        assert "9 consecutive samples" in str(e.value)  # 2m + 1 rate samples give two terms
    assert str(stream_error.value) == str(batch_error.value)
    s.update([0.0] * 4)
    assert list(s.result()["m"]) == [1, 2, 4]


@pytest.mark.parametrize("bad, parameter, index", [([1.0, np.inf, 2.0, 3.0], "data", 1)])
def test_allan_infinite_and_phase_nan_are_input_errors(bad, parameter, index):
    with pytest.raises(InputError) as e:
        allan_variance(bad, 1.0)
    assert (e.value.parameter, e.value.index) == (parameter, index)
    with pytest.raises(InputError) as e:
        allan_variance([0.0, 1.0, np.nan, 3.0, 4.0], 1.0, data_type="phase")
    assert (e.value.parameter, e.value.index) == ("data", 2)
    with pytest.raises(InputError) as e:
        AllanStream([1], 1.0).update([0.0, -np.inf])
    assert (e.value.parameter, e.value.index) == ("chunk", 1)


def test_allan_gaps_leaving_no_term_name_data():
    with pytest.raises(InputError) as e:
        allan_variance([1.0, np.nan, 2.0, np.nan, 3.0, np.nan, 4.0], 1.0)
    assert e.value.parameter == "data"


# ---------------------------------------------------------------- finite input, finite output


def test_schuler_period_below_the_model_range_names_h():
    # returned NaN (and earth.parameters a gravity of 66.9 m/s²) at h = −7e6 m
    lo, hi = atomnav.earth.HEIGHT_RANGE
    assert (lo, hi) == (-1e4, 1e6)  # the strapdown state check's range, from the core
    with pytest.raises(InputError) as e:
        atomnav.earth.schuler_period(0.9, -7e6)
    assert e.value.parameter == "h"
    with pytest.raises(InputError) as e:
        atomnav.earth.gravity([0.9, 0.9, 0.9], [0.0, 2e6, 0.0])
    assert (e.value.parameter, e.value.index) == ("h", 1)
    with pytest.raises(InputError) as e:
        atomnav.earth.parameters([[0.9, 0.0, 0.0], [0.9, 0.0, -7e6]])
    assert (e.value.parameter, e.value.index) == ("lla", 1)
    with pytest.raises(InputError) as e:
        atomnav.earth.navigation_rates([[0.9, 0.0, -7e6]], [[100.0, 0.0, 0.0]])
    assert (e.value.parameter, e.value.index) == ("lla", 0)


def test_earth_model_at_the_ends_of_the_height_range_is_finite():
    lo, hi = atomnav.earth.HEIGHT_RANGE
    p = atomnav.earth.parameters([[0.9, 0.0, lo], [0.9, 0.0, hi]])
    assert np.isfinite(p.to_numpy()).all()
    # Schuler period √(R₀/γ)·2π from the table's own radii and gravity, at both ends
    for h, row in zip((lo, hi), p.itertuples()):
        r0 = np.sqrt(row.M_m * row.N_m) + h
        assert atomnav.earth.schuler_period(0.9, h) == pytest.approx(2 * np.pi * np.sqrt(r0 / row.gravity_mps2), rel=1e-12)


def test_glonass_propagate_inside_the_earth_names_pos():
    # returned NaN
    from atomnav.gnss.ephemeris import glonass_propagate
    with pytest.raises(InputError) as e:
        glonass_propagate([0, 0, 0], [0, 0, 0], [0, 0, 0], 100.0)
    assert e.value.parameter == "pos"
    with pytest.raises(InputError) as e:
        glonass_propagate([6.0e6, 0, 0], [0, 0, 0], [0, 0, 0], 100.0)  # below a_e = 6378136 m
    assert e.value.parameter == "pos"
    with pytest.raises(InputError) as e:  # falls from 7000 km at rest: inside within the hour
        glonass_propagate([7.0e6, 0, 0], [0, 0, 0], [0, 0, 0], 3600.0)
    assert e.value.parameter == "vel"
    out = glonass_propagate([25.5e6, 0, 0], [0, 3.0e3, 1.0e3], [0, 0, 0], 900.0)
    assert np.isfinite(out).all()


@pytest.mark.parametrize("values", [[[0.2, 0.3, 0.7], [0.9, 1.8, 2.6]], []])
def test_update_result_built_by_hand_needs_its_three_parts(values):
    # a user-built UpdateResult of two parts raised IndexError from .rejected (fuzz seed 20261202)
    from atomnav.filter.engine import UpdateResult

    with pytest.raises(atomnav.InputError, match="expected the three parts") as e:
        UpdateResult(values)
    assert e.value.parameter == "values"
