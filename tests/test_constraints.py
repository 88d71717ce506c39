"""Vehicle and pedestrian constraints (atomnav.filter.constraints) on simulated runs with
known truth.

Oracles: the simulator's truth. Still detection is scored sample by sample against the
true speed of a stop-and-go drive (still = speed exactly 0), the schedule of a turning
stand (still = outside every move) and the car's profile (at rest before its vibration
starts); the non-holonomic constraint is scored by the drift over
GNSS outages against the true positions, with and without it."""

from __future__ import annotations

import copy
import pickle

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import atomnav as an
from atomnav import InputError
from atomnav.filter import BiasModel, InsSetup, NonHolonomic, PositionFixes, StillPeriods, aided_ins, detect_still
from atomnav.filter.outages import outage_analysis, outage_windows

RATE = 100.0
# the stand: six held states and five 4-s moves between them (tilt, turntable), 90 s
STATES = [[0.0, 0.0], [0.0, np.pi / 2], [0.3, np.pi / 2], [0.3, -np.pi / 4], [0.0, 0.0], [0.0, np.pi]]
MOVES, MOVE_S, STAND_S = [10.0, 25.0, 40.0, 55.0, 70.0], 4.0, 90.0


def _arrays(meas, kind: str):
    cols = an.trajectory.IMU_COLUMNS[kind]
    return meas["time_s"].to_numpy(), meas[cols[1:4]].to_numpy(), meas[cols[4:7]].to_numpy()


def _imu(truth, kind: str, errors: str, seed: int = 1):
    meas = an.imu.corrupt(truth.ideal_imu(kind), errors=errors, dt=1 / RATE, kind=kind, seed=seed)
    return _arrays(meas, kind)


def _scores(detected: np.ndarray, truth_still: np.ndarray) -> tuple[float, float]:
    """Precision and recall of the still samples: a true positive is a sample both detected
    and truly still; precision = TP / detected, recall = TP / truly still."""
    tp = np.sum(detected & truth_still)
    return tp / detected.sum(), tp / truth_still.sum()


@pytest.fixture(scope="module")
def stand():
    return an.trajectory.rotary_stand(STATES, MOVES, MOVE_S, STAND_S, rate_hz=RATE)


@pytest.fixture(scope="module")
def stop_and_go():
    """73 s: 10 s at rest, then three times: 3 s to 5 m/s, 5 s cruise, 3 s to rest, 10 s
    at rest; the body squats and dives with the acceleration and vibrates while moving."""
    return an.trajectory.stop_and_go(rate_hz=RATE)


def test_the_stop_and_go_run_stops_and_goes(stop_and_go):
    """The oracle's own premise: four stops of 10 s (the truth's speed exactly 0) and 5 m/s
    between them."""
    speed = np.linalg.norm(stop_and_go.vel_ned, axis=1)
    at_rest = speed == 0.0
    change = np.flatnonzero(np.diff(np.r_[0, at_rest.astype(int), 0]))  # run starts and ends
    lengths = (change[1::2] - change[::2]) / RATE  # s per run of rest
    np.testing.assert_allclose(lengths, 10.0, atol=0.02)
    assert len(lengths) == 4 and speed.max() == pytest.approx(5.0)


@pytest.mark.parametrize("kind, errors", [("rates", "tactical"), ("increments", "mems")])
def test_still_detection_finds_the_stops_of_a_stop_and_go_run(stop_and_go, kind, errors):
    """Every sample counts once: a rate sample at t_k is truly still when the truth's speed
    at t_k is exactly 0; an increment over (t_{k−1}, t_k] when it is 0 at both ends.
    Precision and recall ≥ 95 %; a sample found still never moves faster than 5 cm/s (the
    edges of a stop, where the acceleration and the squat's rate are under the thresholds)."""
    t, g, a = _imu(stop_and_go, kind, errors)
    still = detect_still(t, g, a, kind=kind, lla=stop_and_go.initial_state()["lla"])
    speed = np.linalg.norm(stop_and_go.vel_ned, axis=1)
    k = np.searchsorted(stop_and_go.time, t)
    at_rest = speed[k] == 0.0 if kind == "rates" else (speed[k] == 0.0) & (speed[k - 1] == 0.0)
    precision, recall = _scores(still.still, at_rest)
    print(f"{kind} {errors}: precision {precision:.4f}, recall {recall:.4f}")
    assert precision >= 0.95 and recall >= 0.95, (precision, recall)
    assert len(still.first) == 4 and speed[k][still.still].max() < 0.05
    np.testing.assert_array_equal(still.still, np.isin(np.arange(len(t)), np.concatenate(
        [np.arange(f, l + 1) for f, l in zip(still.first, still.last)])))


