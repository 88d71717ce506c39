"""The Rauch–Tung–Striebel smoother on the aided INS (Rauch, Tung & Striebel 1965): better
than the filter on a 30-minute run, equal to the batch (fixed-interval) posterior of the
stacked linear-Gaussian model built here with dense numpy matrices, independent of the
chunking of the stored forward pass (in memory or on disk), and strict about its input."""

from __future__ import annotations

import copy
import dataclasses
import os

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav import InputError
from atomnav.filter import AidedIns, position_aided_ins

RATE = 50.0          # IMU rate (Hz)
PREDICT_EVERY = 25   # an epoch every 0.5 s
FIX_SIGMA = 3.0      # position-fix noise (m, each NED axis)
POS = ["dpos_n_m", "dpos_e_m", "dpos_d_m"]
P0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-6] * 3, [1e-4] * 3, [1e-10] * 3])


def _case(duration: float, seed: int):
    """A sinusoidal run with a tactical-grade IMU (seeded) and 1 Hz position fixes with
    seeded noise: (truth, IMU arrays, factory keyword arguments)."""
    truth = an.trajectory.sinusoidal(duration, rate_hz=RATE)
    meas = an.imu.corrupt(truth.ideal_imu("rates"), errors="tactical", dt=1 / RATE, kind="rates", seed=seed)
    imu = (meas["time_s"].to_numpy(), meas[[f"gyro_{a}_rad_s" for a in "xyz"]].to_numpy(),
           meas[[f"accel_{a}_mps2" for a in "xyz"]].to_numpy())
    fix_t = np.arange(1.0, duration + 1e-9, 1.0)
    lla = truth.lla[np.searchsorted(truth.time, fix_t)]
    rm, rn = an.earth.radii(lla[:, 0])
    ned = np.random.default_rng(seed + 100).standard_normal(lla.shape) * FIX_SIGMA
    fix_lla = lla + np.c_[ned[:, 0] / (rm + lla[:, 2]), ned[:, 1] / ((rn + lla[:, 2]) * np.cos(lla[:, 0])), -ned[:, 2]]
    s0 = truth.initial_state()
    kw = dict(t0=s0["t0"], lla0=s0["lla"], vel0=s0["vel_ned"], q0=s0["q_nb"], kind="rates", fix_time=fix_t, fix_lla=fix_lla,
              fix_cov=np.tile(np.eye(3) * FIX_SIGMA**2, (len(fix_t), 1, 1)), p0=P0, accel_psd=1e-6, gyro_psd=1e-10,
              predict_every=PREDICT_EVERY)
    return truth, imu, kw


@pytest.fixture(scope="module")
def half_hour():
    truth, imu, kw = _case(1800.0, seed=3)
    result = position_aided_ins(**kw, smooth=True).run(*imu, progress=False)
    return truth, result


def test_smoothed_position_beats_filtered_on_a_30_minute_run(half_hour):
    truth, result = half_hour
    filtered, smoothed = truth.errors(result.nav), truth.errors(result.smoothed.nav)
    rms_f = np.sqrt((filtered[POS] ** 2).to_numpy().sum(axis=1).mean())
    rms_s = np.sqrt((smoothed[POS] ** 2).to_numpy().sum(axis=1).mean())
    assert len(result.smoothed.nav) == len(result.nav) == 3600
    # the smoother uses the fixes on both sides of an epoch
    assert rms_s < rms_f, (rms_s, rms_f)


def test_smoothed_sigma_is_at_most_the_filtered_one_at_every_epoch(half_hour):
    _, result = half_hour
    cols = [c for c in result.nav.columns if c.startswith("sigma_")]
    assert list(result.smoothed.nav.columns) == list(result.nav.columns)
    s, f = result.smoothed.nav[cols].to_numpy(), result.nav[cols].to_numpy()
    # P^s = P⁺ + C (P^s₊₁ − P⁻₊₁) Cᵀ with P^s₊₁ ≤ P⁻₊₁: never above the filter
    assert np.all(s <= f), np.unravel_index(np.argmax(s / f), s.shape)
    assert np.array_equal(s[-1], f[-1])  # the last epoch is the filter's
    assert np.all(s[:-1, :3] < f[:-1, :3])  # the position σ shrinks wherever a later fix exists


# ---------------------------------------------------------------------------------------------
# the batch posterior of the stacked model: an oracle built with dense matrices


def _stored(ins: AidedIns) -> dict:
    chunks = ins.forward_pass.chunks()
    return {f: np.concatenate([np.asarray(c[f]) for _, c in chunks]) for f in chunks[0][1]}


