"""Position-aided 15-state INS on the project strapdown: closed and open loop."""

import numpy as np
import pytest

from atomnav import InputError, earth
from atomnav.filter import BiasModel, chi2_band, position_aided_ins

LAT, LON, H = 0.8, 0.2, 100.0
OMEGA = 7.292115e-5


def static_case(duration=200.0, rate=100.0, seed=4, mode="closed", chunk_s=60.0):
    """Level, north-facing, at rest: exact rates are ω_ie^n and −gⁿ; IMU biases added."""
    n = int(duration * rate) + 1
    t = np.arange(n) / rate
    gyro = np.tile([OMEGA * np.cos(LAT), 0.0, -OMEGA * np.sin(LAT)], (n, 1))
    accel = np.tile([0.0, 0.0, -earth.gravity(LAT, H)], (n, 1))
    ba_true, bg_true = np.array([0.0, 0.0, 2e-3]), np.array([0.0, 0.0, 0.0])
    rng = np.random.default_rng(seed)
    fix_t = np.arange(1.0, duration + 1e-9, 1.0)
    m = len(fix_t)
    sig = 1.0
    ned = rng.standard_normal((m, 3)) * sig
    m_rad, n_rad = earth.radii(LAT)
    rm, rp = m_rad + H, n_rad + H
    fix_lla = np.c_[LAT + ned[:, 0] / rm, LON + ned[:, 1] / (rp * np.cos(LAT)), H - ned[:, 2]]
    p0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-8] * 3, [(3e-3) ** 2] * 3, [(1e-7) ** 2] * 3])
    ins = position_aided_ins(0.0, [LAT, LON, H], [0, 0, 0], [1, 0, 0, 0], "rates", fix_t, fix_lla,
                             np.tile(np.eye(3) * sig**2, (m, 1, 1)), p0=p0, accel_psd=1e-10, gyro_psd=1e-16,
                             predict_every=10, mode=mode)
    res = ins.run(t, gyro + bg_true, accel + ba_true, chunk_s=chunk_s, progress=False)
    return res.nav, res.measurements, ba_true


def test_closed_loop_estimates_vertical_accel_bias_and_is_consistent():
    table, fixes, ba = static_case()
    last = table.iloc[-1]
    sigma = last["sigma_accel_bias[2]"]
    assert sigma < 2e-4
    assert abs(last["accel_bias_z_mps2"] - ba[2]) < 3 * sigma
    assert abs(last["h_m"] - H) < 3.0
    lo, hi = chi2_band(3, len(fixes))
    assert lo <= fixes["nis"].mean() <= hi
    assert not fixes["rejected_rows"].any()


def test_open_and_closed_loop_agree_on_bias_estimate():
    closed, _, ba = static_case(duration=100.0, mode="closed")
    opened, _, _ = static_case(duration=100.0, mode="open")
    a, b = closed["accel_bias_z_mps2"].iloc[-1], opened["accel_bias_z_mps2"].iloc[-1]
    assert abs(a - b) < 1e-3 * ba[2]
    assert abs(closed["h_m"].iloc[-1] - opened["h_m"].iloc[-1]) < 1e-3


def _args():
    t = np.arange(11) * 0.1
    g = np.zeros((11, 3))
    a = np.tile([0, 0, -9.8], (11, 1))
    build = dict(t0=0.0, lla0=[LAT, LON, H], vel0=[0, 0, 0], q0=[1, 0, 0, 0], kind="rates", fix_time=[0.5],
                 fix_lla=[[LAT, LON, H]], fix_cov=np.eye(3)[None], p0=np.eye(15), accel_psd=1e-8, gyro_psd=1e-12)
    return build, (t, g, a)


def test_bad_fix_time_outside_imu_span():
    kw, imu = _args()
    kw["fix_time"] = [1.5]
    with pytest.raises(InputError, match=r"time: the measurement at 1.5 s \(index 0\) is outside the IMU span \[0, 1\] s") as e:
        position_aided_ins(**kw).run(*imu, progress=False)
    assert (e.value.parameter, e.value.index) == ("time", 0)