def test_still_detection_finds_the_holds_of_a_turning_stand(stand):
    """The stand turns without moving: still = outside every move (start, start + 4 s) of
    its schedule; precision and recall ≥ 95 %, one still period per held state."""
    t, g, a = _imu(stand, "rates", "tactical")
    still = detect_still(t, g, a, kind="rates", lla=stand.initial_state()["lla"])
    moving = np.zeros(len(t), bool)
    for s in MOVES:
        moving |= (t > s) & (t < s + MOVE_S)
    precision, recall = _scores(still.still, ~moving)
    assert precision >= 0.95 and recall >= 0.95, (precision, recall)
    assert len(still.first) == len(STATES)


def test_still_detection_stops_when_the_car_starts():
    """The car is at rest until its vibration starts at 4 s: the still samples found are
    ≥ 95 % of those, and none is moving faster than 1 cm/s by the truth."""
    car = an.trajectory.car(rate_hz=RATE)
    t, g, a = _imu(car, "rates", "tactical")
    still = detect_still(t, g, a, kind="rates", lla=car.initial_state()["lla"])
    _, recall = _scores(still.still, t <= 4.0)
    assert recall >= 0.95, recall
    speed = np.linalg.norm(car.vel_ned, axis=1)
    assert speed[still.still].max() < 0.01 and (speed > 1.0).any()


def test_gravity_given_or_from_the_site_and_thresholds_act(stand):
    t, g, a = _imu(stand, "rates", "tactical")
    lla = stand.initial_state()["lla"]
    by_site = detect_still(t, g, a, kind="rates", lla=lla)
    by_value = detect_still(t, g, a, kind="rates", gravity=an.earth.gravity(lla[0], lla[2]))
    np.testing.assert_array_equal(by_site.still, by_value.still)
    # a gravity 1 m/s² off leaves no sample within 0.25 m/s²
    assert not detect_still(t, g, a, kind="rates", gravity=by_site.gravity + 1.0).still.any()
    # a window longer than any hold (the last, 16 s) finds nothing; a gyro threshold above the stand's rate
    # finds everything still
    assert not detect_still(t, g, a, kind="rates", lla=lla, window=int(17 * RATE)).still.any()
    assert detect_still(t, g, a, kind="rates", lla=lla, gyro_threshold=10.0).still.all()


def test_zero_updates_from_the_still_periods_hold_the_stand_in_place(stand):
    """ZUPT and ZARU at the detected still periods, no other aiding: the position error after
    90 s stays below 0.5 m where the free INS drifts more than 10 times as far."""
    t, g, a = _imu(stand, "rates", "mems")
    s0 = stand.initial_state()
    still = detect_still(t, g, a, kind="rates", lla=s0["lla"])
    times = still.update_times()
    period = np.searchsorted(still.intervals[:, 0], times, "right") - 1  # the period each update falls in
    assert np.all(np.diff(times) > 0) and np.all(times <= still.intervals[period, 1])
    errors = an.imu.ImuErrors.preset("mems")
    p0 = np.diag(np.r_[[1e-4] * 3, [1e-6] * 3, [1e-6] * 3, [(3e-3) ** 2] * 3, [(1e-4) ** 2] * 3])
    setup = InsSetup(t0=s0["t0"], lla0=s0["lla"], vel0=s0["vel_ned"], q0=s0["q_nb"], kind="rates", p0=p0,
                     accel_psd=errors.accel.white ** 2, gyro_psd=errors.gyro.white ** 2, predict_every=10)
    drift = {}
    for name, sources in (("aided", [still.zero_velocity(0.01), still.zero_rate(errors.gyro.white ** 2, 1e-4)]), ("free", [])):
        nav = aided_ins(setup, sources).run(t, g, a, progress=False).nav
        err = stand.errors(nav)
        drift[name] = np.linalg.norm(err[["dpos_n_m", "dpos_e_m", "dpos_d_m"]].to_numpy()[-1])
    assert drift["aided"] < 0.5 and drift["free"] > 10 * drift["aided"], drift


