#!/usr/bin/env python
"""The "realistic mistakes" strategy of the fuzz suite: the mistakes people actually make
with pandas, units, threads and pickling, each applied to a clean call that works.

A catalogue of clean calls is built from the library's own generators (``FIXTURES``: a
10 s sinusoidal trajectory at 100 Hz, its ideal and corrupted IMU tables, a stationary
record, a gyro noise series, GNSS observations, ...). Each clean call is made once; then
one argument is mutated and the call is made again and compared with the clean one:

* tables (every DataFrame argument): a duplicated column (the
  ``pd.concat([df, df[[col]]], axis=1)`` merge mistake), a renamed column, a missing
  column, extra columns, reordered columns; the time column as naive datetime64,
  tz-aware datetime64 and timedelta64; nullable ``Float64`` with and without ``pd.NA``;
  numbers as strings;
* units: the physically meaningful columns and arguments (accelerations, angular rates,
  time, latitude, longitude, Euler angles, the CAI pulse separation T, wavelengths,
  contrasts) scaled by the factor of a real unit mistake (``UNIT_MISTAKES``: a value in
  g, °, °/s, ms, nm or %, from the factors π/180, 180/π, 1000, 1/1000, 9.80665,
  1/9.80665, 100 and 1e9);
* stateful objects (``STATEFUL``): the same call from 4 threads on one shared object,
  compared with the same calls made one after the other; and ``pickle`` / ``deepcopy``
  after some calls, the copy continuing next to the original.

Verdict (``GOOD`` and ``BAD``): a mutation that keeps the meaning (extra or reordered
columns, a time column that converts exactly, ``Float64`` without missing values) must give
the identical result; one that changes it must raise ``InputError`` (its ``.parameter`` a
parameter of the called function) or ``TypeError`` naming one, warn (``UnitWarning``), or
give the identical result (a column the call does not read); ``pd.NA`` must behave as
``NaN`` in a float64 column (the pandas convention for a missing value); numbers as
strings must raise; a unit mistake must warn or raise. A unit mistake is judged only where
the documented plausibility rules can see it (``detectable``): the others are
counted as ``not judged``.

Usage::

    python tests/fuzz_mistakes.py --out mistakes.md            # the CI share
    python tests/fuzz_mistakes.py --thread-rounds 20           # the long run

Reproducers assume ``REPRO_HEADER`` (run from tests/).
"""

from __future__ import annotations

import argparse
import copy
import dataclasses
import inspect
import math
import pickle
import re
import sys
import threading
import time
import warnings
from collections import Counter

import numpy as np
import pandas as pd
from numpydoc.docscrape import NumpyDocString

import fuzz

GOOD = ("identical", "raised", "warned")
"""Outcome classes that are a correct answer to a mistake."""

BAD = ("silent-different", "unit-not-warned", "foreign-exception", "thread-borrow-error", "pickle-failed",
       "pickle-diverged", "raised-bad-parameter", "harmless-rejected", "strings-accepted", "na-not-nan",
       "clean-failed", "no-clean-call")
"""Outcome classes that are a defect: a result that differs from the clean call's without
a word; a unit mistake that neither warns nor raises; an exception that is not atomnav's
answer to bad input (``NumericalError`` for a mistaken input included); pyo3's borrow
flag reached from threads; an object that does not survive ``pickle``/``deepcopy`` or whose
copy does not continue bit for bit; an ``InputError``/``TypeError`` that names no
parameter of the called function; a harmless mutation rejected; numeric strings taken
as numbers; ``pd.NA`` handled unlike ``NaN``; a clean call of the catalogue that raises
or warns (a false unit warning on good data); a public callable that takes a table or an
array with no clean call in the catalogue and no entry in ``EXEMPT`` or
``NOT_YET_CATALOGUED`` (or an entry of either that no longer names such a callable, or one
that has a clean call)."""

NOT_JUDGED = "not judged"
"""A unit mistake no documented plausibility rule can see (e.g. a gyro in °/s on a vehicle
turning slower than 35 rad/s/57.3): counted, listed, not a verdict."""

G0 = 9.80665  # standard gravity (m/s²), the g of an accelerometer in g
DEG = math.pi / 180.0
EARTH_RATE = 7.292115e-5  # rad/s (WGS-84)
EPOCH = pd.Timestamp("2024-01-01")  # the date of the datetime64 time columns
EXTRA_COLUMNS = {"extra_m": 1.0, "note": "x"}  # columns added to a table (a result echoing them is still identical)
THREADS = 4
THREAD_ROUNDS = 3  # thread cases per stateful entry in the CI share (each round a fresh object)
REPRO_KEEP = fuzz.REPRO_KEEP

REPRO_HEADER = ("import copy, pickle, threading, numpy as np, pandas as pd, atomnav as an; "
                "from fuzz_mistakes import fixtures; globals().update(fixtures())")

FIXTURES = """\
import dataclasses
import numpy as np, pandas as pd, atomnav as an
traj = an.trajectory.sinusoidal(10.0, rate_hz=100.0)
init = traj.initial_state()
truth = traj.df
ideal = traj.ideal_imu("increments")
ideal_rates = traj.ideal_imu("rates")
meas = an.imu.corrupt(ideal, errors="tactical", dt=0.01, kind="increments", seed=7)
meas_rates = an.imu.corrupt(ideal_rates, errors="tactical", dt=0.01, kind="rates", seed=7)
nav = an.strapdown.integrate(meas, **init)
still = an.trajectory.stationary(10.0, rate_hz=100.0)
still_init = still.initial_state()
still_meas = an.imu.corrupt(still.ideal_imu("increments"), errors="tactical", dt=0.01, kind="increments", seed=7)
omega = an.noise.synth.model_b(seed=3, n=2048, tau0=1.0)
allan = an.noise.allan.allan_variance(omega, tau0=1.0)
arima = an.noise.filters.ArimaStateSpace.paper()
eph = an.gnss.ephemeris.Ephemerides.nominal(0.0, 600.0)
gnss_t = np.arange(0.0, 10.0, 1.0)
gnss_lla = np.tile(traj.lla[0], (len(gnss_t), 1))
obs = an.gnss.observations.simulate(eph, gnss_t, gnss_lla, np.zeros((len(gnss_t), 3)), seed=1)
k_c = np.array([[0.0, 0.0, 1.61e7], [1.61e7, 0.0, 0.0]])
imu_t = meas_rates["time_s"].to_numpy()
imu_gyro = meas_rates[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]].to_numpy()
imu_accel = meas_rates[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy()
fixes = dict(fix_time=traj.time[100::200], fix_lla=traj.lla[100::200], fix_cov=np.tile(np.eye(3), (5, 1, 1)))
ins_noise = dict(p0=np.diag([1.0] * 3 + [0.01] * 3 + [1e-6] * 3 + [1e-4] * 3 + [1e-8] * 3), accel_psd=1e-6, gyro_psd=1e-10)
slalom = an.trajectory.slalom(rate_hz=200.0, duration=2.0, ellipsoid="kinematic")
slalom_imu = slalom.ideal_imu("rates")
slalom_init = slalom.initial_state()
cai_shots = 0.1 + 0.05 * np.arange(30)
cai_phase = np.random.default_rng(3).uniform(-1.0, 1.0, (30, 6))
cai_noise = 0.01 * np.random.default_rng(4).standard_normal((30, 6))
sine = an.cai.SineMotion(position_poly=[[0, 1.0, 0.1], [0, 0.2, 0], [0, 0, 0]], position_sines=[[0, 2e-5, 9.7, 0.3]],
                         attitude_poly=[[0.01, 0, 0], [-0.02, 0, 0], [0.3, 0.05, 0]], attitude_sines=[[2, 5e-4, 3.7, 0.2]])
sine_t = np.arange(201) / 200.0
sine_f, sine_w, sine_wd = an.cai.motion_imu(sine, sine_t, gravity=(0.0, 0.0, 9.81))
ring = np.array([np.linalg.qr(r)[0] for r in np.random.default_rng(1).normal(size=(6, 3, 3))])
ring = ring * np.sign(np.linalg.det(ring))[:, None, None]  # six rotations
stars = np.array([[0.6, 0.0, 0.8], [0.0, 0.6, 0.8], [0.0, 0.0, 1.0]])
kf_phi, kf_q = np.array([[1.0, 0.5], [0.0, 0.9]]), np.array([[0.02, 0.01], [0.01, 0.05]])
kf_h, kf_r = np.array([[1.0, 0.0]]), np.array([[0.3]])
car = an.trajectory.car(rate_hz=100.0)
car_imu = an.imu.corrupt(car.ideal_imu("increments"), errors="mems", dt=0.01, seed=7)
car_fix_t = np.arange(1.0, 16.0)
"""


def fixtures() -> dict:
    """The fixture namespace (built once per process; every case works on copies)."""
    if not _FIXTURES:
        exec(FIXTURES, _FIXTURES)  # noqa: S102 - the catalogue's own source text
    return {k: v for k, v in _FIXTURES.items() if not k.startswith("__")}


_FIXTURES: dict = {}


# ----------------------------------------------------------------------------------------
# the catalogue


@dataclasses.dataclass(frozen=True)
class Unit:
    """A physically meaningful argument: variable ``var`` of the clean call, the element
    ``index`` of it (a Python subscript such as ``"[:, 1]"``; the whole value when empty),
    of quantity ``role`` (a key of ``UNIT_MISTAKES``)."""

    var: str
    role: str
    index: str = ""


@dataclasses.dataclass(frozen=True)
class Clean:
    """A clean call that works: ``setup`` (Python lines on the fixtures) then the
    expression ``call``; ``target`` is the dotted name of the callable it calls (its
    parameters are the names an error may give). ``tables``: variables holding a DataFrame
    (or Series) whose mutations are drawn, their unit-bearing columns found by name
    (``COLUMN_ROLES``); ``units``: the other unit-bearing arguments."""

    target: str
    call: str
    setup: str = ""
    tables: tuple[str, ...] = ()
    units: tuple[Unit, ...] = ()
    time_origin: str = ""  # the argument fixing the origin of a table's time in seconds (e.g. t0)
    epoch: str = ""  # the date a table's time in seconds counts from, where the call documents one


def _c(target, call, setup="", tables=(), units=(), time_origin="", epoch=""):
    return Clean(target, call, setup, tuple(tables), tuple(units), time_origin, epoch)


LLA = (Unit("lla", "lat", "[0]"), Unit("lla", "lon", "[1]"))
LLA_ROWS = (Unit("lla", "lat", "[:, 0]"), Unit("lla", "lon", "[:, 1]"))
INIT = 't0, lla, vel_ned, q_nb = init["t0"], init["lla"], init["vel_ned"], init["q_nb"]'
EULER = "euler = np.array([[0.1, -0.2, 1.5], [0.05, 0.1, -2.5]])"
GPS_WEEK_START = "2023-12-31"  # the Sunday that starts the GPS week of EPOCH (GNSS time_s is seconds of week)
AIDED = ('ins = an.filter.position_aided_ins(init["t0"], init["lla"], init["vel_ned"], init["q_nb"], "rates", **fixes, '
         '**ins_noise)\ntime, gyro, accel = imu_t, imu_gyro, imu_accel')
AIDED_UNITS = (Unit("time", "imu_time"), Unit("gyro", "gyro"), Unit("accel", "accel"))
SINE_IMU = "t, f, w, shots, T = sine_t, sine_f, sine_w, np.array([0.1, 0.5]), 0.05"
SINE_UNITS = (Unit("t", "imu_time"), Unit("f", "accel"), Unit("w", "gyro"), Unit("T", "T"))
OBS = "epoch, camera = np.array([0, 0, 0, 1, 1, 1]), np.zeros(6, dtype=np.int64)\ns_cf = g = np.vstack([np.eye(3)] * 2)"
RHO = "rho, epochs = np.tile([0.0, 4e-5, 6e-5], (400, 1)) * 0.005, np.array([0.1, 0.9, 1.7])"
KF = "phi, q, h, r = kf_phi, kf_q, kf_h, kf_r"
PLOTS = ("import matplotlib.pyplot as plt\n"
         "drawn = lambda fig: ([(a.get_title(), ln.get_label(), ln.get_xydata()) for a in fig.axes for ln in a.lines], "
         "plt.close(fig))[0]")