def test_bad_fix_before_streamed_record():
    kw, (t, g, a) = _args()
    kw.update(fix_time=[0.05], t0=0.1)
    with pytest.raises(ValueError, match=r"sources: time 0.05 s at index 0 is before the IMU record start 0.1 s"):
        position_aided_ins(**kw).process(t[1:], g[1:], a[1:])


def test_bad_nan_fix():
    kw, _ = _args()
    kw["fix_lla"] = [[LAT, np.nan, H]]
    with pytest.raises(ValueError, match="fix_lla: non-finite value nan at index 0"):
        position_aided_ins(**kw)


def test_bad_p0_size():
    kw, _ = _args()
    kw["p0"] = np.eye(9)
    with pytest.raises(ValueError, match="p0: expected the 15 x 15 INS block, got 9x9"):
        position_aided_ins(**kw)


def test_bad_fix_covariance():
    kw, _ = _args()
    kw["fix_cov"] = -np.eye(3)[None]
    with pytest.raises(ValueError, match=r"fix_cov: entry 0: not positive definite"):
        position_aided_ins(**kw)


def test_bad_unsorted_fixes():
    kw, _ = _args()
    kw.update(fix_time=[0.5, 0.4], fix_lla=[[LAT, LON, H]] * 2, fix_cov=np.tile(np.eye(3), (2, 1, 1)))
    with pytest.raises(ValueError, match="fix_time: time not strictly increasing: decreasing stamp 0.4 at index 1"):
        position_aided_ins(**kw)


def test_divergence_keeps_partial_result():
    from atomnav import NumericalError

    kw, (t, g, a) = _args()
    kw["predict_every"] = 2
    a[7] = [1e12, 0, 0]  # flings the INS off the globe at sample 7 (t = 0.7 s)
    ins = position_aided_ins(**kw)
    with pytest.raises(NumericalError, match=r"navigation solution diverged at sample 7 \(t = 0.70") as err:
        ins.run(t, g, a, chunk_s=0.35, progress=False)
    # every epoch before the failing sample is kept: every 2 steps (0.2, 0.4 s) and at the fix (0.5 s)
    assert list(err.value.partial.nav["time_s"]) == pytest.approx([0.2, 0.4, 0.5])


def test_chunked_run_equals_one_call():
    one, fixes_one, _ = static_case(duration=30.0, chunk_s=1e9)
    many, fixes_many, _ = static_case(duration=30.0, chunk_s=0.73)
    assert one.equals(many)
    assert fixes_one.equals(fixes_many)


def test_without_measurements_equals_free_strapdown():
    """No hidden aiding: with no fix the aided INS is the strapdown on the same data."""
    from atomnav.strapdown import Strapdown

    kw, _ = _args()
    kw.update(fix_time=np.zeros(0), fix_lla=np.zeros((0, 3)), fix_cov=np.zeros((0, 3, 3)), predict_every=1)
    rng = np.random.default_rng(1)
    n = 2001
    t = np.arange(n) * 0.01
    g = rng.normal(0, 1e-3, (n, 3))
    a = np.tile([0.1, 0.0, -9.8], (n, 1)) + rng.normal(0, 1e-2, (n, 3))
    res = position_aided_ins(**kw).run(t, g, a, progress=False)
    sd = Strapdown(0.0, [LAT, LON, H], [0, 0, 0], [1, 0, 0, 0], kind="rates")
    free = sd.run(np.column_stack([t, g, a]))
    cols = ["lat_rad", "lon_rad", "h_m", "vn_mps", "ve_mps", "vd_mps", "qw", "qx", "qy", "qz"]
    np.testing.assert_allclose(res.nav[cols].to_numpy(), free.iloc[1:][cols].to_numpy(), rtol=0, atol=1e-9)


def _noisy_record(n=2001, seed=1):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.01
    g = rng.normal(0, 1e-3, (n, 3))
    a = np.tile([0.1, 0.0, -9.8], (n, 1)) + rng.normal(0, 1e-2, (n, 3))
    return t, g, a


def _no_fix_kwargs(**extra):
    kw, _ = _args()
    kw.update(fix_time=np.zeros(0), fix_lla=np.zeros((0, 3)), fix_cov=np.zeros((0, 3, 3)), predict_every=1, **extra)
    return kw