# ---- non-holonomic constraint ------------------------------------------------------------

CAR_S = 300.0


@pytest.fixture(scope="module")
def drive():
    """A level car slalom (10 m/s, ±3 m, 20 s period; heading along the path, so the body
    velocity is forward only: `atomnav.trajectory.car` skids sideways after 18 s and does
    not fit the constraint), a MEMS IMU, and position fixes of σ = 1 m at 1 Hz."""
    truth = an.trajectory.slalom(rate_hz=RATE, duration=CAR_S, speed=10.0, amp=3.0, period=20.0)
    imu = _imu(truth, "rates", "mems", seed=5)
    errors = an.imu.ImuErrors.preset("mems")
    s0 = truth.initial_state()
    p0 = np.diag(np.r_[[1.0] * 3, [1e-2] * 3, [1e-5] * 3, [(2e-3) ** 2] * 3, [(5e-5) ** 2] * 3])
    setup = InsSetup(t0=s0["t0"], lla0=s0["lla"], vel0=s0["vel_ned"], q0=s0["q_nb"], kind="rates", p0=p0,
                     accel_psd=errors.accel.white ** 2, gyro_psd=errors.gyro.white ** 2,
                     accel_bias=BiasModel("random_walk", psd=1e-9), gyro_bias=BiasModel("random_walk", psd=1e-14),
                     predict_every=10)
    t = np.arange(1.0, CAR_S + 1e-9, 1.0)
    k = np.searchsorted(truth.time, t)
    noise = np.random.default_rng(5).standard_normal((len(t), 3))  # NED, m
    lla = truth.lla[k].copy()
    rm, rn = an.earth.radii(lla[:, 0])
    lla[:, 0] += noise[:, 0] / (rm + lla[:, 2])
    lla[:, 1] += noise[:, 1] / ((rn + lla[:, 2]) * np.cos(lla[:, 0]))
    lla[:, 2] -= noise[:, 2]
    fixes = PositionFixes(t, lla, np.eye(3))
    reference = PositionFixes(t, truth.lla[k], np.eye(3) * 1e-4)  # the truth, to score against
    return dict(truth=truth, imu=imu, setup=setup, fixes=fixes, reference=reference)


def test_the_slalom_meets_the_constraint(drive):
    """The oracle's own premise: the true body velocity is forward only."""
    truth = drive["truth"]
    q, v = np.array(truth.q_nb), np.array(truth.vel_ned)
    body = Rotation.from_quat(q[:, [1, 2, 3, 0]]).inv().apply(v)  # C_n^b v^n
    assert np.abs(body[:, 1:]).max() < 1e-6 and body[:, 0].min() > 9.0


def test_nhc_cuts_the_outage_drift_by_a_third(drive):
    """Nine 15-s outages (from 40 s after the first fix, every 30 s): the largest 3-D error
    against the truth in each, forward filter, with NHC (σ 0.05 m/s at 10 Hz) and without.
    Both the mean over the outages and the worst outage drop by ≥ 30 %."""
    windows = outage_windows(drive["fixes"].time, length=15.0, first=40.0, spacing=30.0)
    t = drive["imu"][0]
    largest = {}
    for name, sources in (("without", []), ("with", [NonHolonomic(t[::10], 0.05)])):
        out = outage_analysis(drive["setup"], drive["fixes"], drive["imu"], windows, sources=sources,
                              reference=drive["reference"], progress=False)
        table = out.table[out.table["solution"] == "forward"]
        largest[name] = table["max_error_m"].to_numpy()
    print({k: np.round(v, 3) for k, v in largest.items()})
    assert len(largest["with"]) == 9
    assert largest["with"].mean() <= 0.7 * largest["without"].mean(), largest
    assert largest["with"].max() <= 0.7 * largest["without"].max(), largest