PLOTS_AIDED = PLOTS + "\n" + AIDED + "\nres = ins.run(time, gyro, accel, progress=False)"

LOG = ("log_columns = {'time': 't', **{f'gyro_{a}': f'w{a}_dps' for a in 'xyz'}, **{f'accel_{a}': f'a{a}_g' for a in 'xyz'}}\n"
       "log = pd.DataFrame({'t': imu_t, **{f'w{a}_dps': np.degrees(imu_gyro[:, i]) for i, a in enumerate('xyz')}, "
       "**{f'a{a}_g': imu_accel[:, i] / 9.80665 for i, a in enumerate('xyz')}})")
REF = ("ref_columns = {'time': 't', 'lat': 'lat_deg', 'lon': 'lon_deg', 'h': 'alt_m', "
       "**{k: k for k in ('vn', 've', 'vd', 'roll', 'pitch', 'yaw')}}\n"
       "ref = pd.DataFrame({'t': traj.time, 'lat_deg': np.degrees(traj.lla[:, 0]), 'lon_deg': np.degrees(traj.lla[:, 1]), "
       "'alt_m': traj.lla[:, 2], **dict(zip(['vn', 've', 'vd'], traj.vel_ned.T)), "
       "**dict(zip(['roll', 'pitch', 'yaw'], an.rotation.euler_from_quat(traj.q_nb).T))})")
ALIGN = 'imu, lla = still_meas, still_init["lla"]'
ZUPT = ('time = still.time[50::100]\n'
        'still_setup = an.filter.InsSetup(t0=still_init["t0"], lla0=still_init["lla"], vel0=still_init["vel_ned"], '
        'q0=still_init["q_nb"], kind="increments", **ins_noise)\n'
        'still_imu = [still_meas["time_s"].to_numpy(), still_meas[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(), '
        'still_meas[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy()]\n'
        'still_aided = lambda source: an.filter.aided_ins(still_setup, source).run(*still_imu, progress=False)')
FRINGE = ("rng = np.random.default_rng(5)\npsi = rng.uniform(-np.pi, np.pi, 400)\n"
          "p = 0.5 + 0.02 * rng.standard_normal(400) + 0.3 * np.cos(0.4 + psi + 0.2 * rng.standard_normal(400))")
ROTVEC = "rotvec = np.array([[0.1, -0.2, 0.3], [0.0, 0.0, 0.0], [2.0, 1.0, -1.5]])"
ORIGIN = (Unit("origin_lla", "lat", "[0]"), Unit("origin_lla", "lon", "[1]"))
ERR_TABLE = ('err = pd.DataFrame({"time_s": np.arange(0.0, 1500.0), '
             '"horizontal_m": 1.0 + 0.01 * np.arange(1500.0) + np.sin(np.arange(1500.0) / 7.0)})')
MOUNT = ("mount = an.rotation.dcm_from_euler(np.array([1e-3, 2e-3, -1e-3]))\n"
         "ds_imu, ds_avu = ring, mount.T @ ring @ mount")  # six increments seen through a small mount
BETA = "beta = np.array([[0.1, 0.2, 0.3], [1.0, -0.5, 2.0]])"
SOURCED = (AIDED + '\nsetup = ins.setup\nsources = [an.filter.PositionFixes(fixes["fix_time"], fixes["fix_lla"], '
           'fixes["fix_cov"])]')
MOTION = ("i = np.searchsorted(car.time, car_fix_t - 1e-9)\n"
          "position = an.filter.PositionFixes(car_fix_t, car.lla[i], np.diag([0.25, 0.25, 1.0]))\n"
          "velocity = an.filter.VelocityFixes(car_fix_t, car.vel_ned[i], np.diag([0.0025, 0.0025, 0.01]))\n"
          'imu = car_imu[car_imu["time_s"] <= 15.0]\n'
          'level = an.alignment.coarse(imu[imu["time_s"] <= 4.0], car.lla[0], errors="mems")')
FIX_TABLE = ('fix_table = pd.DataFrame({"time_s": fixes["fix_time"], "lat_rad": fixes["fix_lla"][:, 0], '
             '"lon_rad": fixes["fix_lla"][:, 1], "h_m": fixes["fix_lla"][:, 2], "sigma_n_m": 1.0, "sigma_e_m": 1.0, '
             '"sigma_d_m": 1.0})')

CAMPAIGN = ("import tempfile, atomnav.campaign.sweep, atomnav.campaign.plots\nfrom campaign_toy import random_walk\n"
            "campaign, folder = an.campaign.Campaign(random_walk, {'dt_s': [0.5, 1.0]}, seeds=4), tempfile.mkdtemp()\n"
            "table = an.campaign.run(campaign, folder, progress=False)")