def test_damped_without_measurements_equals_damped_free_strapdown():
    """The damped channel is the strapdown's baro loop (spec Eq. 26) on the same h_ref: no
    hidden aiding, same loop. The reference altitude is 20–80 m above the start so the loop works."""
    from atomnav.strapdown import integrate

    t, g, a = _noisy_record()
    h_ref = H + 50.0 + 30.0 * np.sin(t / 3.0)
    res = position_aided_ins(**_no_fix_kwargs(vertical="damped", zeta=0.5, omega=0.05)).run(
        t, g, a, h_ref=h_ref, chunk_s=7.3, progress=False)
    free = integrate(np.column_stack([t, g, a]), 0.0, [LAT, LON, H], [0, 0, 0], [1, 0, 0, 0], kind="rates",
                     vertical="damped", h_ref=h_ref, zeta=0.5, omega=0.05)
    cols = ["lat_rad", "lon_rad", "h_m", "vn_mps", "ve_mps", "vd_mps", "qw", "qx", "qy", "qz"]
    np.testing.assert_allclose(res.nav[cols].to_numpy(), free.iloc[1:][cols].to_numpy(), rtol=0, atol=1e-9)
    # and the loop really acted: the undamped channel ends elsewhere
    undamped = position_aided_ins(**_no_fix_kwargs()).run(t, g, a, progress=False)
    assert abs(undamped.nav["h_m"].iloc[-1] - res.nav["h_m"].iloc[-1]) > 1.0


def test_damped_channel_estimates_a_barometer_bias():
    """Position fixes (σ 1 m) every second and a barometer 8 m too high (white error PSD
    1 m²·s): the `baro_bias` state (prior σ 20 m) finds the 8 m within 3σ, σ < 1.5 m,
    and the altitude stays on the fixes, not on the biased barometer. The vertical
    accelerometer bias prior is 1e-4 m/s²: in steady state the loop turns b_a into an
    altitude offset b_a/K_v2 (1e-3 m/s² ↔ 10 m), so with a 1e-3 prior the two are
    separable only in the loop's ~100 s transients (σ of the baro bias then stays 5.5 m)."""
    duration, rate = 300.0, 100.0
    n = int(duration * rate) + 1
    t = np.arange(n) / rate
    gyro = np.tile([OMEGA * np.cos(LAT), 0.0, -OMEGA * np.sin(LAT)], (n, 1))
    accel = np.tile([0.0, 0.0, -earth.gravity(LAT, H)], (n, 1))
    rng = np.random.default_rng(3)
    baro_noise = rng.standard_normal(int(duration) + 2)[np.ceil(np.round(t, 9)).astype(int)]
    h_ref = H + 8.0 + baro_noise
    fix_t = np.arange(1.0, duration + 1e-9, 1.0)
    m_rad, n_rad = earth.radii(LAT)
    ned = rng.standard_normal((len(fix_t), 3))
    fix_lla = np.c_[LAT + ned[:, 0] / (m_rad + H), LON + ned[:, 1] / ((n_rad + H) * np.cos(LAT)), H - ned[:, 2]]
    p0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-8] * 3, [(1e-4) ** 2] * 3, [(1e-7) ** 2] * 3])
    ins = position_aided_ins(0.0, [LAT, LON, H], [0, 0, 0], [1, 0, 0, 0], "rates", fix_t, fix_lla,
                             np.tile(np.eye(3), (len(fix_t), 1, 1)), p0=p0, accel_psd=1e-10, gyro_psd=1e-16,
                             predict_every=100, vertical="damped", baro_psd=1.0,
                             baro_bias=BiasModel(), baro_bias_sigma0=20.0)
    assert ins.labels[-1] == "baro_bias[0]"
    last = ins.run(t, gyro, accel, h_ref=h_ref, progress=False).nav.iloc[-1]
    sigma = last["sigma_baro_bias[0]"]
    assert sigma < 1.5
    assert abs(last["extra_baro_bias[0]"] - 8.0) < 3 * sigma
    assert abs(last["h_m"] - H) < 2.0