def test_nhc_is_skipped_below_min_speed(drive):
    """Above the slalom's speed every update is skipped; below it every one is applied."""
    t = drive["imu"][0]
    setup = drive["setup"]
    fixes = drive["fixes"].select(drive["fixes"].time < 60.0)
    cut = t <= 60.0
    imu = tuple(x[cut] for x in drive["imu"])
    skipped = aided_ins(setup, [fixes, NonHolonomic(imu[0][::10], 0.05, min_speed=50.0)]).run(*imu, progress=False)
    applied = aided_ins(setup, [fixes, NonHolonomic(imu[0][::10], 0.05)]).run(*imu, progress=False)
    assert (applied.measurements["source"] == "non_holonomic").sum() == len(imu[0][::10])
    assert (skipped.measurements["source"] == "non_holonomic").sum() == 0


# ---- bad input ---------------------------------------------------------------------------

def _record(n=200):
    t = np.arange(n) / RATE
    g = np.zeros((n, 3))
    a = np.tile([0.0, 0.0, -9.81], (n, 1))
    return t, g, a


def _with(x, row, col=0, value=np.nan):
    y = np.array(x, dtype=float)
    y[(row, col) if y.ndim == 2 else row] = value
    return y


BAD_STILL = [
    ("time", lambda t, g, a: dict(time=_with(t, 7)), 7),
    ("time", lambda t, g, a: dict(time=_with(t, 9, value=t[8])), 9),
    ("gyro", lambda t, g, a: dict(gyro=_with(g, 12, 1)), 12),
    ("accel", lambda t, g, a: dict(accel=_with(a, 5, 2)), 5),
    ("gyro", lambda t, g, a: dict(gyro=g[:-1]), None),
    ("accel", lambda t, g, a: dict(accel=a[:, :2]), None),
    ("kind", lambda t, g, a: dict(kind="rate"), None),
    ("lla", lambda t, g, a: dict(lla=None), None),
    ("lla", lambda t, g, a: dict(lla=[0.9, np.nan, 100.0]), 1),
    ("gravity", lambda t, g, a: dict(gravity=9.8), None),  # with lla: both
    ("gravity", lambda t, g, a: dict(lla=None, gravity=-9.8), None),
    ("window", lambda t, g, a: dict(window=0), None),
    ("window", lambda t, g, a: dict(window=201), None),
    ("accel_threshold", lambda t, g, a: dict(accel_threshold=0.0), None),
    ("accel_threshold", lambda t, g, a: dict(accel_threshold=np.nan), None),
    ("gyro_threshold", lambda t, g, a: dict(gyro_threshold=-1e-3), None),
]


@pytest.mark.parametrize("name, change, row", BAD_STILL, ids=[f"{n}-{i}" for i, (n, _, _) in enumerate(BAD_STILL)])
def test_bad_detect_still_input_names_the_argument(name, change, row):
    t, g, a = _record()
    args = dict(time=t, gyro=g, accel=a, kind="rates", lla=[0.9, 0.6, 100.0])
    args.update(change(t, g, a))
    with pytest.raises(InputError) as e:
        detect_still(**args)
    assert e.value.parameter == name and e.value.index == row, (e.value, e.value.parameter, e.value.index)


@pytest.mark.parametrize("name, value", [("kind", 3), ("window", 2.5), ("window", "50"), ("accel_threshold", "0.25"),
                                         ("gyro_threshold", [0.1]), ("gravity", "9.8")])
def test_wrong_types_of_detect_still_are_type_errors(name, value):
    t, g, a = _record()
    args = dict(time=t, gyro=g, accel=a, kind="rates", lla=[0.9, 0.6, 100.0])
    if name == "gravity":
        args["lla"] = None
    args[name] = value
    with pytest.raises(TypeError, match=name):
        detect_still(**args)


def test_bad_update_arguments_name_them():
    t, g, a = _record()
    still = detect_still(t, g, a, kind="rates", gravity=9.81)
    assert still.still.all() and len(still.update_times()) == 4  # samples 0, 50, 100, 150
    for call, name in [(lambda: still.update_times(0), "every"), (lambda: still.zero_velocity(0.0), "sigma"),
                       (lambda: still.zero_rate(-1.0), "gyro_psd"), (lambda: still.zero_rate(1e-10, np.nan), "sigma")]:
        with pytest.raises(InputError) as e:
            call()
        assert e.value.parameter == name
    with pytest.raises(TypeError, match="every"):
        still.update_times(1.5)