CATALOGUE: tuple[Clean, ...] = (
    # strapdown
    _c("atomnav.strapdown.integrate", "an.strapdown.integrate(imu, **init)", "imu = meas", ["imu"], time_origin="t0"),
    _c("atomnav.strapdown.integrate", 'an.strapdown.integrate(imu, kind="rates", **init)', "imu = meas_rates",
       ["imu"], time_origin="t0"),
    _c("atomnav.strapdown.integrate", "an.strapdown.integrate(imu, **still_init)", "imu = still_meas", ["imu"],
       time_origin="t0"),
    _c("atomnav.strapdown.integrate", "an.strapdown.integrate(meas, t0, lla, vel_ned, q_nb)", INIT, (), LLA),
    _c("atomnav.strapdown.Strapdown.run", "an.strapdown.Strapdown(**init).run(imu)", "imu = meas", ["imu"],
       time_origin="t0"),
    _c("atomnav.strapdown.Strapdown", "an.strapdown.Strapdown(t0, lla, vel_ned, q_nb).run(meas)", INIT, (), LLA),
    _c("atomnav.strapdown.Strapdown.reset", "(sd.reset(state), sd.state())",
       "sd = an.strapdown.Strapdown(**init)\nstate = nav.iloc[[-1]]", ["state"]),
    _c("atomnav.strapdown.integrate_attitude", "an.strapdown.integrate_attitude(init['q_nb'], dtheta)",
       'dtheta = meas[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy()'),
    # IMU errors
    _c("atomnav.imu.corrupt", 'an.imu.corrupt(imu, errors="tactical", dt=0.01, kind="increments", seed=7)',
       "imu = ideal", ["imu"]),
    _c("atomnav.imu.corrupt", 'an.imu.corrupt(imu, errors="tactical", dt=0.01, kind="rates", seed=7)',
       "imu = ideal_rates", ["imu"]),
    _c("atomnav.imu.ImuSimulator.corrupt",
       'an.imu.ImuSimulator("tactical", dt=0.01, kind="rates", seed=7).corrupt(accel, gyro)',
       'accel = ideal_rates[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy()\n'
       'gyro = ideal_rates[["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"]].to_numpy()', (),
       (Unit("accel", "accel"), Unit("gyro", "gyro"))),
    # trajectories
    _c("atomnav.trajectory.Trajectory.from_dataframe", "an.trajectory.Trajectory.from_dataframe(df)", "df = truth",
       ["df"]),
    _c("atomnav.trajectory.Trajectory.from_dataframe", "an.trajectory.Trajectory.from_dataframe(df)",
       'df = truth.drop(columns=["qw", "qx", "qy", "qz"])', ["df"]),
    _c("atomnav.trajectory.Trajectory", "an.trajectory.Trajectory(df)", "df = truth", ["df"]),
    _c("atomnav.trajectory.Trajectory.errors", "traj.errors(nav)", "", ["nav"]),
    _c("atomnav.trajectory.nav_table", "an.trajectory.nav_table(time, lla, vel_ned, q_nb)",
       "time, lla, vel_ned, q_nb = traj.time, traj.lla, traj.vel_ned, traj.q_nb", (),
       (Unit("time", "time"),) + LLA_ROWS),
    _c("atomnav.trajectory.stationary", "an.trajectory.stationary(10.0, euler=euler)", "euler = (0.1, -0.2, 1.5)",
       (), (Unit("euler", "euler"),)),
    _c("atomnav.trajectory.stationary", "an.trajectory.stationary(10.0, origin=lla)", "lla = init['lla']", (), LLA),
    # rotations
    _c("atomnav.rotation.quat_from_euler", "an.rotation.quat_from_euler(euler)", EULER, (), (Unit("euler", "euler"),)),
    _c("atomnav.rotation.dcm_from_euler", "an.rotation.dcm_from_euler(euler)", EULER, (), (Unit("euler", "euler"),)),
    _c("atomnav.astro.euler_dcm", "an.astro.euler_dcm(euler)", EULER, (), (Unit("euler", "euler"),)),
    _c("atomnav.rotation.quat_from_dcm", "an.rotation.quat_from_dcm(dcm)", "dcm = an.rotation.dcm_from_quat(traj.q_nb)"),
    _c("atomnav.rotation.dcm_from_quat", "an.rotation.dcm_from_quat(q)", "q = traj.q_nb"),
    _c("atomnav.rotation.attitude_error_angle", "an.rotation.attitude_error_angle(q_a, q_b)",
       'q_a, q_b = traj.q_nb[1:], nav[["qw", "qx", "qy", "qz"]].to_numpy()'),
    # Earth
    _c("atomnav.earth.lla_to_ecef", "an.earth.lla_to_ecef(lla)", "lla = traj.lla", (), LLA_ROWS),
    _c("atomnav.earth.dcm_ned_to_ecef", "an.earth.dcm_ned_to_ecef(lat, lon)", "lat, lon = init['lla'][0], init['lla'][1]",
       (), (Unit("lat", "lat"), Unit("lon", "lon"))),
    _c("atomnav.earth.gravity", "an.earth.gravity(lat, 200.0)", "lat = traj.lla[:, 0]", (), (Unit("lat", "lat"),)),
    _c("atomnav.earth.schuler_period", "an.earth.schuler_period(lat, 200.0)", "lat = 0.9", (), (Unit("lat", "lat"),)),
    # atom interferometer closed forms
    _c("atomnav.cai.predictor.k_eff", "an.cai.predictor.k_eff(wavelength)", "wavelength = 780.241e-9", (),
       (Unit("wavelength", "wavelength"),)),
    _c("atomnav.cai.predictor.phase_constant", "an.cai.predictor.phase_constant(k_c, 2.8, w, f, T)",
       "w, f, T = np.array([0.0, 0.0, 7.29e-5]), np.array([0.0, 0.0, -9.81]), 0.05", (), (Unit("T", "T"),)),
    _c("atomnav.cai.predictor.scale_factors", "an.cai.predictor.scale_factors(T)", "T = 0.05", (), (Unit("T", "T"),)),
    _c("atomnav.cai.predictor.phase_noise", "an.cai.predictor.phase_noise(0.01, contrast)", "contrast = 0.5", (),
       (Unit("contrast", "contrast"),)),
    _c("atomnav.cai.readout.readout", "an.cai.readout(phi, contrast=contrast)",
       "phi, contrast = np.linspace(0.0, 3.0, 7), 0.5", (), (Unit("contrast", "contrast"),)),
    # sensor noise
    _c("atomnav.noise.allan.allan_variance", "an.noise.allan.allan_variance(data, tau0=1.0)",
       "data = pd.Series(omega, name='omega_deg_h')", ["data"]),
    _c("atomnav.noise.allan.time_deviation", "an.noise.allan.time_deviation(data, tau0=1.0)",
       "data = pd.Series(np.cumsum(omega), name='phase_s')", ["data"]),
    _c("atomnav.noise.allan.time_interval_error", "an.noise.allan.time_interval_error(phase, tau0=1.0)",
       "phase = pd.Series(np.cumsum(omega), name='phase_s')", ["phase"]),
    # (the fit carries its input table; the fit itself is compared)
    _c("atomnav.noise.allan.fit_allan_table",
       "dataclasses.replace(an.noise.allan.fit_allan_table(table, n_samples=2048), table=None)",
       "table = allan", ["table"]),
    _c("atomnav.noise.filters.kalman", "an.noise.filters.kalman(series, arima)", "series = pd.Series(omega[:500])",
       ["series"]),
    # GNSS
    _c("atomnav.gnss.spp.solve", "an.gnss.spp.solve(eph, obs)", "", ["obs"], time_origin="eph"),
    _c("atomnav.gnss.observations.simulate", "an.gnss.observations.simulate(eph, t, lla, np.zeros((10, 3)), seed=1)",
       "t, lla = gnss_t, gnss_lla", (), (Unit("t", "time"),) + LLA_ROWS),
    _c("atomnav.gnss.observations.obs_arrays", "an.gnss.observations.obs_arrays(obs)", "", ["obs"],
       epoch=GPS_WEEK_START),
    # aided INS (a 10 s record with five position fixes)
    _c("atomnav.filter.aided.position_aided_ins",
       'an.filter.position_aided_ins(t0, lla, vel_ned, q_nb, "rates", fix_time, fix_lla, fix_cov, **ins_noise)'
       '.run(imu_t, imu_gyro, imu_accel, progress=False)',
       f'{INIT}\nfix_time, fix_lla, fix_cov = fixes["fix_time"], fixes["fix_lla"], fixes["fix_cov"]', (),
       (Unit("fix_lla", "lat", "[:, 0]"), Unit("fix_lla", "lon", "[:, 1]"), Unit("fix_time", "time")) + LLA),
    _c("atomnav.filter.aided.AidedIns.process", "ins.process(time, gyro, accel)", AIDED, (), AIDED_UNITS),
    _c("atomnav.filter.aided.AidedIns.run", "ins.run(time, gyro, accel, chunk_s=3.0, progress=False)", AIDED, (),
       AIDED_UNITS),
    _c("atomnav.cai.sensor.cai_aided_ins",
       'an.cai.cai_aided_ins(t0, lla, vel_ned, q_nb, an.cai.seed003_sensor(), shots, phase=phase, noise=noise, '
       'kind="rates", ellipsoid="kinematic").run(*[slalom_imu[c].to_numpy() for c in CAI_IMU], progress=False)',
       't0, lla, vel_ned, q_nb = slalom_init["t0"], slalom_init["lla"], slalom_init["vel_ned"], slalom_init["q_nb"]\n'
       'shots, phase, noise = cai_shots, cai_phase, cai_noise\n'
       'CAI_IMU = ["time_s", ["gyro_x_rad_s", "gyro_y_rad_s", "gyro_z_rad_s"], ["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]]',
       (), (Unit("shots", "time"),) + LLA),
    _c("atomnav.cai.sensor.CaiShots", "an.cai.CaiShots(an.cai.seed003_sensor(), shots, phase=phase, noise=noise)",
       "shots, phase, noise = cai_shots, cai_phase, cai_noise", (), (Unit("shots", "time"),)),
    # the atom-interferometer phase predictor (1 s of an analytic motion at 200 Hz)
    _c("atomnav.cai.predictor.predict_phase", "an.cai.predictor.predict_phase(t, f, w, shots, T, an.cai.Channels.cyclic())",
       SINE_IMU, (), SINE_UNITS),
    _c("atomnav.cai.predictor.check_jacobian", "an.cai.predictor.check_jacobian(t, f, w, shots, T, an.cai.Channels.cyclic())",
       SINE_IMU, (), SINE_UNITS),
    _c("atomnav.cai.predictor.motion_imu", "an.cai.predictor.motion_imu(sine, t, gravity=(0.0, 0.0, 9.81))",
       "t = sine_t", (), (Unit("t", "time"),)),
    # (a motion keeps its arguments as given: it is judged by the IMU output it gives)
    _c("atomnav.cai.predictor.SineMotion",
       "an.cai.predictor.motion_imu(an.cai.predictor.SineMotion(position_poly=pp, position_sines=ps, attitude_poly=ap, "
       "attitude_sines=asin), sine_t, gravity=(0.0, 0.0, 9.81))",
       "pp, ps, ap, asin = (np.array(getattr(sine, k), dtype=float) for k in "
       "('position_poly', 'position_sines', 'attitude_poly', 'attitude_sines'))", (),
       (Unit("ap", "euler", "[:, 0]"),)),
    # star cameras
    _c("atomnav.astro.Catalog", "an.astro.Catalog(dirs, mags, ids)", "dirs, mags, ids = stars, np.array([1.0, 2.0, 3.0]), np.arange(3)"),
    _c("atomnav.astro.aberration", "an.astro.aberration(directions, v)", "directions, v = stars, np.array([0.0, 0.0, 3e4])"),
    _c("atomnav.astro.refraction_correct", "an.astro.refraction_correct(s, up, 1.0003)",
       "s, up = stars, np.tile([0.0, 0.0, 1.0], (3, 1))"),
    _c("atomnav.astro.results.Observations", "an.astro.results.Observations(epoch, camera, s_cf, g)", OBS),
    _c("atomnav.astro.star_attitudes", "an.astro.star_attitudes(an.astro.results.Observations(epoch, camera, s_cf, g), "
       "2, cameras, 7.8e-5)", OBS + "\ncameras = np.eye(3)[None]"),
    _c("atomnav.astro.gyro_increments", "an.astro.gyro_increments(0.0, 0.005, rho, epochs, an.astro.GyroErrorModel.vasilyuk2024())",
       RHO),
    _c("atomnav.astro.dead_reckoning_cov",
       "an.astro.dead_reckoning_cov(0.0, 0.005, rho, epochs, an.astro.GyroErrorModel.vasilyuk2024())", RHO),
    _c("atomnav.astro.model_covariance", "an.astro.model_covariance(cal, ds_imu, ds_avu, e_imu, p_avu)",
       "ds_imu, ds_avu = ring, ring @ an.rotation.dcm_from_euler(np.array([1e-3, 2e-3, -1e-3]))\n"
       "cal = an.astro.calibrate(ds_imu, ds_avu)\n"
       "e_imu, p_avu = np.tile(1e-10 * np.eye(3), (6, 1, 1)), np.tile(1e-10 * np.eye(3), (7, 1, 1))"),
    # estimation
    _c("atomnav.filter.riccati.dare", "an.filter.riccati.dare(phi, q, h, r)", KF),
    _c("atomnav.filter.riccati.closed_loop_matrix", "an.filter.riccati.closed_loop_matrix(phi, h, gain)",
       KF + "\ngain = an.filter.riccati.dare(phi, q, h, r).gain"),
    _c("atomnav.filter.riccati.kalman_recursion", "an.filter.riccati.kalman_recursion(phi, q, h, r, p0, 5)",
       KF + "\np0 = np.diag([1.0, 0.5])"),
    _c("atomnav.filter.engine.rts_smooth", "an.filter.engine.rts_smooth(phi, x_prior, p_prior, x_post, p_post)",
       "kf = an.filter.engine.KalmanFilter(np.diag([1.0, 0.5]), mode='open')\nrows = []\n"
       "for k, z in enumerate([0.3, -0.1, 0.5, 0.2]):\n"
       "    if k:\n"
       "        kf.predict(kf_phi, kf_q)\n"
       "    prior = (kf.x, kf.p)\n"
       "    kf.update([z], kf_h, kf_r)\n"
       "    rows.append((kf_phi, *prior, kf.x, kf.p))\n"
       "phi, x_prior, p_prior, x_post, p_post = (np.array(c) for c in zip(*rows))"),
    _c("atomnav.filter.engine.ins_error_model", "an.filter.engine.ins_error_model(lla, vel_ned, q_nb, f_b, gyro_psd=1e-10, accel_psd=1e-6)",
       "lla, vel_ned, q_nb, f_b = traj.lla[:50], traj.vel_ned[:50], traj.q_nb[:50], imu_accel[:50]", (),
       LLA_ROWS + (Unit("f_b", "accel"),)),
    _c("atomnav.filter.analysis.Scenario",
       "an.filter.analysis.covariance_analysis(an.filter.analysis.Scenario(f, qc, dt, p0, h, r, measure))",
       "f, qc = np.repeat([[[0.0, 1.0], [0.0, 0.0]]], 20, axis=0), np.repeat([np.diag([0.0, 0.01])], 20, axis=0)\n"
       "dt, p0, h, r, measure = np.full(20, 0.5), np.eye(2), np.array([[1.0, 0.0]]), np.array([[0.2]]), [True] * 21",
       (), (Unit("dt", "time"),)),
    # IMU errors and the plausibility checks themselves
    _c("atomnav.imu.TriadErrors",
       'an.imu.corrupt(ideal, errors=an.imu.ImuErrors(accel=an.imu.TriadErrors(bias=bias, misalignment=m)), dt=0.01, '
       'kind="increments", seed=7)', "bias, m = np.array([1e-3, -2e-3, 5e-4]), 1e-4 * (np.ones((3, 3)) - np.eye(3))"),
    _c("atomnav.plausibility.imu", 'an.plausibility.imu(time, gyro, accel, "rates")',
       "time, gyro, accel = imu_t, imu_gyro, imu_accel", (),
       (Unit("time", "time"), Unit("gyro", "gyro"), Unit("accel", "accel"))),
    _c("atomnav.plausibility.imu", 'an.plausibility.imu(time, gyro, accel, "increments", dt=0.01)',
       'time = still_meas["time_s"].to_numpy()\n'
       'gyro = still_meas[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy()\n'
       'accel = still_meas[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy()', (),
       (Unit("time", "time"), Unit("gyro", "gyro"))),
    _c("atomnav.plausibility.specific_force", 'an.plausibility.specific_force(f, "f")', "f = imu_accel", (),
       (Unit("f", "accel"),)),
    # reading a user's own files (a DataFrame already read; the files are read by pandas)
    _c("atomnav.io.read_imu", 'an.io.read_imu(log, columns=log_columns, units={"gyro": "deg/s", "accel": "g"}, kind="rates")',
       LOG, ["log"]),
    _c("atomnav.io.read_trajectory", 'an.io.read_trajectory(ref, columns=ref_columns, units={"lat": "deg", "lon": "deg", "euler": "rad"})',
       REF, ["ref"]),
    # (it reads column names only: its mistakes are those of the calls that use it)
    _c("atomnav.trajectory.imu_kind", "an.trajectory.imu_kind(None, imu)", "imu = meas"),
    _c("atomnav.plausibility.swapped_blocks", 'an.plausibility.swapped_blocks(time, gyro, accel, "rates")',
       "time, gyro, accel = imu_t, imu_gyro, imu_accel"),
    # initial alignment on the 10 s static record
    _c("atomnav.alignment.coarse", 'an.alignment.coarse(imu, lla, errors="tactical")', ALIGN, ["imu"], LLA),
    _c("atomnav.alignment.level", 'an.alignment.level(imu, lla, errors="tactical")', ALIGN, ["imu"], LLA),
    _c("atomnav.alignment.fine", "an.alignment.fine(imu, lla, start)",
       ALIGN + '\nstart = an.alignment.coarse(imu, lla, errors="tactical")', ["imu"], LLA),
    _c("atomnav.filter.sources.ZeroVelocity", "still_aided(an.filter.ZeroVelocity(time, 0.01))", ZUPT, (),
       (Unit("time", "time"),)),
    _c("atomnav.filter.sources.ZeroRate", "still_aided(an.filter.ZeroRate(time, 1e-12))", ZUPT, (),
       (Unit("time", "time"),)),
    # measurement sources (a source is what it holds: times, values, covariances)
    _c("atomnav.filter.sources.PositionFixes", "an.filter.PositionFixes(time, lla, cov)",
       'time, lla, cov = fixes["fix_time"], fixes["fix_lla"], fixes["fix_cov"]', (),
       (Unit("time", "time"),) + LLA_ROWS),
    _c("atomnav.filter.sources.PositionFixes", "an.filter.PositionFixes(fix_table)", FIX_TABLE, ["fix_table"]),
    _c("atomnav.filter.sources.VelocityFixes", "an.filter.VelocityFixes(time, vel_ned, np.eye(3) * 0.01)",
       "time, vel_ned = traj.time[50::100], traj.vel_ned[50::100]", (), (Unit("time", "time"),)),
    _c("atomnav.filter.sources.aided_ins",
       "an.filter.aided_ins(setup, sources).run(time, gyro, accel, progress=False)",
       AIDED + '\nsetup = ins.setup\nsources = [an.filter.PositionFixes(fixes["fix_time"], fixes["fix_lla"], fixes["fix_cov"]), '
       'an.filter.VelocityFixes(traj.time[50::100], traj.vel_ned[50::100], np.eye(3) * 0.01)]', (), AIDED_UNITS),
    # atom-interferometer campaigns on a trajectory of the user's
    _c("atomnav.cai.sensor.incomplete_shots", "an.cai.incomplete_shots(an.cai.seed003_sensor(), shots, time)",
       "shots, time = np.array([0.0, 0.5, 1.9]), slalom.time", (), (Unit("shots", "time"), Unit("time", "time"))),
    _c("atomnav.cai.campaign.run_campaign",
       "an.cai.run_campaign(slalom, config, runs=2, seed=1, progress=False)",
       "config = an.cai.ScenarioConfig(an.cai.seed003_sensor(), an.cai.seed003_filter())"),
    # plots: compared by what they draw (every line's axes title, label and data)
    _c("atomnav.plots.trajectory", "drawn(an.plots.trajectory(nav, reference))",
       PLOTS + '\nnav, reference = nav[["lat_rad", "lon_rad", "h_m"]], truth[["lat_rad", "lon_rad", "h_m"]]',
       ["nav", "reference"]),
    _c("atomnav.plots.errors", "drawn(an.plots.errors(err, sigma))", PLOTS_AIDED + "\nerr = traj.errors(res.nav)\n"
       'sigma = res.nav[["time_s", *[f"sigma_{b}[{i}]" for b in ("position", "velocity", "attitude") for i in range(3)]]]',
       ["err", "sigma"]),
    _c("atomnav.plots.imu_errors", "drawn(an.plots.imu_errors(result, truth))",
       PLOTS_AIDED + '\nresult = res.nav[["time_s", *[c for c in res.nav.columns if "bias" in c]]]\ntruth = meas[["time_s", *an.imu.BIAS_COLUMNS[0], *an.imu.BIAS_COLUMNS[1]]]',
       ["result", "truth"]),
    _c("atomnav.plots.consistency", "drawn(an.plots.consistency(nis=nis, nees=nees, dof=3))",
       PLOTS_AIDED + '\nnis, err = res.measurements, traj.errors(res.nav)\n'
       'nees = pd.DataFrame({"time_s": err["time_s"], "nees": (err[["dpos_n_m", "dpos_e_m", "dpos_d_m"]] ** 2).sum(axis=1)})',
       ["nis", "nees"]),
    _c("atomnav.plots.allan", "drawn(an.plots.allan(table, fit, unit=an.units.DEG_PER_HOUR))",
       PLOTS + "\ntable, fit = allan, an.noise.allan.fit_allan(omega, 1.0)", ["table"]),
    # atom-interferometer readout noise (Tennstedt et al. 2021: a fringe scanned by a known phase)
    _c("atomnav.cai.noise_id.fringe_track", "an.cai.noise_id.fringe_track(p, psi)", FRINGE),
    _c("atomnav.cai.noise_id.residuals", "an.cai.noise_id.residuals(p, psi, track)",
       FRINGE + "\ntrack = an.cai.noise_id.fringe_track(p, psi)", ["track"]),
    _c("atomnav.cai.noise_id.identify_noise", "an.cai.noise_id.identify_noise(x, phi, amplitude)",
       FRINGE + "\nx, phi, amplitude = an.cai.noise_id.residuals(p, psi, an.cai.noise_id.fringe_track(p, psi))"),
    # atom-interferometer sensitivity functions (Tennstedt et al. 2023)
    _c("atomnav.cai.predictor.phase_jacobian",
       "an.cai.predictor.phase_jacobian(t, f, w, shots, T, an.cai.Channels.cyclic())", SINE_IMU, (), SINE_UNITS),
    _c("atomnav.cai.sensitivity.convolution_phase",
       "an.cai.convolution_phase(t, acceleration, centres, t_dark=t_dark, tau=1e-5, k=1.61e7)",
       "t = np.arange(1000) / 1000.0\nacceleration, centres, t_dark = 0.1 * np.sin(6 * np.pi * t), np.array([0.3, 0.6]), 0.05",
       (), (Unit("t", "time"), Unit("t_dark", "T"))),
    _c("atomnav.cai.sensitivity.ideal_transfer", "an.cai.ideal_transfer(T, omega)",
       "T, omega = 0.05, np.array([1.0, 10.0, 100.0])", (), (Unit("T", "T"),)),
    _c("atomnav.cai.sensitivity.sensitivity", "an.cai.sensitivity(t, t_dark, 1e-5)",
       "t, t_dark = np.linspace(-0.06, 0.06, 7), 0.05", (), (Unit("t_dark", "T"),)),
    _c("atomnav.cai.sensor.CaiShots.incomplete",
       "an.cai.CaiShots(an.cai.seed003_sensor(), np.array([0.0, 0.5, 1.9]), phase=cai_phase[:3], noise=cai_noise[:3])"
       ".incomplete(time)",
       "time = slalom.time", (), (Unit("time", "time"),)),
    # rotations between representations (the attitudes of the 10 s trajectory)
    _c("atomnav.rotation.euler_from_quat", "an.rotation.euler_from_quat(q)", "q = traj.q_nb"),
    _c("atomnav.rotation.euler_from_dcm", "an.rotation.euler_from_dcm(dcm)", "dcm = an.rotation.dcm_from_quat(traj.q_nb)"),
    _c("atomnav.rotation.rotvec_from_quat", "an.rotation.rotvec_from_quat(q)", "q = traj.q_nb"),
    _c("atomnav.rotation.rotvec_from_dcm", "an.rotation.rotvec_from_dcm(dcm)", "dcm = an.rotation.dcm_from_quat(traj.q_nb)"),
    _c("atomnav.rotation.quat_from_rotvec", "an.rotation.quat_from_rotvec(rotvec)", ROTVEC),
    _c("atomnav.rotation.dcm_from_rotvec", "an.rotation.dcm_from_rotvec(rotvec)", ROTVEC),
    _c("atomnav.rotation.quat_multiply", "an.rotation.quat_multiply(a, b)", "a, b = traj.q_nb[1:], traj.q_nb[:-1]"),
    _c("atomnav.rotation.quat_normalize", "an.rotation.quat_normalize(q)", "q = 2.0 * traj.q_nb"),
    _c("atomnav.rotation.skew", "an.rotation.skew(v)", "v = imu_gyro"),
    # Earth: frames and local parameters along the trajectory
    _c("atomnav.earth.ecef_to_lla", "an.earth.ecef_to_lla(ecef)", "ecef = an.earth.lla_to_ecef(traj.lla)"),
    _c("atomnav.earth.ecef_to_ned", "an.earth.ecef_to_ned(ecef, origin_lla)",
       "ecef, origin_lla = an.earth.lla_to_ecef(traj.lla), init['lla']", (), ORIGIN),
    _c("atomnav.earth.ned_to_ecef", "an.earth.ned_to_ecef(ned, origin_lla)",
       "ned, origin_lla = an.earth.lla_to_ned(traj.lla, init['lla']), init['lla']", (), ORIGIN),
    _c("atomnav.earth.lla_to_ned", "an.earth.lla_to_ned(lla, origin_lla)", "lla, origin_lla = traj.lla, init['lla']", (),
       LLA_ROWS + ORIGIN),
    _c("atomnav.earth.navigation_rates", "an.earth.navigation_rates(lla, vel_ned)", "lla, vel_ned = traj.lla, traj.vel_ned",
       (), LLA_ROWS),
    _c("atomnav.earth.parameters", "an.earth.parameters(lla)", "lla = traj.lla", (), LLA_ROWS),
    _c("atomnav.earth.radii", "an.earth.radii(lat)", "lat = traj.lla[:, 0]", (), (Unit("lat", "lat"),)),
    # the plausibility rules themselves, on an IMU record in SI
    # (a check returns its argument unchanged: it is judged by its warning)
    _c("atomnav.plausibility.angular_rate", 'an.plausibility.angular_rate(w, "w") is w', "w = imu_gyro", (),
       (Unit("w", "gyro"),)),
    _c("atomnav.plausibility.time_steps", 'an.plausibility.time_steps(t, "t") is t', "t = imu_t", (),
       (Unit("t", "imu_time"),)),
    # diagnostics
    _c("atomnav.diagnostics.zero_crossing_periods", "an.diagnostics.zero_crossing_periods(t, v)",
       "t = np.linspace(0.0, 10.0, 1001)\nv = np.sin(2 * np.pi * 0.7 * t + 0.1)", (), (Unit("t", "time"),)),
    # sensor noise: Allan statistics, ARMA modelling and filters of the gyro noise series (Niu et al. 2025)
    _c("atomnav.noise.allan.bias", "an.noise.allan.bias(series)", "series = omega"),
    _c("atomnav.noise.allan.bias_stability", "an.noise.allan.bias_stability(series, window=3)", "series = omega"),
    _c("atomnav.noise.allan.fit_allan", "an.noise.allan.fit_allan(series, 1.0)", "series = omega"),
    _c("atomnav.noise.allan.fit_allan", "an.noise.allan.fit_allan(series, 1.0)", "series = pd.Series(omega)", ["series"]),
    _c("atomnav.noise.arma.fit_arma", "an.noise.arma.fit_arma(series)", "series = pd.Series(omega[:500])", ["series"]),
    _c("atomnav.noise.baselines.butterworth_lowpass", "an.noise.baselines.butterworth_lowpass(series, 1.0, fc=0.01)",
       "series = pd.Series(omega)", ["series"]),
    _c("atomnav.noise.allan.long_term_stability", "an.noise.allan.long_term_stability(series, 1.0)", "series = omega"),
    _c("atomnav.noise.allan.short_term_sensitivity", "an.noise.allan.short_term_sensitivity(series, 1.0)",
       "series = omega"),
    _c("atomnav.noise.arma.difference", "an.noise.arma.difference(series)", "series = omega"),
    _c("atomnav.noise.arma.undifference", "an.noise.arma.undifference(diffs, initial)",
       "diffs, initial = np.diff(omega), omega[0]"),
    _c("atomnav.noise.arma.acf_pacf", "an.noise.arma.acf_pacf(z, nlags=20)", "z = omega"),
    _c("atomnav.noise.arma.durbin_watson", "an.noise.arma.durbin_watson(e)", "e = np.diff(omega)"),
    _c("atomnav.noise.arma.ljung_box", "an.noise.arma.ljung_box(e)", "e = np.diff(omega)"),
    _c("atomnav.noise.arma.stationarity", "an.noise.arma.stationarity(z)", "z = omega[:500]"),
    _c("atomnav.noise.arma.fit_arma", "an.noise.arma.fit_arma(series)", "series = omega[:500]"),
    _c("atomnav.noise.arma.select_arma", "an.noise.arma.select_arma(d, max_p=1, max_q=1)", "d = np.diff(omega[:500])"),
    _c("atomnav.noise.baselines.butterworth_lowpass", "an.noise.baselines.butterworth_lowpass(series, 1.0, fc=0.01)",
       "series = omega"),
    _c("atomnav.noise.baselines.wavelet_denoise", "an.noise.baselines.wavelet_denoise(series)", "series = omega"),
    _c("atomnav.noise.filters.filter_series", "an.noise.filters.filter_series(series, config)",
       "series = omega[:500]\nconfig = an.noise.filters.ArmaFilterConfig(arima.ar, arima.ma, arima.sigma2)"),
    _c("atomnav.noise.filters.sage_husa", "an.noise.filters.sage_husa(series, arima)", "series = omega[:500]"),
    _c("atomnav.noise.report.compare", "an.noise.report.compare(series)", "series = omega"),
    # GNSS: satellites, Doppler, RINEX writing and the thesis scenarios' error summaries
    _c("atomnav.gnss.ephemeris.Ephemerides.state", 'eph.state("G01", t)', "t = np.arange(0.0, 600.0, 30.0)", (),
       (Unit("t", "time"),)),
    _c("atomnav.gnss.ephemeris.Ephemerides.look_angles", 'eph.look_angles("G01", t, lla)',
       "t, lla = np.arange(0.0, 600.0, 30.0), init['lla']", (), (Unit("t", "time"),) + LLA),
    _c("atomnav.gnss.observations.doppler_to_rate", "an.gnss.observations.doppler_to_rate(doppler_hz, sat, channel)",
       'doppler_hz, sat, channel = np.array([1000.0, -2500.0, 300.0]), ["G01", "R05", "R07"], np.array([0, 1, -7])'),
    _c("atomnav.gnss.rinex.write_obs", "an.gnss.rinex.write_obs(path, obs, week_start).read_text()",
       "import datetime, os, tempfile\npath = os.path.join(tempfile.mkdtemp(), 'obs.rnx')\n"
       f"week_start = datetime.datetime.fromisoformat({GPS_WEEK_START!r})", ["obs"], epoch=GPS_WEEK_START),
    _c("atomnav.gnss.scenarios.last_rms", "an.gnss.scenarios.last_rms(err, 600.0)", ERR_TABLE, ["err"]),
    _c("atomnav.gnss.scenarios.outage_summary", "an.gnss.scenarios.outage_summary(err, 600.0, 60.0)", ERR_TABLE,
       ["err"]),
    # the tightly coupled INS on the 10 s record (the GNSS observations of a receiver at its start)
    _c("atomnav.gnss.tight.GnssObservations",
       "an.filter.aided_ins(setup, [an.gnss.tight.GnssObservations(eph, obs)]).run(time, gyro, accel, progress=False)",
       AIDED + "\nsetup = ins.setup", ["obs"], AIDED_UNITS, epoch=GPS_WEEK_START),
    _c("atomnav.gnss.tight.tight_ins", "an.gnss.tight.tight_ins(eph, obs, setup=setup).run(time, gyro, accel, progress=False)",
       AIDED + "\nsetup = ins.setup", ["obs"], AIDED_UNITS, epoch=GPS_WEEK_START),
    # star cameras: the mount calibration of Vasilyuk et al. 2024 on six rotations
    _c("atomnav.astro.astro_increments", "an.astro.astro_increments(s_vf, p_avu)",
       "s_vf, p_avu = ring, np.tile(1e-10 * np.eye(3), (6, 1, 1))"),
    _c("atomnav.astro.calibrate", "an.astro.calibrate(ds_imu, ds_avu)", MOUNT),
    _c("atomnav.astro.observability", "an.astro.observability(ds_avu)", MOUNT),
    _c("atomnav.astro.d1", "an.astro.d1(beta)", BETA, (), (Unit("beta", "euler"),)),
    _c("atomnav.astro.d2", "an.astro.d2(beta)", BETA, (), (Unit("beta", "euler"),)),
    _c("atomnav.astro.euler_from_dcm", "an.astro.euler_from_dcm(c)", "c = ring"),
    _c("atomnav.astro.refraction_apply", "an.astro.refraction_apply(s, up, 1.0003)",
       "s, up = stars, np.tile([0.0, 0.0, 1.0], (3, 1))"),
    _c("atomnav.astro.simulate_observations",
       "an.astro.simulate_observations(catalog, s_gcrs_vf, up_gcrs, cameras, fov_half_rad=0.5, m_lim=6.0, "
       "sigma_s_rad=1e-5, n_refr=1.0003, seed=1)",
       "sky = np.random.default_rng(2).normal(size=(400, 3))\n"
       "catalog = an.astro.Catalog(sky / np.linalg.norm(sky, axis=1)[:, None], np.linspace(0.0, 6.5, 400), np.arange(400))\n"
       "s_gcrs_vf, up_gcrs, cameras = ring[:3], np.tile([0.0, 0.0, 1.0], (3, 1)), np.eye(3)[None]"),
    # the aided INS built from sources (SourcedIns), fed chunk by chunk or whole
    _c("atomnav.filter.sources.SourcedIns.process", "an.filter.aided_ins(setup, sources).process(time, gyro, accel)",
       SOURCED, (), AIDED_UNITS),
    _c("atomnav.filter.sources.SourcedIns.run", "an.filter.aided_ins(setup, sources).run(time, gyro, accel, progress=False)",
       SOURCED, (), AIDED_UNITS),
    # GNSS outages withheld from the aided INS and scored (windows [2, 3.5) and [5, 6.5) s over the five fixes)
    _c("atomnav.filter.outages.outage_windows", "an.filter.outages.outage_windows(time, length=1.5, first=1.0, spacing=3.0)",
       'time = fixes["fix_time"]', (), (Unit("time", "time"),)),
    _c("atomnav.filter.outages.outage_analysis",
       "an.filter.outages.outage_analysis(setup, sources[0], (time, gyro, accel), windows, progress=False)",
       SOURCED + "\nwindows = np.array([[2.0, 3.5], [5.0, 6.5]])", (), AIDED_UNITS + (Unit("windows", "time"),)),
    _c("atomnav.filter.outages.score_outages", "an.filter.outages.score_outages(solution, reference, windows)",
       'solution = nav[["time_s", "lat_rad", "lon_rad", "h_m"]]\n'
       'reference = an.filter.PositionFixes(fixes["fix_time"], fixes["fix_lla"], fixes["fix_cov"])\n'
       "windows = np.array([[2.0, 3.5], [5.0, 6.5]])", ["solution"], (Unit("windows", "time"),), time_origin="windows"),
    _c("atomnav.filter.outages.score_outages", "an.filter.outages.score_outages(solution, reference, windows)",
       AIDED + '\nres = ins.run(time, gyro, accel, progress=False)\nsolution = res.nav[["time_s", "lat_rad", "lon_rad", "h_m", "qw", "qx", "qy", "qz"]]\n'
       'reference = an.filter.PositionFixes(fixes["fix_time"], fixes["fix_lla"], fixes["fix_cov"], lever_arm=[0.5, 0.0, -0.3])\n'
       "windows = np.array([[2.0, 3.5], [5.0, 6.5]])", ["solution"], (Unit("windows", "time"),), time_origin="windows"),
    # alignment in motion: the car levelled at rest until 4 s, heading from its GNSS velocity (15 s of 1 Hz fixes)
    _c("atomnav.alignment.in_motion", "an.alignment.in_motion(imu, position, velocity, level)", MOTION, ["imu"]),
    _c("atomnav.alignment.MotionAlignment.after", "a.after(imu)",
       MOTION + "\na = an.alignment.in_motion(imu, position, velocity, level)\nimu = car_imu", ["imu"]),
    # design-study campaigns on the closed-form random walk of tests/campaign_toy.py
    _c("atomnav.campaign.plan.Campaign", "an.campaign.Campaign(random_walk, {'dt_s': [0.5, 1.0]}, seeds=4)",
       "import atomnav.campaign\nfrom campaign_toy import random_walk"),
    _c("atomnav.campaign.sweep.compare", "an.campaign.compare(table, campaign)", CAMPAIGN, ["table"]),
    _c("atomnav.campaign.plots.error_vs_parameter", "drawn(an.campaign.plots.error_vs_parameter(report, 'dt_s', 'pos_error_m'))",
       PLOTS + "\n" + CAMPAIGN + "\nreport = an.campaign.compare(table, campaign)", ["report"]),
    _c("atomnav.campaign.plots.error_map", "drawn(an.campaign.plots.error_map(grid, 'steps', 'dt_s', 'pos_error_m_cov', target=5.0))",
       PLOTS + "\n" + CAMPAIGN + "\ngrid = an.campaign.sweep(random_walk, {'steps': [10, 20, 40], 'dt_s': [0.5, 1.0]}, "
       "progress=False)", ["grid"]),
    _c("atomnav.campaign.plots.throughput", "drawn(an.campaign.plots.throughput(timing))",
       PLOTS + "\nimport atomnav.campaign.plots\ntiming = pd.DataFrame({'run': range(6), 'point': [0, 0, 0, 1, 1, 1], "
       "'worker': ['a', 'b', 'a', 'b', 'a', 'a'], 'elapsed_s': [0.5, 1.0, 0.25, 2.0, 0.5, 0.75]})", ["timing"]),
    # vehicle and pedestrian constraints on the 10 s static record
    _c("atomnav.filter.constraints.detect_still",
       'an.filter.constraints.detect_still(time, gyro, accel, kind="increments", lla=lla, window=20)',
       ZUPT + '\ntime, gyro, accel = still_imu\nlla = still_init["lla"]', (),
       (Unit("time", "imu_time"), Unit("gyro", "gyro"), Unit("accel", "accel")) + LLA),
    _c("atomnav.filter.constraints.NonHolonomic", "still_aided(an.filter.constraints.NonHolonomic(time, 0.05))", ZUPT, (),
       (Unit("time", "time"),)),
)


