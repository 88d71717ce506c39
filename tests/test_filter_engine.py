"""Error-state Kalman filter engine: layout, discretisation, updates, smoother, bad input."""

import numpy as np
import pytest

import atomnav
from atomnav.filter import INS15, BiasModel, KalmanFilter, Layout, discretize, ins_error_model, rts_smooth


def test_layout_derives_indices_and_rejects_unknown_names():
    lay = Layout(INS15 + (("lever_arm", 3), ("clock", 2)))
    assert lay["gyro_bias"] == slice(12, 15)
    assert lay["clock"] == slice(18, 20)
    assert lay.size == 20
    assert lay.labels[19] == "clock[1]"
    with pytest.raises(ValueError, match="unknown block name 'scale'"):
        lay["scale"]
    with pytest.raises(ValueError, match='unknown block name "lever" at index 1: a non-standard block needs a size'):
        Layout(["position", "lever"])


def test_van_loan_double_integrator_and_gauss_markov():
    dt, q = 0.3, 2.5
    phi, qd = discretize([[0, 1], [0, 0]], [[0, 0], [0, q]], dt)
    assert np.allclose(phi, [[1, dt], [0, 1]], rtol=0, atol=1e-15)
    assert np.allclose(qd, q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]]), rtol=1e-13, atol=0)
    tau, sigma = 50.0, 3e-4  # Gauss–Markov: q = 2σ²/τ, Q_d = σ²(1 − e^{−2Δt/τ})
    phi, qd = discretize([[-1 / tau]], [[2 * sigma**2 / tau]], 7.0)
    assert abs(phi[0, 0] / np.exp(-7 / tau) - 1) < 1e-14
    assert abs(qd[0, 0] / (sigma**2 * (1 - np.exp(-14 / tau))) - 1) < 1e-13
    # first-order option: Φ = I + FΔt, Q_d = Q_cΔt
    phi1, qd1 = discretize([[-1 / tau]], [[2 * sigma**2 / tau]], 7.0, method="first_order")
    assert phi1[0, 0] == pytest.approx(1 - 7 / tau, rel=1e-15) and qd1[0, 0] == pytest.approx(14 * sigma**2 / tau, rel=1e-15)


def _numpy_update(x, p, z, h, r):
    s = h @ p @ h.T + r
    k = p @ h.T @ np.linalg.inv(s)
    a = np.eye(len(x)) - k @ h
    return x + k @ (z - h @ x), a @ p @ a.T + k @ r @ k.T


def test_stacked_and_sequential_updates_match_textbook_kf():
    rng = np.random.default_rng(5)
    n, m = 6, 4
    g = rng.standard_normal((n, n))
    p0 = g @ g.T + np.eye(n)
    phi = np.eye(n) + 0.1 * rng.standard_normal((n, n))
    qd = np.diag(rng.uniform(0.01, 0.1, n))
    h = rng.standard_normal((m, n))
    l = rng.standard_normal((m, m))
    r = l @ l.T + np.eye(m)  # correlated noise: the sequential path must decorrelate
    z = rng.standard_normal(m)
    x_ref = phi @ np.zeros(n)
    p_ref = phi @ p0 @ phi.T + qd
    x_ref, p_ref = _numpy_update(x_ref, p_ref, z, h, r)
    for sequential in (False, True):
        kf = KalmanFilter(p0, mode="open")
        kf.predict(phi, qd)
        innov, nis, rejected = kf.update(z, h, r, sequential=sequential)
        assert rejected == []
        assert np.allclose(kf.x, x_ref, rtol=1e-10, atol=1e-12)
        assert np.allclose(kf.p, p_ref, rtol=1e-10, atol=1e-12)
        assert np.array_equal(kf.p, kf.p.T)
    s = h @ (phi @ p0 @ phi.T + qd) @ h.T + r
    kf = KalmanFilter(p0, mode="open")
    kf.predict(phi, qd)
    _, nis, _ = kf.update(z, h, r)
    assert nis[0] == pytest.approx(z @ np.linalg.solve(s, z), rel=1e-12)
    # closed loop: correction handed over and reset
    kf = KalmanFilter(p0, mode="closed")
    kf.update(z, h, r)
    dx = kf.take_correction()
    assert np.allclose(dx, _numpy_update(np.zeros(n), p0, z, h, r)[0], rtol=1e-10, atol=1e-12)
    assert np.all(kf.x == 0)