def _batch(fp: dict, p0: np.ndarray, h_rows: dict, r: np.ndarray, z: dict, closed: bool):
    """Posterior mean and covariance of x₁ … x_E given every measurement, for the model
    x₀ ~ N(0, P₀), x_k = Φ_k (x_{k−1} − u_{k−1}) + w_k, w_k ~ N(0, Q_k) (u the closed loop's
    feedback, the stored posterior mean; 0 in open loop), z_k = H x_k + v, v ~ N(0, R) at the
    epochs of ``h_rows``: the stacked prior x = A (x₀, w₁ … w_E) + μ conditioned on all z at
    once, Σ_post = Σ − Σ Hᵀ (H Σ Hᵀ + R)⁻¹ H Σ."""
    phi, qd = fp["phi"], fp["qd"]
    e, n = phi.shape[0], phi.shape[1]
    size = (e + 1) * n
    a = np.zeros((size, size))
    a[:n, :n] = np.eye(n)
    for k in range(1, e + 1):  # block row k: Φ_k (block row k − 1), then + w_k
        a[k * n:(k + 1) * n] = phi[k - 1] @ a[(k - 1) * n:k * n]
        a[k * n:(k + 1) * n, k * n:(k + 1) * n] += np.eye(n)
    d = np.zeros((size, size))
    d[:n, :n] = p0
    for k in range(1, e + 1):
        d[k * n:(k + 1) * n, k * n:(k + 1) * n] = qd[k - 1]
    sigma = a @ d @ a.T
    mu = np.zeros(size)
    for k in range(1, e + 1):
        u = fp["x_post"][k - 2] if closed and k >= 2 else np.zeros(n)
        mu[k * n:(k + 1) * n] = phi[k - 1] @ (mu[(k - 1) * n:k * n] - u)
    epochs = sorted(h_rows)
    h = np.zeros((len(epochs) * 3, size))
    for i, k in enumerate(epochs):
        h[3 * i:3 * i + 3, (k + 1) * n:(k + 2) * n] = h_rows[k]
    zz = np.concatenate([z[k] for k in epochs])
    s = h @ sigma @ h.T + np.kron(np.eye(len(epochs)), r)
    gain = np.linalg.solve(s, h @ sigma).T
    mean = mu + gain @ (zz - h @ mu)
    cov = sigma - gain @ h @ sigma
    blocks = [cov[(k + 1) * n:(k + 2) * n, (k + 1) * n:(k + 2) * n] for k in range(e)]
    return mean[n:].reshape(e, n), np.array(blocks)


@pytest.mark.parametrize("mode", ["closed", "open"])
def test_smoothed_covariance_and_mean_equal_the_batch_posterior(mode):
    _, imu, kw = _case(20.0, seed=11)
    ins = position_aided_ins(**kw, mode=mode, smooth=True)
    result = ins.run(*imu, progress=False)
    sm = ins.smooth(covariance=True)
    fp = _stored(ins)
    times = result.nav["time_s"].to_numpy()
    assert len(times) == 40  # a few tens of epochs
    # every fix is applied at the epoch of its time: z = innovation + H x⁻ there
    meas = result.measurements
    k_of = np.searchsorted(times, meas["time_s"].to_numpy())
    assert np.array_equal(times[k_of], meas["time_s"].to_numpy())
    h = np.zeros((3, 15))
    h[:, :3] = np.eye(3)
    innov = result.innovation.reshape(-1, 3)
    z = {k: innov[i] + h @ fp["x_prior"][k] for i, k in enumerate(k_of)}
    mean, cov = _batch(fp, P0, {k: h for k in k_of}, np.eye(3) * FIX_SIGMA**2, z, closed=mode == "closed")

    # covariance: every entry to 1e-9 of the scale √(P_ii P_jj) of its correlation
    scale = np.sqrt(np.einsum("kii->ki", cov))
    rel = np.abs(sm.covariance - cov) / (scale[:, :, None] * scale[:, None, :])
    assert rel.max() < 1e-9, (rel.max(), np.unravel_index(rel.argmax(), rel.shape))

    # mean: the smoothed error relative to the stored nominal (the corrected solution in
    # closed loop, hence minus the fed-back estimate) is what the table subtracts from it
    correction = mean - fp["x_post"] if mode == "closed" else mean
    nominal = fp["nominal"]
    sigma = np.sqrt(np.einsum("kii->ki", cov))
    for cols, rows, block in ((["vn_mps", "ve_mps", "vd_mps"], slice(4, 7), slice(3, 6)),
                              ([f"accel_bias_{a}_mps2" for a in "xyz"], slice(11, 14), slice(9, 12)),
                              ([f"gyro_bias_{a}_rad_s" for a in "xyz"], slice(14, 17), slice(12, 15))):
        want = nominal[:, rows] - correction[:, block]
        err = np.abs(sm.nav[cols].to_numpy() - want) / sigma[:, block]
        assert err.max() < 1e-9, (mode, cols, err.max())


# ---------------------------------------------------------------------------------------------
# chunks, disk, streaming, copies


@pytest.fixture(scope="module")
def short():
    return _case(30.0, seed=5)