EXEMPT = {
    # an option name in, the table of its docstring out
    "atomnav.trajectory.Trajectory.ideal_imu": "takes an option name; the table is its output",
    # result containers: the library builds them from its own checked arrays and returns them
    "atomnav.astro.Increments": "the result of astro.gyro_increments",
    "atomnav.astro.results.StarAttitudes": "the result of astro.star_attitudes",
    "atomnav.astro.results.AstroIncrements": "the result of astro.astro_increments",
    "atomnav.cai.results.HybridResult": "the result of a CAI hybrid Monte Carlo",
    "atomnav.noise.filters.KalmanResult": "the result of noise.filters.kalman",
    "atomnav.noise.allan.AllanFit": "the result of noise.allan.fit_allan",
    "atomnav.noise.arma.ArmaFit": "the result of noise.arma.fit_arma",
    "atomnav.noise.report.Comparison": "the result of noise.report.compare",
    "atomnav.gnss.solution.PosSolution": "the result of gnss.read_pos",
    "atomnav.gnss.spp.SppResult": "the result of gnss.solve",
    "atomnav.gnss.rinex.RinexObservations": "the result of gnss.rinex.read_obs",
    "atomnav.astro.results.Calibration": "the result of astro.calibrate",
    "atomnav.filter.aided.AidedResult": "the result of an aided INS run",
    "atomnav.filter.analysis.MonteCarlo": "the result of a filter Monte-Carlo campaign",
    "atomnav.filter.outages.OutageResult": "the result of filter.outage_analysis",
    "atomnav.filter.constraints.StillPeriods": "the result of filter.constraints.detect_still",
    "atomnav.io.ImuLog": "the result of io.read_imu",
    "atomnav.io.SamplingReport": "the sampling report of an io.ImuLog",
    "atomnav.alignment.FineAlignment": "the result of alignment.fine",
    "atomnav.filter.aided.SmoothedResult": "the result of smoothing an aided INS",
    # its constructor takes an error model and options; the arrays are those of its corrupt()
    "atomnav.imu.ImuSimulator": "takes an error model and options; ImuSimulator.corrupt has the clean call",
    # campaign scenarios are functions; the tables are what they return
    "atomnav.campaign.scenario.predicted_by": "takes a predictor function; the table is its output",
}
"""Public callables whose docstring mentions a table or an array but that take none from
the user, each with the reason it has no clean call (``table_or_array_callables`` finds
them by their docstrings)."""

