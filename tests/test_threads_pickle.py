"""Stateful objects shared by threads, and pickled or deep-copied mid-use.

Threads: four threads calling one object never see pyo3's "Already mutably borrowed"; the
calls run one after another, so the final state is the one the same calls made in
sequence give (each case makes calls whose order does not change the final state).
Pickle/deepcopy: a copy taken mid-record continues bit for bit like the original (the
oracle is the original itself). The thread cases repeat 20 times: a race shows up as a
failure in some of them. The core releases the GIL in each of these calls."""

from __future__ import annotations

import copy
import pickle
import threading

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav.filter.engine import KalmanFilter
from atomnav.noise.allan import AllanStream
from atomnav.noise.filters import PAPER_AR, PAPER_MA, PAPER_SIGMA2, ArimaStateSpace, KalmanStream

REPEATS = 20


@pytest.fixture(scope="module")
def record():
    traj = an.trajectory.sinusoidal(10.0, rate_hz=100.0)
    ideal = traj.ideal_imu("increments")
    meas = an.imu.corrupt(ideal, errors="tactical", dt=0.01, kind="increments", seed=7)
    return traj, ideal, meas


def _four_threads(call):
    """Run ``call(k)`` for k = 0..3 on four threads released together; the exceptions."""
    barrier, errors = threading.Barrier(4), []

    def work(k):
        barrier.wait()
        try:
            call(k)
        except Exception as e:  # noqa: BLE001 - collected and asserted on
            errors.append(e)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return errors


def _copies(obj):
    return [pickle.loads(pickle.dumps(obj)), copy.deepcopy(obj)]


def _model():
    return ArimaStateSpace(ar=PAPER_AR, ma=PAPER_MA, sigma2=PAPER_SIGMA2)


# ---- pickle and deepcopy: the copy continues like the original ------------------------

def test_strapdown_copy_continues_bit_for_bit(record):
    traj, _, meas = record
    sd = an.strapdown.Strapdown(**traj.initial_state())
    sd.run(meas.iloc[:437])  # mid-record: coning/sculling history in the state
    copies = _copies(sd)
    want = sd.run(meas.iloc[437:])
    for c in copies:
        pd.testing.assert_frame_equal(c.run(meas.iloc[437:]), want, check_exact=True)


def test_strapdown_with_rates_copy_keeps_its_priming(record):
    traj = record[0]
    rates = traj.ideal_imu("rates")
    sd = an.strapdown.Strapdown(**traj.initial_state(), kind="rates")
    sd.run(rates.iloc[:1])  # the priming sample only
    c = pickle.loads(pickle.dumps(sd))
    pd.testing.assert_frame_equal(c.run(rates.iloc[1:300]), sd.run(rates.iloc[1:300]), check_exact=True)