BAD_NHC = [
    ("time", dict(time=[0.0, np.nan, 2.0]), 1),
    ("time", dict(time=[0.0, 1.0, 1.0]), 2),
    ("sigma", dict(sigma=0.0), None),
    ("sigma", dict(sigma=np.inf), None),
    ("lever_arm", dict(lever_arm=[0.0, np.nan, 0.0]), 1),
    ("lever_arm", dict(lever_arm=[1.0, 0.0]), None),
    ("min_speed", dict(min_speed=-0.1), None),
    ("min_speed", dict(min_speed=np.nan), None),
]


@pytest.mark.parametrize("name, change, row", BAD_NHC, ids=[f"{n}-{i}" for i, (n, _, _) in enumerate(BAD_NHC)])
def test_bad_nhc_input_names_the_argument(name, change, row):
    args = dict(time=[0.0, 1.0, 2.0], sigma=0.1)
    args.update(change)
    with pytest.raises(InputError) as e:
        NonHolonomic(args.pop("time"), args.pop("sigma"), **args)
    assert e.value.parameter == name and e.value.index == row, (e.value, e.value.parameter, e.value.index)


@pytest.mark.parametrize("name, value", [("sigma", "0.1"), ("min_speed", "1"), ("lever_arm", "abc")])
def test_wrong_types_of_nhc_are_type_errors(name, value):
    args = dict(sigma=0.1)
    args[name] = value
    with pytest.raises(TypeError, match=name):
        NonHolonomic([0.0, 1.0], args.pop("sigma"), **args)


def test_still_periods_pickle(stand):
    t, g, a = _imu(stand, "rates", "tactical")
    still = detect_still(t, g, a, kind="rates", lla=stand.initial_state()["lla"])
    for c in (pickle.loads(pickle.dumps(still)), copy.deepcopy(still)):
        assert isinstance(c, StillPeriods)
        np.testing.assert_array_equal(c.still, still.still)
        np.testing.assert_array_equal(c.update_times(), still.update_times())
        assert (c.window, c.gravity) == (still.window, still.gravity)


def test_zero_rate_of_still_periods_copies_feed_the_same_ins(stand):
    """The ZARU of the still periods, pickled or deep-copied, gives the run of the original."""
    t, g, a = _imu(stand, "rates", "tactical")
    s0 = stand.initial_state()
    still = detect_still(t, g, a, kind="rates", lla=s0["lla"])
    source = still.zero_rate(1e-9, 1e-5)
    p0 = np.diag(np.r_[[1e-4] * 3, [1e-6] * 3, [1e-6] * 3, [1e-4] * 3, [1e-10] * 3])
    setup = InsSetup(t0=s0["t0"], lla0=s0["lla"], vel0=s0["vel_ned"], q0=s0["q_nb"], kind="rates", p0=p0,
                     accel_psd=1e-6, gyro_psd=1e-9, predict_every=10)
    want = aided_ins(setup, source).run(t, g, a, progress=False)
    assert len(want.measurements) >= 100
    for c in (pickle.loads(pickle.dumps(source)), copy.deepcopy(source)):
        got = aided_ins(setup, c).run(t, g, a, progress=False)
        np.testing.assert_array_equal(got.nav.to_numpy(), want.nav.to_numpy())
        np.testing.assert_array_equal(got.measurements["time_s"], want.measurements["time_s"])


@pytest.mark.parametrize("name, value", [("speed", 0.0), ("ramp", -1.0), ("cruise", -1.0), ("stop", 0.0), ("cycles", 0),
                                         ("squat", np.nan), ("vibration", -0.01), ("heading", np.inf)])
def test_bad_stop_and_go_arguments_name_them(name, value):
    with pytest.raises(InputError) as e:
        an.trajectory.stop_and_go(rate_hz=10.0, **{name: value})
    assert e.value.parameter == name


def test_stop_and_go_cycles_must_be_an_integer():
    with pytest.raises(TypeError, match="cycles"):
        an.trajectory.stop_and_go(rate_hz=10.0, cycles=2.5)