NOT_YET_CATALOGUED: dict[str, str] = {
}
"""Table- or array-taking callables whose clean call found a defect of atomnav that needs
more than a local fix: the defect and the outcome of its reproducer. ``check_coverage``
accepts them like ``EXEMPT``; each leaves when its defect is mended and its clean call
lands."""


@dataclasses.dataclass(frozen=True)
class Stateful:
    """A stateful (or configuration) object ``obj`` built by ``setup``: ``first`` is the
    call the 4 threads make at once and the use before pickling (empty: a configuration
    object, pickled as built), ``then`` the continuation compared after pickling, and
    ``state`` an expression reading its state."""

    target: str
    setup: str
    first: str
    then: str
    state: str


STATEFUL: tuple[Stateful, ...] = (
    Stateful("atomnav.strapdown.Strapdown.run", "obj = an.strapdown.Strapdown(**init)", "obj.run(meas.iloc[:500])",
             "obj.run(meas.iloc[500:])", "obj.state()"),
    Stateful("atomnav.imu.ImuSimulator.corrupt", 'obj = an.imu.ImuSimulator("tactical", dt=0.01, kind="increments", seed=7)',
             "obj.corrupt(ideal.iloc[:500])", "obj.corrupt(ideal.iloc[500:])", "obj.corrupt(ideal.iloc[:3])"),
    Stateful("atomnav.noise.allan.AllanStream.update", "obj = an.noise.allan.AllanStream([1, 2, 4, 8], tau0=1.0)",
             "obj.update(omega[:1000])", "obj.update(omega[1000:])", 'obj.result("allan")'),
    Stateful("atomnav.noise.filters.KalmanStream.update", "obj = an.noise.filters.KalmanStream(arima)",
             "obj.update(omega[:1000])", "obj.update(omega[1000:])", "obj.update(omega[:3])"),
    Stateful("atomnav.filter.engine.KalmanFilter.predict",
             "obj = an.filter.engine.KalmanFilter(np.eye(3))\nphi, qd = np.eye(3) + 0.01 * np.ones((3, 3)), 1e-4 * np.eye(3)",
             "obj.predict(phi, qd, steps=2000)", "obj.predict(phi, qd, steps=10)", "(obj.x, obj.p, obj.epoch)"),
    Stateful("atomnav.filter.engine.KalmanFilter.update",
             "obj = an.filter.engine.KalmanFilter(np.eye(3))\nz, h, r = np.array([0.1, 0.2]), np.eye(3)[:2], 0.01 * np.eye(2)",
             "obj.update(z, h, r)", "obj.update(z, h, r)", "(obj.x, obj.p, obj.epoch)"),
    Stateful("atomnav.filter.aided.AidedIns.process", AIDED.replace("ins = ", "obj = "),
             "obj.process(time[:437], gyro[:437], accel[:437])", "obj.process(time[437:], gyro[437:], accel[437:])",
             "(obj.pending, obj.finish())"),
    Stateful("atomnav.trajectory.Trajectory", "obj = an.trajectory.sinusoidal(10.0, rate_hz=100.0)", "",
             "obj.ideal_imu('increments')", "obj.initial_state()"),
    Stateful("atomnav.imu.ImuErrors", 'obj = an.imu.ImuErrors.preset("tactical")', "", "obj.summary()", "obj.summary()"),
    Stateful("atomnav.gnss.ephemeris.Ephemerides", "obj = an.gnss.ephemeris.Ephemerides.nominal(0.0, 600.0)", "",
             "obj.state('G01', 100.0)", "obj.satellites"),
)