def _smoothed(short, **options):
    _, imu, kw = short
    ins = position_aided_ins(**kw, smooth=True, **options)
    ins.run(*imu, progress=False)
    return ins, ins.smooth(covariance=True)


def test_chunk_sizes_and_the_disk_path_give_identical_results(short, tmp_path):
    _, whole = _smoothed(short)
    for options in (dict(smooth_chunk=7), dict(smooth_chunk=1), dict(smooth_chunk=5, smooth_memory=0, smooth_dir=str(tmp_path)),
                    dict(smooth_chunk=13, smooth_memory=3 * 13 * 7576)):
        ins, got = _smoothed(short, **options)
        assert ins.forward_pass.epochs == 60
        pd.testing.assert_frame_equal(got.nav, whole.nav, check_exact=True)
        assert np.array_equal(got.covariance, whole.covariance), options
        if options.get("smooth_memory") == 0:
            assert ins.forward_pass.on_disk == 12 and len(os.listdir(tmp_path)) == 1
        if options.get("smooth_memory") == 3 * 13 * 7576:  # three chunks of 13 epochs fit
            assert ins.forward_pass.on_disk == 1
        del ins
    assert os.listdir(tmp_path) == []  # the temporary directory goes with its engine


def test_streaming_and_a_copy_mid_record_smooth_like_run(short, tmp_path):
    _, (t, g, a), kw = short
    _, want = _smoothed(short)
    ins = position_aided_ins(**kw, smooth=True, smooth_chunk=4, smooth_memory=0, smooth_dir=str(tmp_path))
    half = len(t) // 2
    for lo, hi in ((0, 3), (3, 140), (140, 141), (141, half)):  # uneven calls, some without an epoch
        ins.process(t[lo:hi], g[lo:hi], a[lo:hi])
    twin = copy.deepcopy(ins)  # owns its chunks: the original's files are not shared
    assert twin.forward_pass.on_disk == ins.forward_pass.on_disk > 0
    for engine in (ins, twin):
        engine.process(t[half:], g[half:], a[half:])
        engine.finish()
        got = engine.smooth(covariance=True)
        pd.testing.assert_frame_equal(got.nav, want.nav, check_exact=True)
        assert np.array_equal(got.covariance, want.covariance)
    assert len(os.listdir(tmp_path)) == 2


def test_memory_per_epoch_is_the_documented_one(short):
    ins, _ = _smoothed(short)
    stored = sum(np.asarray(c[f]).nbytes for _, c in ins.forward_pass.chunks() for f in c)
    n = 15
    assert ins.epoch_bytes == 8 * (4 * n * n + 2 * n + 17) == stored / 60


# ---------------------------------------------------------------------------------------------
# bad input


def test_smoothing_without_a_stored_forward_pass_names_smooth(short):
    _, (t, g, a), kw = short
    ins = position_aided_ins(**kw)
    ins.run(t, g, a, progress=False)
    with pytest.raises(InputError, match="smooth: the forward pass was not stored") as e:
        ins.smooth()
    assert e.value.parameter == "smooth"
    # asking for it once the record has begun is too late for a fixed-interval smoother
    late = position_aided_ins(**kw)
    late.process(t[:10], g[:10], a[:10])
    with pytest.raises(InputError, match="smooth: the forward pass must be stored from the first sample") as e:
        AidedIns(late._core, dataclasses.replace(late.setup, smooth=True))
    assert e.value.parameter == "smooth"


@pytest.mark.parametrize("option, value, error", [
    ("smooth", "yes", TypeError), ("smooth", 1, TypeError),
    ("smooth_chunk", 0, InputError), ("smooth_chunk", 2.5, TypeError),
    ("smooth_memory", -1, InputError), ("smooth_memory", "1GB", TypeError),
    ("smooth_dir", "/nonexistent/atomnav", InputError), ("smooth_dir", 3, TypeError),
])
def test_bad_smoother_options_name_themselves(short, option, value, error):
    _, _, kw = short
    with pytest.raises(error, match=f"^{option}: ") as e:
        position_aided_ins(**kw, **{option: value})
    if error is InputError:
        assert e.value.parameter == option


def test_bad_smooth_arguments_and_an_empty_record(short):
    _, _, kw = short
    ins = position_aided_ins(**kw, smooth=True)
    for name in ("covariance", "progress"):
        with pytest.raises(TypeError, match=f"^{name}: "):
            ins.smooth(**{name: "yes"})
    # nothing processed yet: an empty table with the filter's columns, not an error
    empty = ins.smooth(covariance=True)
    assert len(empty.nav) == 0 and empty.covariance.shape == (0, 15, 15)
    assert list(empty.nav.columns) == list(ins.process(*[np.zeros((0,)), np.zeros((0, 3)), np.zeros((0, 3))]).nav.columns)