def test_imu_simulator_copy_continues_the_same_random_streams(record):
    ideal = record[1]
    f, w = ideal[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy(), ideal[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy()
    errors = an.imu.ImuErrors.preset("mems")  # white, random walk, Gauss-Markov and flicker terms
    sim = an.imu.ImuSimulator(errors, 0.01, "increments", seed=3)
    sim.corrupt(f[:250], w[:250])
    copies = _copies(sim)
    want = sim.corrupt(f[250:], w[250:])
    for c in copies:
        pd.testing.assert_frame_equal(c.corrupt(f[250:], w[250:]), want, check_exact=True)


def test_allan_stream_copy_continues_bit_for_bit():
    x = np.random.default_rng(1).normal(size=3000)
    s = AllanStream([1, 2, 4, 8], tau0=0.1)
    s.update(x[:1234])
    copies = _copies(s)
    s.update(x[1234:])
    for c in copies:
        c.update(x[1234:])
        pd.testing.assert_frame_equal(c.result("allan"), s.result("allan"), check_exact=True)
        pd.testing.assert_frame_equal(c.result("hadamard"), s.result("hadamard"), check_exact=True)


def test_kalman_stream_copy_continues_bit_for_bit():
    x = np.random.default_rng(2).normal(size=600)
    s = KalmanStream(_model(), "differenced")
    s.update(x[:311])
    copies = _copies(s)
    want = s.update(x[311:])
    for c in copies:
        _assert_same_result(c.update(x[311:]), want)


def _assert_same_result(got, want):
    for name in ("omega_hat", "r", "gain"):
        np.testing.assert_array_equal(getattr(got, name), getattr(want, name))


def test_kalman_filter_copy_continues_bit_for_bit():
    rng = np.random.default_rng(4)
    a = rng.normal(size=(6, 6))
    phi, q = np.eye(6) + 0.01 * a, 1e-3 * np.eye(6)
    h, r = rng.normal(size=(3, 6)), np.eye(3)
    kf = KalmanFilter(np.eye(6), mode="open")
    kf.predict(phi, q)
    kf.update(rng.normal(size=3), h, r)
    copies = _copies(kf)
    z = rng.normal(size=3)
    for f in [kf, *copies]:
        f.predict(phi, q, steps=3)
        f.update(z, h, r, sequential=True)
    for c in copies:
        np.testing.assert_array_equal(c.x, kf.x)
        np.testing.assert_array_equal(c.p, kf.p)
        assert c.epoch == kf.epoch


def test_trajectory_and_its_motion_round_trip(record):
    traj = record[0]
    for c in _copies(traj):
        pd.testing.assert_frame_equal(c.df, traj.df, check_exact=True)
        pd.testing.assert_frame_equal(c.ideal_imu("increments"), traj.ideal_imu("increments"), check_exact=True)


def test_ephemerides_round_trip():
    from atomnav.gnss.ephemeris import Ephemerides
    from atomnav.gnss.observations import simulate

    eph = Ephemerides.nominal(0.0, 600.0, seed=5)
    t, lla, vel = [0.0, 300.0], np.tile([np.deg2rad(55.75), np.deg2rad(37.6), 200.0], (2, 1)), np.zeros((2, 3))
    want = simulate(eph, t, lla, vel, seed=1)
    for c in _copies(eph):
        pd.testing.assert_frame_equal(simulate(c, t, lla, vel, seed=1), want, check_exact=True)


def test_a_state_of_another_class_is_an_input_error():
    sd_bytes = pickle.dumps(an.strapdown.Strapdown(0.0, [0.5, 0.1, 0.0], [0, 0, 0], [1, 0, 0, 0])._core)
    state = pickle.loads(sd_bytes).__reduce__()[1][0]
    with pytest.raises(an.InputError, match="a saved Strapdown state") as e:
        an._core.KalmanFilter._from_state(state)
    assert e.value.parameter == "state"


# ---- threads ---------------------------------------------------------------------------

@pytest.mark.parametrize("repeat", range(REPEATS))
def test_strapdown_run_while_threads_read_its_state(record, repeat):
    traj, _, meas = record
    sd = an.strapdown.Strapdown(**traj.initial_state(), kind="increments")
    seen = []

    def call(k):
        if k == 0:
            seen.append(sd.run(meas))
        else:
            for _ in range(20):
                assert sd.kind == "increments"
                sd.state()

    assert _four_threads(call) == []
    alone = an.strapdown.Strapdown(**traj.initial_state()).run(meas)
    pd.testing.assert_frame_equal(seen[0], alone, check_exact=True)


@pytest.mark.parametrize("repeat", range(REPEATS))
def test_imu_simulator_from_four_threads(record, repeat):
    ideal = record[1]
    f, w = ideal[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy()[:200], ideal[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy()[:200]
    shared, out = an.imu.ImuSimulator("tactical", 0.01, "increments", seed=9), []
    assert _four_threads(lambda k: out.append(shared.corrupt(f, w))) == []
    alone = an.imu.ImuSimulator("tactical", 0.01, "increments", seed=9)
    want = pd.concat([alone.corrupt(f, w) for _ in range(4)])
    pd.testing.assert_frame_equal(pd.concat(out).sort_index(), want, check_exact=True)


@pytest.mark.parametrize("repeat", range(REPEATS))
def test_streams_and_kalman_filter_from_four_threads(repeat):
    x = np.random.default_rng(repeat).normal(size=800)
    allan, kalman = AllanStream([1, 2, 4], tau0=1.0), KalmanStream(_model())
    kf = KalmanFilter(np.eye(4))
    phi, q = np.eye(4) + 0.01 * np.ones((4, 4)), 1e-3 * np.eye(4)

    def call(k):
        allan.update(x)
        kalman.update(x)
        kf.predict(phi, q, steps=50)

    assert _four_threads(call) == []
    allan1, kalman1, kf1 = AllanStream([1, 2, 4], tau0=1.0), KalmanStream(_model()), KalmanFilter(np.eye(4))
    for _ in range(4):
        allan1.update(x)
        kalman1.update(x)
        kf1.predict(phi, q, steps=50)
    pd.testing.assert_frame_equal(allan.result("allan"), allan1.result("allan"), check_exact=True)
    np.testing.assert_array_equal(kf.p, kf1.p)
    assert kf.epoch == kf1.epoch == 200
    _assert_same_result(kalman.update(x[:50]), kalman1.update(x[:50]))  # the same state continues alike


def test_stateless_functions_from_four_threads(record):
    traj, _, meas = record
    want = an.strapdown.integrate(meas, **traj.initial_state())
    x = np.random.default_rng(0).normal(size=20000)
    want_adev = an.noise.allan.allan_variance(x, 0.01)
    got = {}

    def call(k):
        got[k] = (an.strapdown.integrate(meas, **traj.initial_state()), an.noise.allan.allan_variance(x, 0.01))

    assert _four_threads(call) == []
    for nav, adev in got.values():
        pd.testing.assert_frame_equal(nav, want, check_exact=True)
        pd.testing.assert_frame_equal(adev, want_adev, check_exact=True)


@pytest.mark.parametrize("repeat", range(REPEATS))
def test_aided_ins_getters_while_another_thread_runs_it(repeat):
    # The aided INS holds its state in a mutex and releases the GIL while it computes; a
    # getter that waited for that mutex with the GIL held deadlocked against it.
    from atomnav.filter import position_aided_ins

    n = 6001
    rng = np.random.default_rng(repeat)
    t = np.arange(n) * 0.01
    g, a = rng.normal(0, 1e-3, (n, 3)), np.tile([0.1, 0.0, -9.8], (n, 1)) + rng.normal(0, 1e-2, (n, 3))
    lla = [0.97, 0.65, 200.0]
    build = dict(t0=0.0, lla0=lla, vel0=[0, 0, 0], q0=[1, 0, 0, 0], kind="rates", fix_time=[20.0, 50.0],
                 fix_lla=[lla, lla], fix_cov=np.stack([np.eye(3)] * 2), p0=np.eye(15), accel_psd=1e-8, gyro_psd=1e-12)
    shared, out = position_aided_ins(**build), []

    def call(k):
        if k == 0:
            out.append(shared.process(t, g, a))
        else:
            for _ in range(50):
                assert shared.pending in (0, 1, 2)

    worker = threading.Thread(target=lambda: out.append(_four_threads(call)))
    worker.start()
    worker.join(timeout=60)
    assert not worker.is_alive(), "deadlock: a getter waited for the filter with the GIL held"
    assert out[-1] == []
    alone = position_aided_ins(**build).process(t, g, a)
    pd.testing.assert_frame_equal(out[0].nav, alone.nav, check_exact=True)


def test_imu_simulator_kind_cannot_be_changed_after_construction(record):
    # setting kind after construction relabelled the output columns without changing the
    # simulation; kind, dt and errors are now read-only
    sim = an.imu.ImuSimulator("tactical", 0.01, "rates", seed=1)
    for name, value in (("kind", "increments"), ("dt", 0.02)):
        with pytest.raises(AttributeError, match="no setter"):
            setattr(sim, name, value)
    sim.errors.gyro.white = 1.0  # a copy: the simulator keeps its own model
    assert sim.errors.gyro.white == an.imu.ImuErrors.preset("tactical").gyro.white
    assert sim.kind == "rates"