# ----------------------------------------------------------------------------------------
# mutations


UNIT_MISTAKES = {
    "accel": ((1 / G0, "g"),),
    "gyro": ((1 / DEG, "°/s (° per increment)"),),
    "time": ((1000.0, "ms"),),
    "imu_time": ((1000.0, "ms"),),
    "lat": ((1 / DEG, "°"),),
    "lon": ((1 / DEG, "°"),),
    "euler": ((1 / DEG, "°"),),
    "T": ((1000.0, "ms"),),
    "wavelength": ((1e9, "nm"),),
    "contrast": ((100.0, "%"),),
}
"""The unit mistakes of each quantity: (factor that turns the SI value into the mistaken
number, the unit the user meant)."""

COLUMN_ROLES = (
    (r"^(accel_[xyz]_mps2|dv_[xyz]_mps)$", "accel"),
    (r"^(gyro_[xyz]_rad_s|dtheta_[xyz]_rad)$", "gyro"),
    (r"^time_s$", "time"),
    (r"^lat_rad$", "lat"),
    (r"^lon_rad$", "lon"),
    (r"^(roll|pitch|yaw)_rad$", "euler"),
)
"""Unit-bearing table columns, by name (the units are in the column names)."""

GYRO_LIMIT = 35.0  # rad/s: beyond it an angular rate is in °/s (the documented rule)
STATIC_RATE = 1e-3  # rad/s: a record whose angular rates scatter less than this (σ per axis) is at rest
T_LIMIT = 10.0  # s: a CAI pulse separation beyond it is in ms (the documented rule)


def detectable(role: str, clean, scaled, dt: float | None, imu: bool = False) -> bool:
    """Can the documented plausibility rules see this unit mistake? ``clean`` and
    ``scaled`` are the values before and after (arrays); ``dt`` the sampling interval (s)
    of increments (None for rates and other quantities); ``imu``: the value is a column of
    an IMU table (whose time step has a plausible range; a trajectory's or an observation
    table's has none)."""
    c, s = np.abs(np.asarray(clean, float)), np.abs(np.asarray(scaled, float))
    if role == "gyro":  # beyond 35 rad/s, or at rest (a mean near 57.3 x Earth rate)
        rate = np.atleast_2d(np.asarray(clean, float) / (dt or 1.0))
        return bool(np.max(np.abs(rate), initial=0.0) / DEG > GYRO_LIMIT or rate.std(axis=0).max() < STATIC_RATE)
    if role == "lat":
        return bool((s > math.pi / 2).any())
    if role in ("lon", "euler"):
        return bool((s > 2 * math.pi).any())
    if role == "T":
        return bool((s > T_LIMIT).any())
    if role == "contrast":
        return bool((s > 1.0).any())
    if role == "time":
        return imu
    if role == "imu_time":  # the time stamps of an IMU record given apart from its table: a step above 1 s
        return bool(np.median(np.diff(s)) > 1.0)
    return True  # accel in g (|f| near 1), wavelength in nm: always visible


@dataclasses.dataclass(frozen=True)
class Mutation:
    """One mistake: ``kind`` (``harmless``: must be identical; ``changes``: must raise,
    warn or be identical; ``strings``: must raise; ``na``: must behave as ``nan_code``
    does; ``unit``: must warn or raise), a short ``name`` and the Python lines ``code``
    that make it (rebinding the variable, never changing a fixture in place)."""

    kind: str
    name: str
    code: str
    nan_code: str = ""
    judged: bool = True


def _renamed(col: str) -> str:
    """A realistic misspelling: the name without its unit suffix, or upper case."""
    head, _, tail = col.rpartition("_")
    return head if head and tail in ("s", "rad", "mps", "mps2", "m", "hz") else col.upper()


def table_mutations(var: str, df, time_origin: str = "", epoch: str = "") -> list[Mutation]:
    """The DataFrame (or Series) mistakes on variable ``var``; ``time_origin``: the
    argument of the call that fixes the origin of its time in seconds, if any; ``epoch``:
    the date the call documents its seconds to count from, if any (a naive datetime64 from
    it then converts exactly; a tz-aware one states a time scale the call may refuse)."""
    out = []
    if isinstance(df, pd.Series):
        df_cols = []
    else:
        df_cols = [str(c) for c in df.columns]
    for c in df_cols:
        out += [Mutation("changes", f"duplicated column {c!r}", f"{var} = pd.concat([{var}, {var}[[{c!r}]]], axis=1)"),
                Mutation("changes", f"renamed column {c!r} -> {_renamed(c)!r}",
                         f"{var} = {var}.rename(columns={{{c!r}: {_renamed(c)!r}}})"),
                Mutation("changes", f"missing column {c!r}", f"{var} = {var}.drop(columns=[{c!r}])")]
    if df_cols:
        extra = ", ".join(f"{k}={v!r}" for k, v in EXTRA_COLUMNS.items())
        out += [Mutation("harmless", "extra columns", f"{var} = {var}.assign({extra})"),
                Mutation("harmless", "reordered columns", f"{var} = {var}[{var}.columns[::-1]]")]
        if "time_s" in df_cols:
            # a time column that starts at 0 converts exactly whether it is read relative to the
            # first sample or to an epoch; one that does not is a mistake the call must see, and so
            # is a date where another argument (time_origin) places the record in time in seconds
            kind = "harmless" if float(df["time_s"].iloc[0]) == 0.0 else "changes"
            dated = "changes" if time_origin else kind
            date = str(pd.Timestamp(epoch or EPOCH))
            td = f"pd.to_timedelta({var}['time_s'], unit='s')"
            out += [Mutation("harmless" if epoch else dated, "time as naive datetime64",
                             f"{var} = {var}.assign(time_s=pd.Timestamp({date!r}) + {td})"),
                    Mutation("changes" if epoch else dated, "time as tz-aware datetime64",
                             f"{var} = {var}.assign(time_s=pd.Timestamp({date!r}, tz='UTC') + {td})"),
                    Mutation(kind, "time as timedelta64", f"{var} = {var}.assign(time_s={td})"),
                    Mutation("strings", "time as strings", f"{var} = {var}.assign(time_s={var}['time_s'].astype(str))")]
    numeric = [c for c in df_cols if pd.api.types.is_float_dtype(df[c])]
    row = min(5, len(df) - 1)  # the row given pd.NA
    if isinstance(df, pd.Series):
        out += [Mutation("harmless", "nullable Float64", f"{var} = {var}.astype('Float64')"),
                Mutation("na", f"nullable Float64 with pd.NA at row {row}",
                         f"{var} = {var}.astype('Float64')\n{var}.iloc[{row}] = pd.NA",
                         f"{var} = {var}.copy()\n{var}.iloc[{row}] = np.nan"),
                Mutation("strings", "numbers as strings", f"{var} = {var}.astype(str)")]
    elif numeric:
        col = next((c for c in numeric if c != "time_s"), numeric[0])
        out += [Mutation("harmless", "nullable Float64", f"{var} = {var}.astype({{c: 'Float64' for c in {numeric!r}}})"),
                Mutation("na", f"nullable Float64 with pd.NA in {col!r} row {row}",
                         f"{var} = {var}.astype({{c: 'Float64' for c in {numeric!r}}})\n"
                         f"{var}.loc[{var}.index[{row}], {col!r}] = pd.NA",
                         f"{var} = {var}.copy()\n{var}.loc[{var}.index[{row}], {col!r}] = np.nan"),
                Mutation("strings", f"numbers as strings in {col!r}", f"{var} = {var}.assign(**{{{col!r}: {var}[{col!r}].astype(str)}})"),
                Mutation("strings", "all numbers as strings", f"{var} = {var}.astype(str)")]
    return out


def array_mutations(var: str) -> list[Mutation]:
    """The mistakes on a float array argument ``var``: the same numbers as nested lists
    (harmless) and as strings."""
    return [Mutation("harmless", f"{var} as nested lists", f"{var} = {var}.tolist()"),
            Mutation("strings", f"{var} as strings", f"{var} = {var}.astype(str)")]


def _increment_dt(df) -> float | None:
    """The sampling interval (s) of an increments table (None for rates)."""
    if any(str(c).startswith("dtheta_") for c in df.columns) and "time_s" in df.columns and len(df) > 1:
        return float(np.median(np.diff(df["time_s"].to_numpy(float))))
    return None