def test_bad_damped_without_h_ref():
    t, g, a = _noisy_record(11)
    with pytest.raises(ValueError, match="h_ref: a damped vertical channel needs a reference altitude per sample"):
        position_aided_ins(**_no_fix_kwargs(vertical="damped")).run(t, g, a, progress=False)


def test_bad_h_ref_with_free_channel():
    t, g, a = _noisy_record(11)
    with pytest.raises(ValueError, match="h_ref: given, but the vertical channel is free"):
        position_aided_ins(**_no_fix_kwargs()).run(t, g, a, h_ref=np.full(11, H), progress=False)


def test_bad_h_ref_length():
    t, g, a = _noisy_record(11)
    with pytest.raises(ValueError, match="h_ref: expected 11 rows like time, got 10"):
        position_aided_ins(**_no_fix_kwargs(vertical="damped")).run(t, g, a, h_ref=np.full(10, H), progress=False)


def test_bad_h_ref_nan_names_the_index_in_the_record():
    t, g, a = _noisy_record(501)
    h = np.full(501, H)
    h[357] = np.nan
    with pytest.raises(ValueError, match="h_ref: non-finite value at index 357"):
        position_aided_ins(**_no_fix_kwargs(vertical="damped")).run(t, g, a, h_ref=h, chunk_s=1.0, progress=False)


def test_bad_gyro_nan_names_the_index_in_the_record():
    t, g, a = _noisy_record(501)
    g[412, 1] = np.inf
    with pytest.raises(ValueError, match="gyro: non-finite value at index 412"):
        position_aided_ins(**_no_fix_kwargs()).run(t, g, a, chunk_s=1.0, progress=False)


def test_bad_accel_nan_names_the_index_in_the_record():
    t, g, a = _noisy_record(501)
    a[250, 2] = np.nan
    with pytest.raises(ValueError, match="accel: non-finite value at index 250"):
        position_aided_ins(**_no_fix_kwargs()).run(t, g, a, chunk_s=1.0, progress=False)


def test_bad_time_nan_names_the_index_in_the_record():
    t, g, a = _noisy_record(501)
    t[333] = np.nan
    with pytest.raises(ValueError, match="time: non-finite time NaN at index 333"):
        position_aided_ins(**_no_fix_kwargs()).run(t, g, a, chunk_s=1.0, progress=False)


def test_bad_time_order_names_the_index_in_the_record():
    t, g, a = _noisy_record(501)
    t[421] = t[419]
    with pytest.raises(ValueError, match="time: time not strictly increasing: decreasing stamp 4.19 at index 421"):
        position_aided_ins(**_no_fix_kwargs()).run(t, g, a, chunk_s=1.0, progress=False)


def test_bad_vertical_option():
    with pytest.raises(ValueError, match="vertical: unknown option .baro.; choose one of free, damped"):
        position_aided_ins(**_no_fix_kwargs(vertical="baro"))


def test_bad_vertical_damping():
    with pytest.raises(ValueError, match="zeta: the baro loop's damping ratio must be finite and > 0, got 0"):
        position_aided_ins(**_no_fix_kwargs(vertical="damped", zeta=0.0))


def test_bad_baro_psd():
    with pytest.raises(ValueError, match="baro_psd: must be finite and >= 0, got -1"):
        position_aided_ins(**_no_fix_kwargs(vertical="damped", baro_psd=-1.0))


def test_bad_baro_bias_without_sigma0():
    with pytest.raises(ValueError, match="baro_bias_sigma0: required with baro_bias"):
        position_aided_ins(**_no_fix_kwargs(vertical="damped", baro_bias=BiasModel()))


def _static_engine(**extra):
    n = 1001
    t = np.arange(n) / 100.0
    gyro = np.tile([OMEGA * np.cos(LAT), 0.0, -OMEGA * np.sin(LAT)], (n, 1))
    accel = np.tile([0.0, 0.0, -earth.gravity(LAT, H)], (n, 1))
    p0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-6] * 3, [1e-6] * 3, [1e-12] * 3])
    ins = position_aided_ins(0.0, [LAT, LON, H], [0, 0, 0], [1, 0, 0, 0], "rates", np.arange(1.0, 10.0), [[LAT, LON, H]] * 9,
                             np.eye(3), p0=p0, gyro_psd=1e-14, accel_psd=1e-8, predict_every=10, **extra)
    return ins, t, gyro, accel