def test_default_closed_mode_propagates_a_given_initial_state_like_filterpy():
    """KalmanFilter(x0=..., p0=...): the default (closed) mode propagates δx̂ by Φ in predict,
    as filterpy's KalmanFilter does; a run of predicts and updates equals filterpy's."""
    from filterpy.kalman import KalmanFilter as FilterpyKf

    rng = np.random.default_rng(8)
    n, m = 4, 2
    phi = np.eye(n) + 0.2 * rng.standard_normal((n, n))
    g = rng.standard_normal((n, n))
    p0, qd = g @ g.T + np.eye(n), np.diag(rng.uniform(0.01, 0.1, n))
    h, r = rng.standard_normal((m, n)), np.diag([0.3, 0.5])
    x0 = rng.standard_normal(n)
    ours = KalmanFilter(x0=x0, p0=p0)
    peer = FilterpyKf(dim_x=n, dim_z=m)
    peer.x, peer.P, peer.F, peer.Q, peer.H, peer.R = x0.copy(), p0.copy(), phi, qd, h, r
    ours.predict(phi, qd)
    peer.predict()
    assert np.allclose(ours.x, phi @ x0, rtol=1e-13, atol=1e-13)   # not left at x0
    for _ in range(5):
        z = rng.standard_normal(m)
        ours.update(z, h, r)
        peer.update(z)
        ours.predict(phi, qd)
        peer.predict()
    assert np.allclose(ours.x, peer.x, rtol=1e-10, atol=1e-12)
    assert np.allclose(ours.p, peer.P, rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("sequential", [False, True])
def test_standard_and_joseph_covariance_updates(sequential):
    """Both forms are selectable: the standard form is P − KSKᵀ = (I − KH)P, the Joseph
    form (I − KH)P(I − KH)ᵀ + KRKᵀ (equal in exact arithmetic for the optimal gain); with a
    diagonal R the sequential path equals the stacked one in both forms."""
    rng = np.random.default_rng(3)
    n, m = 5, 3
    g = rng.standard_normal((n, n))
    p0 = g @ g.T + np.eye(n)
    h, r = rng.standard_normal((m, n)), np.diag([0.2, 0.4, 0.1])
    z, x0 = rng.standard_normal(m), rng.standard_normal(n)
    s = h @ p0 @ h.T + r
    k = p0 @ h.T @ np.linalg.inv(s)
    p_standard = (np.eye(n) - k @ h) @ p0
    for form in ("standard", "joseph"):
        kf = KalmanFilter(p0, x0=x0, covariance_update=form)
        kf.update(z, h, r, sequential=sequential)
        assert np.allclose(kf.x, x0 + k @ (z - h @ x0), rtol=1e-10, atol=1e-12)
        assert np.allclose(kf.p, (p_standard + p_standard.T) / 2, rtol=1e-9, atol=1e-12), form


def test_joseph_form_keeps_a_nearly_removed_variance_positive():
    """An update that removes almost all of a state's variance (σ² 1e8 → 1e-8): the Joseph
    form keeps P positive definite with the right remaining variance."""
    p0 = np.diag([1e8, 1.0])
    h, r = np.array([[1.0, 0.0]]), np.array([[1e-8]])
    kf = KalmanFilter(p0, covariance_update="joseph")
    kf.update([1.0], h, r)
    assert kf.p[0, 0] == pytest.approx(1e-8 * 1e8 / (1e8 + 1e-8), rel=1e-6)
    assert np.all(np.linalg.eigvalsh(kf.p) > 0)


def test_bad_initial_state_and_update_form():
    with pytest.raises(atomnav.InputError, match="x0: expected 2 entries") as e:
        KalmanFilter(np.eye(2), x0=[1.0])
    assert e.value.parameter == "x0"
    with pytest.raises(atomnav.InputError) as e:
        KalmanFilter(np.eye(2), x0=[1.0, np.nan])
    assert e.value.parameter == "x0" and e.value.index == 1
    with pytest.raises(atomnav.InputError, match="joseph, standard") as e:
        KalmanFilter(np.eye(2), covariance_update="jo")
    assert e.value.parameter == "covariance_update"
    with pytest.raises(TypeError):
        KalmanFilter(np.eye(2), [0.0, 0.0])   # x0 is keyword-only


def test_gate_rejects_outlier_row_and_reports_it():
    kf = KalmanFilter(np.eye(3), mode="open")
    h, r = np.eye(3), np.eye(3) * 0.01
    innov, nis, rejected = kf.update([0.1, 50.0, -0.2], h, r, sequential=True, gate=10.83)
    assert rejected == [1]
    assert nis[1] == pytest.approx((50.0 / 0.1) ** 2 / (1 + 1 / 0.01), rel=1e-12)  # z̄² / (h̄Ph̄ᵀ + 1), z̄ = z/σ
    assert kf.x[1] == 0.0 and kf.p[1, 1] == 1.0
    assert kf.x[0] == pytest.approx(0.1 / 1.01, rel=1e-12)
    kf = KalmanFilter(np.eye(3), mode="open")
    _, nis, rejected = kf.update([0.1, 50.0, -0.2], h, r, gate=16.27)
    assert rejected == [0, 1, 2] and np.all(kf.x == 0)


def test_loss_of_positive_definiteness_names_the_epoch():
    kf = KalmanFilter(np.eye(2))
    kf.predict(np.eye(2), np.zeros((2, 2)))
    kf.predict(np.eye(2), np.zeros((2, 2)))
    with pytest.raises(atomnav.NumericalError, match="positive definiteness at epoch 3"):
        kf.predict(np.diag([1.0, 0.0]), np.zeros((2, 2)))


def test_rts_matches_batch_conditional_mean():
    """Oracle: the joint Gaussian of all states and measurements, conditioned densely."""
    rng = np.random.default_rng(11)
    n, N = 2, 6
    phi = np.array([[1.0, 0.5], [0.0, 0.9]])
    qd = np.array([[0.02, 0.01], [0.01, 0.05]])
    p0 = np.diag([1.0, 0.5])
    h = np.array([[1.0, 0.0]])
    r = np.array([[0.3]])
    z = rng.standard_normal(N)
    kf = KalmanFilter(p0, mode="open")
    store = {k: [] for k in ("phi", "xp", "pp", "xs", "ps")}
    for k in range(N):
        if k > 0:
            kf.predict(phi, qd)
        store["phi"].append(phi)
        store["xp"].append(kf.x)
        store["pp"].append(kf.p)
        kf.update([z[k]], h, r)
        store["xs"].append(kf.x)
        store["ps"].append(kf.p)
    xs, ps = rts_smooth(store["phi"], store["xp"], store["pp"], store["xs"], store["ps"])
    # joint prior covariance of (x_0..x_{N-1})
    big = np.zeros((N * n, N * n))
    covs = [p0]
    for k in range(1, N):
        covs.append(phi @ covs[-1] @ phi.T + qd)
    for i in range(N):
        for j in range(i, N):
            c = np.linalg.matrix_power(phi, j - i) @ covs[i]
            big[j * n:(j + 1) * n, i * n:(i + 1) * n] = c
            big[i * n:(i + 1) * n, j * n:(j + 1) * n] = c.T
    hb = np.kron(np.eye(N), h)
    s = hb @ big @ hb.T + np.eye(N) * r[0, 0]
    gain = big @ hb.T @ np.linalg.inv(s)
    mean = gain @ z
    cov = big - gain @ hb @ big
    assert np.allclose(xs.ravel(), mean, rtol=1e-9, atol=1e-12)
    for k in range(N):
        assert np.allclose(ps[k], cov[k * n:(k + 1) * n, k * n:(k + 1) * n], rtol=1e-9, atol=1e-12)


def test_ins_error_model_schuler_and_bias_coupling_at_rest():
    lat = 0.8
    g = 9.80665
    lla = np.array([[lat, 0.2, 0.0]])
    f, qc = ins_error_model(lla, np.zeros((1, 3)), np.array([[1.0, 0, 0, 0]]), np.array([[0, 0, -g]]),
                            accel_psd=4e-8, gyro_psd=3e-13,
                            accel_bias=BiasModel("gauss_markov", tau=100.0, sigma=1e-3),
                            gyro_bias=BiasModel("random_walk", psd=1e-16))
    f, qc = f[0], qc[0]
    lay = Layout()
    v, a = lay["velocity"], lay["attitude"]
    # spec gnss-ins-tight §2.9 check: δv̇_N = γψ_E, ψ̇_E = −δv_N/R_M
    assert f[v.start, a.start + 1] == pytest.approx(g)
    a_wgs, e2 = 6378137.0, 6.69437999014e-3
    rm = a_wgs * (1 - e2) / (1 - e2 * np.sin(lat) ** 2) ** 1.5
    assert f[a.start + 1, v.start] == pytest.approx(-1 / rm, rel=1e-9)
    # δb = b̂ − b: F_vba = −C, F_ψbg = +C (level, north-aligned: C = I)
    assert np.allclose(f[v, lay["accel_bias"]], -np.eye(3)) and np.allclose(f[a, lay["gyro_bias"]], np.eye(3))
    assert np.allclose(np.diag(f[lay["accel_bias"], lay["accel_bias"]]), -0.01)
    assert np.allclose(np.diag(qc[lay["accel_bias"], lay["accel_bias"]]), 2e-6 / 100)
    assert np.allclose(np.diag(qc[lay["gyro_bias"], lay["gyro_bias"]]), 1e-16)


# ---- bad input: one test per case -------------------------------------------------

def test_bad_p0_non_square():
    with pytest.raises(ValueError, match="p0: must be square"):
        KalmanFilter(np.ones((2, 3)))


def test_bad_p0_non_symmetric():
    with pytest.raises(ValueError, match=r"p0: not symmetric: entry \(1, 0\)"):
        KalmanFilter([[1.0, 0.2], [0.0, 1.0]])


def test_bad_p0_not_positive_definite():
    with pytest.raises(ValueError, match="p0: not positive definite"):
        KalmanFilter([[1.0, 2.0], [2.0, 1.0]])


def test_bad_h_mismatched_dimensions():
    kf = KalmanFilter(np.eye(3))
    with pytest.raises(ValueError, match=r"h: expected 2x3 \(measurements x states\), got 2x4"):
        kf.update([0.0, 0.0], np.ones((2, 4)), np.eye(2))


def test_bad_r_not_positive_definite():
    kf = KalmanFilter(np.eye(2))
    with pytest.raises(ValueError, match="r: not positive definite"):
        kf.update([0.0], np.ones((1, 2)), [[0.0]])


def test_bad_infinite_measurement():
    # NaN is a missing component (tests/test_nan_missing.py); inf is invalid
    kf = KalmanFilter(np.eye(2))
    with pytest.raises(ValueError, match="z: infinite value inf at index 1"):
        kf.update([0.0, np.inf], np.eye(2), np.eye(2))


def test_bad_phi_dimensions():
    kf = KalmanFilter(np.eye(2))
    with pytest.raises(ValueError, match="phi: expected 2x2, got 3x3"):
        kf.predict(np.eye(3), np.eye(2))


def test_bad_mode_name():
    with pytest.raises(ValueError, match='mode: unknown option "feedback"; choose one of closed, open'):
        KalmanFilter(np.eye(2), mode="feedback")


def test_bad_bias_model_name():
    with pytest.raises(ValueError, match='accel_bias: unknown bias model "flicker"'):
        ins_error_model([[0.5, 0, 0]], [[0, 0, 0]], [[1, 0, 0, 0]], [[0, 0, -9.8]], gyro_psd=0.0, accel_psd=0.0, accel_bias=BiasModel("flicker"))


def test_layout_is_indexed_by_name_only():
    """A Layout is not a sequence: an integer index is a TypeError, so a Layout passed where
    block pairs are expected is a wrong type, not an error about some other parameter."""
    with pytest.raises(TypeError, match="name: a Layout is indexed by block name"):
        Layout()[0]
    with pytest.raises(TypeError):
        atomnav._core.ins_error_dynamics(Layout(), np.zeros((1, 3)), np.zeros((1, 3)), np.array([[1.0, 0, 0, 0]]),
                                         np.zeros((1, 3)), accel_psd=0.0, gyro_psd=0.0,
                                         accel_bias=("random_constant", 0.0, 0.0), gyro_bias=("random_constant", 0.0, 0.0))


def test_error_model_names_the_layout_missing_a_navigation_block():
    """The core's INS error model needs position, velocity and attitude blocks: a layout
    without them is rejected naming ``layout`` (``blocks`` in the core)."""
    one = (np.array([[0.9, 0.1, 100.0]]), np.zeros((1, 3)), np.array([[1.0, 0, 0, 0]]), np.array([[0, 0, -9.8]]))
    with pytest.raises(atomnav.InputError, match='no block "attitude"') as e:
        ins_error_model(*one, gyro_psd=1e-10, accel_psd=1e-6, layout=Layout(["position", "velocity"]))
    assert e.value.parameter == "layout"
    with pytest.raises(atomnav.InputError) as e:
        atomnav._core.ins_error_dynamics([("position", None), ("velocity", None)], *one, accel_psd=0.0, gyro_psd=0.0,
                                         accel_bias=("random_constant", 0.0, 0.0), gyro_bias=("random_constant", 0.0, 0.0))
    assert e.value.parameter == "blocks"


def test_p0_from_per_block_sigma_named_by_the_layout():
    lay = Layout(INS15 + (("clock", 2),))
    p0 = lay.covariance(position=3.0, velocity=(0.1, 0.2, 0.3), attitude=1e-3, accel_bias=2e-3, gyro_bias=1e-5, clock=(30.0, 0.5))
    sigma = np.r_[[3.0] * 3, [0.1, 0.2, 0.3], [1e-3] * 3, [2e-3] * 3, [1e-5] * 3, [30.0, 0.5]]
    assert np.array_equal(p0, np.diag(sigma**2))
    assert np.array_equal(np.diag(p0)[lay["clock"]], [900.0, 0.25])
    ok = dict(position=1.0, velocity=1.0, attitude=1.0, accel_bias=1.0, gyro_bias=1.0)
    for bad, name in ((dict(ok, gyro_bias=-1.0), "gyro_bias"), ({k: v for k, v in ok.items() if k != "attitude"}, "attitude"),
                      (dict(ok, clock=1.0), "clock"), (dict(ok, velocity=(1.0, 2.0)), "velocity")):
        with pytest.raises(atomnav.InputError) as e:
            Layout().covariance(**bad)
        assert e.value.parameter == name


def test_noise_arguments_are_keyword_only_so_their_order_cannot_matter():
    """pyins and most texts give gyro before accel; atomnav's noise arguments are keyword-only,
    so swapping them positionally (a silent 1e4× model error) is a TypeError."""
    from atomnav.filter import position_aided_ins

    one = ([[0.5, 0.1, 0.0]], [[0.0, 0.0, 0.0]], [[1.0, 0, 0, 0]], [[0.0, 0.0, -9.8]])
    with pytest.raises(TypeError):
        ins_error_model(*one, 1e-6, 1e-10)
    a = ins_error_model(*one, gyro_psd=1e-10, accel_psd=1e-6)
    b = ins_error_model(*one, accel_psd=1e-6, gyro_psd=1e-10)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))
    assert a[1][0][Layout()["velocity"], Layout()["velocity"]][0, 0] == 1e-6      # accel PSD drives velocity
    assert a[1][0][Layout()["attitude"], Layout()["attitude"]][0, 0] == 1e-10    # gyro PSD drives attitude
    with pytest.raises(TypeError):
        position_aided_ins(0.0, [0.5, 0.1, 0.0], [0, 0, 0], [1, 0, 0, 0], "rates", [1.0], [[0.5, 0.1, 0.0]], np.eye(3),
                           np.eye(15), 1e-10, 1e-6)