def unit_mutations(clean: Clean, ns: dict) -> list[Mutation]:
    """The unit mistakes of a clean call: its tables' unit-bearing columns (the three axes
    of a triad together) and its ``units`` arguments."""
    out = []
    for var in clean.tables:
        df = ns[var]
        if isinstance(df, pd.Series):
            continue
        groups: dict[str, list[str]] = {}
        for c in map(str, df.columns):
            role = next((r for pattern, r in COLUMN_ROLES if re.match(pattern, c)), None)
            if role is not None:
                groups.setdefault(role, []).append(c)
        for role, cols in groups.items():
            for factor, unit in UNIT_MISTAKES[role]:
                clean_v = df[cols].to_numpy(float)
                scaled = ", ".join(f"{c}={var}[{c!r}] * {factor!r}" for c in cols)
                out.append(Mutation("unit", f"{role} columns {cols} in {unit} (x{factor:.6g})",
                                    f"{var} = {var}.assign({scaled})",
                                    judged=detectable(role, clean_v, clean_v * factor, _increment_dt(df),
                                                      imu="accel" in groups or "gyro" in groups)))
    for u in clean.units:
        v = np.asarray(eval(f"{u.var}{u.index}", {}, ns), float)  # noqa: S307 - the catalogue's own source
        for factor, unit in UNIT_MISTAKES[u.role]:
            if u.index:
                code = f"{u.var} = np.array({u.var}, dtype=float)\n{u.var}{u.index} = {u.var}{u.index} * {factor!r}"
            else:
                code = f"{u.var} = np.asarray({u.var}, dtype=float) * {factor!r}" if np.ndim(v) else \
                    f"{u.var} = {u.var} * {factor!r}"
            out.append(Mutation("unit", f"{u.var}{u.index} ({u.role}) in {unit} (x{factor:.6g})", code,
                                judged=detectable(u.role, v, v * factor, None)))
    return out


# ----------------------------------------------------------------------------------------
# calls and comparison


@dataclasses.dataclass
class Attempt:
    value: object = None
    error: BaseException | None = None
    unit_warnings: tuple[str, ...] = ()
    seconds: float = 0.0


def unit_warning_class():
    import atomnav

    return getattr(atomnav, "UnitWarning", None)


def attempt(thunk) -> Attempt:
    """Run ``thunk()``: its value or exception and the ``UnitWarning`` messages it gave."""
    unit = unit_warning_class()
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            value, error = thunk(), None
        except Exception as e:  # noqa: BLE001 - every exception is classified
            value, error = None, e
    msgs = tuple(str(w.message) for w in caught if unit is not None and issubclass(w.category, unit))
    return Attempt(value, error, msgs, time.perf_counter() - start)


def canon(x, depth: int = 0):
    """A comparable form of a result: frames, series and arrays as (labels, arrays), time
    columns as seconds (datetime64 from ``EPOCH``, timedelta64 from 0), objects by their
    public attributes."""
    if depth > 5:
        return ("deep",)
    if isinstance(x, pd.DataFrame):  # columns by name, in name order, without the extra columns drawn
        keep = sorted((str(c), i) for i, c in enumerate(x.columns) if str(c) not in EXTRA_COLUMNS)
        return ("frame", tuple(c for c, _ in keep), canon(np.asarray(x.index), depth + 1),
                tuple(canon(x.iloc[:, i], depth + 1) for _, i in keep))
    if isinstance(x, pd.Series):
        if isinstance(x.dtype, pd.DatetimeTZDtype):
            x = x.dt.tz_convert(None)
        return canon(x.to_numpy(), depth + 1)
    if isinstance(x, np.ndarray):
        if x.dtype.kind == "M":
            return (x - np.datetime64(EPOCH)) / np.timedelta64(1, "s")
        if x.dtype.kind == "m":
            return x / np.timedelta64(1, "s")
        return x
    if isinstance(x, (float, int, np.number, bool, np.bool_)):
        return np.asarray(x)
    if isinstance(x, dict):
        return ("dict", tuple((str(k), canon(v, depth + 1)) for k, v in x.items()))
    if isinstance(x, (list, tuple)):
        return ("seq", tuple(canon(v, depth + 1) for v in x))
    if x is None or isinstance(x, (str, bytes)):
        return x
    if dataclasses.is_dataclass(x):
        return ("dc", type(x).__name__, tuple((f.name, canon(getattr(x, f.name), depth + 1)) for f in dataclasses.fields(x)))
    props = [k for k, v in inspect.getmembers(type(x)) if not k.startswith("_")
             and (isinstance(v, property) or inspect.isgetsetdescriptor(v))]
    if props:  # an object is what its public properties read
        return ("obj", type(x).__name__, tuple((k, canon(_read(x, k), depth + 1)) for k in props))
    if hasattr(x, "__dict__"):
        return ("obj", type(x).__name__, tuple((k, canon(v, depth + 1)) for k, v in sorted(vars(x).items())
                                               if not k.startswith("_")))
    return ("opaque", type(x).__name__)


def _read(x, name: str):
    try:
        return getattr(x, name)
    except Exception as e:  # noqa: BLE001 - a property that fails reads as its exception
        return ("error", type(e).__name__)


def same(a, b) -> bool:
    """Bit-identical canonical forms (NaN equal to NaN)."""
    return _eq(canon(a), canon(b))


def _eq(a, b) -> bool:
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        if not (isinstance(a, np.ndarray) and isinstance(b, np.ndarray)) or a.shape != b.shape:
            return False
        if a.dtype.kind in "fc" and b.dtype.kind in "fc":
            return bool(np.array_equal(a, b, equal_nan=True))
        try:
            return bool(np.array_equal(a, b))
        except (TypeError, ValueError):
            return False
    if isinstance(a, tuple) and isinstance(b, tuple):
        return len(a) == len(b) and all(_eq(x, y) for x, y in zip(a, b))
    return type(a) is type(b) and a == b


FORWARDS = {"atomnav.cai.predictor.check_jacobian": "atomnav.cai.predictor.phase_jacobian",
            "atomnav.astro.star_attitudes": "atomnav.astro.results.Observations",
            "atomnav.filter.sources.aided_ins": "atomnav.filter.aided.AidedIns.run",
            "atomnav.gnss.tight.tight_ins": "atomnav.filter.aided.AidedIns.run",
            "atomnav.gnss.tight.GnssObservations": "atomnav.filter.sources.aided_ins",
            "atomnav.filter.outages.outage_analysis": "atomnav.filter.aided.AidedIns.run"}
"""Callables that pass ``*args``/``**kwargs`` on to another public callable, or whose clean
call builds its argument with one (``star_attitudes(Observations(epoch, camera, s_cf, g),
...)``: a mutated ``s_cf`` is rejected by ``Observations``) or runs what it returns
(``aided_ins(setup, sources).run(time, gyro, accel)``, ``tight_ins(eph, obs, ...).run(...)``,
``aided_ins(setup, [GnssObservations(eph, obs)]).run(...)``, ``outage_analysis``'s ``imu``
passed on as ``run(*imu)``), whose parameters are then the
names of the call's arguments."""


def error_names(target: str) -> set[str]:
    """The names an error of a call of ``target`` may give (fuzz's rule: its parameters and,
    for a method, its instance's constructor parameters; those of the callable it forwards
    its arguments to or builds its argument with, ``FORWARDS``)."""
    fuzz._init_targets()
    names = fuzz.TARGETS_BY_NAME[target].param_names()
    return names | (error_names(FORWARDS[target]) if target in FORWARDS else set())


def classify_error(e: BaseException, names: set[str]) -> str:
    """``raised`` for atomnav's answer to bad input naming an argument of the call; the bad
    classes otherwise."""
    import atomnav

    if isinstance(e, atomnav.InputError):
        p = getattr(e, "parameter", None)
        return "raised" if str(p).split(".")[0].split("[")[0] in names else "raised-bad-parameter"
    if isinstance(e, TypeError):
        msg = str(e)
        return "raised" if any(re.search(rf"\b{re.escape(n)}\b", msg) for n in names) else "raised-bad-parameter"
    if isinstance(e, RuntimeError) and "borrowed" in str(e):
        return "thread-borrow-error"
    return "foreign-exception"


def _describe(a: Attempt) -> str:
    if a.error is not None:
        e = a.error
        return f"{type(e).__name__}(parameter={getattr(e, 'parameter', None)!r}, index={getattr(e, 'index', None)!r}): {e}"
    return "returned a result"


def _only_pass_through_lost(m: Mutation, got, clean) -> bool:
    """A renamed or missing column ``c`` whose only effect is that the result table lacks
    ``c``: an optional column the call carries through as given (e.g. ``time_s`` of
    ``imu.corrupt``) and, under another name, ignores like any extra column (documented).
    Nothing the call computes changed, so this is no wrong answer."""
    hit = re.match(r"(renamed|missing) column '([^']+)'", m.name)
    if hit is None or not isinstance(clean, pd.DataFrame) or not isinstance(got, pd.DataFrame):
        return False
    col = hit.group(2)
    return col in clean.columns and col not in got.columns and same(got, clean.drop(columns=[col]))


def judge(m: Mutation, got: Attempt, clean: Attempt, nan_ref: Attempt | None, names: set[str]) -> tuple[str, str]:
    """(outcome class, message) of a mutated call against the clean call."""
    if m.kind == "na" and nan_ref is not None:
        if (got.error is None) != (nan_ref.error is None):
            return "na-not-nan", f"pd.NA: {_describe(got)}; NaN: {_describe(nan_ref)}"
        if got.error is not None:
            cls = classify_error(got.error, names)
            e, r = got.error, nan_ref.error
            if cls == "raised" and (type(e) is not type(r) or getattr(e, "parameter", None) != getattr(r, "parameter", None)
                                    or getattr(e, "index", None) != getattr(r, "index", None)):
                return "na-not-nan", f"pd.NA: {_describe(got)}; NaN: {_describe(nan_ref)}"
            return cls, _describe(got)
        return ("identical", "") if same(got.value, nan_ref.value) else (
            "na-not-nan", "pd.NA gives a different result than NaN")
    if got.unit_warnings and m.kind != "harmless":
        return "warned", got.unit_warnings[0]
    if got.error is not None:
        cls = classify_error(got.error, names)
        if cls == "raised" and m.kind == "harmless":
            return "harmless-rejected", _describe(got)
        return cls, _describe(got)
    if same(got.value, clean.value):
        return ("strings-accepted", "numbers given as strings were read as numbers") if m.kind == "strings" else (
            "identical", "")
    if _only_pass_through_lost(m, got.value, clean.value):
        return "identical", "an optional column the call only carries through was renamed or dropped, and so ignored"
    if m.kind == "unit":
        return "unit-not-warned", "the result changed with no UnitWarning and no error"
    if m.kind == "strings":
        return "strings-accepted", "numbers given as strings were taken (the result differs)"
    return "silent-different", "the result differs from the clean call's, with no warning and no error"


def fresh_namespace() -> dict:
    """Copies of the fixtures (tables and arrays deep-copied; a case never sees another's)."""
    out = {}
    for k, v in fixtures().items():
        out[k] = v.copy(deep=True) if isinstance(v, (pd.DataFrame, pd.Series)) else (
            v.copy() if isinstance(v, np.ndarray) else v)
    out.update(copy=copy, pickle=pickle, threading=threading)
    return out


# ----------------------------------------------------------------------------------------
# a campaign