def test_full_covariance_per_epoch_is_the_engines_and_matches_sigma():
    ins, t, g, a = _static_engine()
    res = ins.run(t, g, a, progress=False, covariance=True, chunk_s=3.0)
    cov = res.covariance
    assert cov.shape == (len(res.nav), 15, 15)
    assert np.array_equal(cov[-1], ins._core.covariance)            # the engine's P after the last epoch
    sig = res.nav[[f"sigma_{lab}" for lab in ins.labels]].to_numpy()
    assert np.array_equal(np.sqrt(np.diagonal(cov, axis1=1, axis2=2)), sig)
    assert np.allclose(cov, np.transpose(cov, (0, 2, 1)), rtol=0, atol=1e-15)
    # streamed chunk by chunk: the same covariances; off by default
    ins2, *_ = _static_engine()
    first, rest = ins2.process(t[:400], g[:400], a[:400], covariance=True), ins2.process(t[400:900], g[400:900], a[400:900])
    last = ins2.process(t[900:], g[900:], a[900:], covariance=True)
    assert np.array_equal(first.covariance, cov[:len(first.nav)])
    assert rest.covariance is None
    assert np.array_equal(last.covariance, cov[len(first.nav) + len(rest.nav):len(first.nav) + len(rest.nav) + len(last.nav)])


def test_nees_helper_against_numpy_and_bad_requests():
    from atomnav import trajectory

    truth = trajectory.stationary(10.0, 100.0, origin=(LAT, LON, H))
    imu = truth.ideal_imu("rates")
    ins, t, *_ = _static_engine()
    g = imu[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]].to_numpy()
    a = imu[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy() + [0.0, 0.0, 1e-3]
    res = ins.run(t, g, a, progress=False, covariance=True)
    out = res.nees(truth, blocks=("position", "attitude"))
    err = truth.errors(res.nav)
    k = len(res.nav) // 2
    e = err.loc[k, ["dpos_n_m", "dpos_e_m", "dpos_d_m", "psi_n_rad", "psi_e_rad", "psi_d_rad"]].to_numpy(float)
    idx = [0, 1, 2, 6, 7, 8]
    assert out["nees"][k] == pytest.approx(e @ np.linalg.inv(res.covariance[k][np.ix_(idx, idx)]) @ e, rel=1e-9)
    assert (out["dof"] == 6).all()
    band = res.nis_band()
    assert {"nis_low", "nis_high", "inside"} <= set(band.columns) and len(band) == len(res.measurements)
    with pytest.raises(InputError) as e1:
        res.nees(truth, blocks=("position", "clock"))
    assert e1.value.parameter == "blocks"
    plain = _static_engine()[0].run(t, g, a, progress=False)
    assert plain.covariance is None
    with pytest.raises(InputError) as e2:
        plain.nees(truth)
    assert e2.value.parameter == "covariance"
    with pytest.raises(InputError, match="stream the record") as e3:
        _static_engine()[0].run(t, g, a, progress=False, covariance=True, covariance_memory=10_000)
    assert e3.value.parameter == "covariance"


def test_one_fix_covariance_serves_every_fix():
    """fix_cov may be a single (3, 3) matrix: the run equals the one with the stack tiled."""
    ins, t, g, a = _static_engine()
    one = ins.run(t, g, a, progress=False)
    p0 = np.array(ins.setup.p0)
    tiled = position_aided_ins(0.0, [LAT, LON, H], [0, 0, 0], [1, 0, 0, 0], "rates", np.arange(1.0, 10.0), [[LAT, LON, H]] * 9,
                               np.tile(np.eye(3), (9, 1, 1)), p0=p0, gyro_psd=1e-14, accel_psd=1e-8, predict_every=10)
    other = tiled.run(t, g, a, progress=False)
    assert np.array_equal(one.nav.to_numpy(), other.nav.to_numpy())
    assert len(one.measurements) == 9