@dataclasses.dataclass
class Campaign:
    """Outcome counts per class and per (callable, class), the first reproducers of each
    bad pair, and the unit mistakes not judged."""

    calls: int = 0
    seconds: float = 0.0
    counts: Counter = dataclasses.field(default_factory=Counter)
    pairs: Counter = dataclasses.field(default_factory=Counter)
    kept: list = dataclasses.field(default_factory=list)  # fuzz.Record, REPRO_KEEP per bad pair
    not_judged: list = dataclasses.field(default_factory=list)  # (target, mutation name)
    covered: set = dataclasses.field(default_factory=set)
    cases: list = dataclasses.field(default_factory=list)  # (target, outcome, message) of every call

    def add(self, target: str, outcome: str, message: str, seconds: float, repro: str) -> None:
        self.cases.append((target, outcome, message))
        self.calls += 1
        self.counts[outcome] += 1
        self.pairs[(target, outcome)] += 1
        if outcome in BAD and self.pairs[(target, outcome)] <= REPRO_KEEP:
            self.kept.append(fuzz.Record(target, outcome, message, seconds, repro))

    @property
    def n_bad(self) -> int:
        return sum(n for (_, cls), n in self.pairs.items() if cls in BAD)

    def first_failures(self) -> dict:
        out: dict = {}
        for r in self.kept:
            out.setdefault((r.target, r.outcome), (r, self.pairs[(r.target, r.outcome)]))
        return out

    def report(self) -> str:
        lines = ["# atomnav realistic-mistakes campaign", "",
                 f"{self.calls} mutated calls over {len(self.covered)} public callables in {self.seconds:.0f} s; "
                 f"{len(self.not_judged)} unit mistakes not judged (no documented rule can see them).", "",
                 "## Outcomes", "", "| class | calls | bad |", "|---|---:|---|"]
        for cls, n in sorted(self.counts.items(), key=lambda kv: -kv[1]):
            lines.append(f"| {cls} | {n} | {'yes' if cls in BAD else ''} |")
        fails = self.first_failures()
        lines += ["", f"## Failing callables ({len({k[0] for k in fails})}; {len(fails)} (callable, class) pairs)", ""]
        for (target, cls), (rec, n) in sorted(fails.items()):
            lines += [f"### `{target}` — {cls} ({n}×)", "", fuzz._md(rec.message), "", "```python", rec.call, "```", ""]
        lines += ["## Unit mistakes not judged", ""]
        lines += [f"- `{t}`: {name}" for t, name in self.not_judged] or ["none"]
        missing = sorted(table_or_array_callables() - self.covered - set(EXEMPT) - set(NOT_YET_CATALOGUED))
        lines += ["", f"## Table- or array-taking callables without a clean call ({len(missing)})", "",
                  ", ".join(f"`{n}`" for n in missing) or "none", "",
                  f"## Exempt ({len(EXEMPT)})", ""] + [f"- `{n}`: {why}" for n, why in sorted(EXEMPT.items())] + [
                  "", f"## Not yet catalogued: a defect to mend first ({len(NOT_YET_CATALOGUED)})", ""] + [
                  f"- `{n}`: {why}" for n, why in sorted(NOT_YET_CATALOGUED.items())] + [""]
        return "\n".join(lines)


def _repro(*blocks: str) -> str:
    return "\n".join(b for b in blocks if b)


def run_clean(c: Clean, camp: Campaign) -> None:
    """The clean call, then each of its mutations."""
    names = error_names(c.target)
    camp.covered.add(c.target)

    def call(code: str) -> Attempt:
        ns = fresh_namespace()
        exec(_repro(c.setup, code), ns)  # noqa: S102 - the catalogue's own source text
        return attempt(lambda: eval(c.call, ns))  # noqa: S307

    clean = call("")
    if clean.error is not None or clean.unit_warnings:
        camp.add(c.target, "clean-failed", _describe(clean) if clean.error else clean.unit_warnings[0], clean.seconds,
                 _repro(c.setup, c.call))
        return
    base = fixtures()
    ns = dict(base)
    exec(c.setup, ns)  # noqa: S102
    arrays = [k for k, v in ns.items() if isinstance(v, np.ndarray) and v.size and v.dtype.kind == "f"
              and not (k in base and v is base[k]) and re.search(rf"\b{k}\b", c.call)]
    mutations = ([m for v in c.tables for m in table_mutations(v, ns[v], c.time_origin, c.epoch)]
                 + [m for v in arrays for m in array_mutations(v)] + unit_mutations(c, ns))
    for m in mutations:
        if not m.judged:
            camp.not_judged.append((c.target, m.name))
            continue
        got = call(m.code)
        nan_ref = call(m.nan_code) if m.kind == "na" else None
        cls, msg = judge(m, got, clean, nan_ref, names)
        camp.add(c.target, cls, f"{m.name}: {msg}", got.seconds, _repro(c.setup, f"# mistake: {m.name}", m.code, c.call))


def _outcome_key(a: Attempt) -> str:
    return "ok" if a.error is None else type(a.error).__name__


def run_threads(s: Stateful, camp: Campaign, rounds: int) -> None:
    """``first`` from 4 threads on one object, against the same calls one after the other on
    a fresh object: the same outcomes and the same final state, never pyo3's borrow error."""
    import atomnav

    names = error_names(s.target)
    concurrent = getattr(atomnav, "ConcurrentUseError", None)
    repro = _repro(s.setup, f"barrier = threading.Barrier({THREADS})",
                   f"def go():\n    barrier.wait()\n    {s.first}",
                   f"threads = [threading.Thread(target=go) for _ in range({THREADS})]",
                   "[t.start() for t in threads]; [t.join() for t in threads]", s.state)
    for _ in range(rounds):
        ns = fresh_namespace()
        exec(s.setup, ns)  # noqa: S102
        barrier = threading.Barrier(THREADS)
        got: list = [None] * THREADS

        def go(i, ns=ns, barrier=barrier, got=got):
            barrier.wait()
            got[i] = attempt(lambda: eval(s.first, ns))  # noqa: S307

        threads = [threading.Thread(target=go, args=(i,)) for i in range(THREADS)]
        start = time.perf_counter()
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        seconds = time.perf_counter() - start
        made = [a for a in got if not (concurrent is not None and isinstance(a.error, concurrent))]
        bad = [classify_error(a.error, names) for a in made if a.error is not None]
        bad = [b for b in bad if b != "raised"]
        if bad:
            first = next(a for a in made if a.error is not None and classify_error(a.error, names) == bad[0])
            camp.add(s.target, bad[0], f"{THREADS} threads: {_describe(first)}", seconds, repro)
            continue
        ref = fresh_namespace()
        exec(s.setup, ref)  # noqa: S102
        seq = [attempt(lambda: eval(s.first, ref)) for _ in made]  # noqa: S307
        if sorted(map(_outcome_key, made)) != sorted(map(_outcome_key, seq)):
            camp.add(s.target, "silent-different", f"{THREADS} threads gave {sorted(map(_outcome_key, made))}, "
                     f"the same calls in sequence {sorted(map(_outcome_key, seq))}", seconds, repro)
            continue
        end, end_ref = attempt(lambda: eval(s.state, ns)), attempt(lambda: eval(s.state, ref))  # noqa: S307
        if end.error is not None or end_ref.error is not None or not same(end.value, end_ref.value):
            camp.add(s.target, "silent-different", f"the state after {THREADS} threads differs from the state after "
                     f"the same calls in sequence ({_describe(end)})", seconds, repro)
        else:
            camp.add(s.target, "identical" if not any(a.error for a in made) else "raised", "", seconds, repro)


def run_pickle(s: Stateful, camp: Campaign) -> None:
    """After ``first``, a ``pickle`` and a ``deepcopy`` copy continue (``then``, ``state``)
    bit for bit like the original."""
    copiers = (("pickle.loads(pickle.dumps(obj))", lambda o: pickle.loads(pickle.dumps(o))),
               ("copy.deepcopy(obj)", copy.deepcopy))
    ns = fresh_namespace()
    exec(_repro(s.setup, s.first), ns)  # noqa: S102
    copies = []
    for how, copier in copiers:
        repro = _repro(s.setup, s.first, f"dup = {how}", s.then, s.state, f"obj = dup  # continue the copy",
                       s.then, s.state)
        start = time.perf_counter()
        try:
            copies.append((how, copier(ns["obj"]), repro))
        except Exception as e:  # noqa: BLE001 - a copy that fails is the finding
            camp.add(s.target, "pickle-failed", f"{how}: {type(e).__name__}: {e}", time.perf_counter() - start, repro)
    if not copies:
        return
    original = [attempt(lambda: eval(s.then, ns)), attempt(lambda: eval(s.state, ns))]  # noqa: S307
    for how, dup, repro in copies:
        other = dict(ns, obj=dup)
        got = [attempt(lambda: eval(s.then, other)), attempt(lambda: eval(s.state, other))]  # noqa: S307
        ok = all(_outcome_key(a) == _outcome_key(b) and same(a.value, b.value) for a, b in zip(got, original))
        camp.add(s.target, "identical" if ok else "pickle-diverged",
                 "" if ok else f"{how} continues unlike the original ({_describe(got[0])})", sum(a.seconds for a in got), repro)


def campaign(thread_rounds: int = THREAD_ROUNDS, only: list[str] | None = None) -> Campaign:
    """Every clean call with its mistakes, every stateful object from threads and through
    pickling. ``only``: dotted-name prefixes of the callables to run."""
    start = time.monotonic()
    camp = Campaign()

    def chosen(target: str) -> bool:
        return not only or any(target.startswith(o) for o in only)

    for c in CATALOGUE:
        if chosen(c.target):
            run_clean(c, camp)
    for s in STATEFUL:
        if chosen(s.target):
            camp.covered.add(s.target)
            if s.first:
                run_threads(s, camp, thread_rounds)
            run_pickle(s, camp)
    if not only:
        check_coverage(camp)
    camp.seconds = time.monotonic() - start
    return camp


def check_coverage(camp: Campaign) -> None:
    """A public table- or array-taking callable without a clean call, and a stale ``EXEMPT``
    entry, are each a ``no-clean-call`` outcome."""
    found, excused = table_or_array_callables(), {**EXEMPT, **NOT_YET_CATALOGUED}
    for name in sorted(found - camp.covered - set(excused)):
        camp.add(name, "no-clean-call", "takes a table or an array (its docstring says so) and has no clean call in "
                 "CATALOGUE nor an entry in EXEMPT or NOT_YET_CATALOGUED", 0.0, "")
    for name in sorted(set(excused) - found):
        camp.add(name, "no-clean-call", "is in EXEMPT or NOT_YET_CATALOGUED but is no longer a public table- or "
                 "array-taking callable", 0.0, "")
    for name in sorted(set(excused) & camp.covered):
        camp.add(name, "no-clean-call", "is in EXEMPT or NOT_YET_CATALOGUED but has a clean call", 0.0, "")


def table_or_array_callables() -> set[str]:
    """The public callables of ``atomnav`` (not the ``_core`` binding) whose signature or
    docstring says they take a DataFrame or an array, by introspection."""
    fuzz._init_targets()
    out = set()
    for t in fuzz.TARGETS:
        if t.module.startswith("atomnav._core") or t.kind == "property" or not t.params:
            continue
        obj = fuzz.resolve(t.module, t.qualname)
        if any(TAKES_TABLE_OR_ARRAY.search(text) for text in parameter_docs(obj)):
            out.add(t.name)
    return out


TAKES_TABLE_OR_ARRAY = re.compile(r"DataFrame|\bSeries\b|\((N|M)\b")
"""What a parameter's documented type or description says when it is a table or an array."""


def parameter_docs(obj) -> list[str]:
    """The documented type and description of each parameter of ``obj`` (its numpydoc
    ``Parameters``; a class's constructor parameters are in its own docstring), or the
    whole docstring where it has no such section."""
    doc = inspect.getdoc(obj) or ""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # numpydoc warns of sections it does not know
        params = NumpyDocString(doc)["Parameters"]
    if not params:
        return [" ".join(doc.split())]
    return [" ".join([p.type, *p.desc]) for p in params]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--thread-rounds", type=int, default=THREAD_ROUNDS)
    ap.add_argument("--only", action="append", default=None, metavar="PREFIX")
    ap.add_argument("--out", default=None, help="markdown report (default: stdout)")
    ap.add_argument("--cases", default=None, help="also write every call's callable, class and mistake (TSV)")
    a = ap.parse_args(argv)
    c = campaign(a.thread_rounds, a.only)
    if a.cases:
        with open(a.cases, "w") as f:
            f.writelines(f"{t}\t{cls}\t{fuzz._md(msg)}\n" for t, cls, msg in c.cases)
    text = c.report() + f"\nReproducers assume `{REPRO_HEADER}` (run from tests/).\n"
    if a.out:
        with open(a.out, "w") as f:
            f.write(text)
    else:
        print(text)
    print(f"{c.calls} calls, {c.n_bad} bad, {c.seconds:.0f} s", file=sys.stderr)
    return 1 if c.n_bad else 0


if __name__ == "__main__":
    sys.exit(main())
