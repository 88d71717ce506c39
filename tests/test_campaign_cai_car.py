"""The campaign scenario cai_car (the car profile of Tennstedt et al. 2023, §2.8) against its
covariance predictor: the Monte-Carlo RMS over seeds of each error norm must agree with the
linear true-error analysis."""

import numpy as np
import pandas as pd
import pytest
from scipy.stats import chi2

import atomnav as an
from atomnav.campaign.cai_car import _configuration, _core_scenario, _linear_model, _motion, _points, _systematic_error, cai_car
from atomnav.imu import ImuErrors

COLUMNS = ["pos_error_m", "vel_error_mps", "att_error_rad"]


def _mc_rms(runs: int, **params) -> tuple[pd.DataFrame, pd.DataFrame]:
    """RMS over seeds 0 … runs − 1 of each metric, and the prediction."""
    tables = [cai_car(seed=s, **params) for s in range(runs)]
    for t in tables[1:]:
        assert np.array_equal(t["time_s"], tables[0]["time_s"])
    rms = np.sqrt(np.mean([t[COLUMNS].to_numpy() ** 2 for t in tables], axis=0))
    pred = cai_car.predict(**params)
    assert list(pred.columns) == ["time_s", *COLUMNS] and np.array_equal(pred["time_s"], tables[0]["time_s"])
    return pd.DataFrame(rms, columns=COLUMNS).assign(time_s=pred["time_s"]), pred


def _ratios(runs: int, **params) -> pd.DataFrame:
    rms, pred = _mc_rms(runs, **params)
    ratio = rms[COLUMNS] / pred[COLUMNS]
    ratio.insert(0, "time_s", pred["time_s"])
    print(params, f"{runs} seeds: MC RMS / prediction\n{ratio.round(3).to_string()}")
    return ratio


def _rms_band(runs: int, p: float = 0.99) -> tuple[float, float]:
    """Two-sided p band of MC RMS / true RMS over ``runs`` seeds when each run's |e|² is
    (tr Σ)·χ²₁, the widest spread a Gaussian error vector's squared norm can have (one axis
    dominating; three equal axes would give χ²₃/3): N·RMS²/tr Σ ~ χ²_N."""
    lo, hi = chi2.ppf([(1 - p) / 2, (1 + p) / 2], runs)
    return float(np.sqrt(lo / runs)), float(np.sqrt(hi / runs))


def test_ci_point_matches_the_true_error_prediction():
    # 30 seeds: the 99 % band of the RMS ratio is √(χ²₃₀(0.005)/30) … √(χ²₃₀(0.995)/30)
    # = √(13.79/30) … √(53.67/30) = 0.678 … 1.338 (statistics alone; the full check with
    # 60 seeds and ±30 % is the slow sweep below)
    lo, hi = _rms_band(30)
    assert abs(lo - 0.678) < 1e-3 and abs(hi - 1.338) < 1e-3
    ratio = _ratios(30)
    final = ratio[COLUMNS].iloc[-1]
    assert ((final > lo) & (final < hi)).all(), final


# Sweep in Earth gravity, navigation grade: T ∈ {10, 20, 25} ms × shot period (2T, 4T, 10T)
# within the linear regime, and the row T = 40 ms beyond it (strict xfail). The other grades
# the linear model carries (precise, medium, coarse) have in-shot phase noise beyond the
# CAI's ±π/2 capture range even at T = 10 ms (precise: σ 1.3 rad; Monte-Carlo RMS 1.7–1.9 ×
# the prediction). 60 seeds: the RMS of 60 runs is known to √(1/(2·60)) = 9 % (1σ) even when
# one axis dominates. Measured MC RMS / prediction at 40 s (pos, vel, att) and the range over
# every filter epoch after 1 s:
#   T = 10 ms: 2T 0.91 0.91 0.93 (0.85–1.05), 4T 0.99 0.99 0.98 (0.91–1.07), 10T 0.99 0.99 0.97 (0.90–1.08)
#   T = 20 ms: 2T 1.10 1.10 1.01 (0.90–1.12), 4T 1.00 1.00 1.03 (0.93–1.08), 10T 1.02 1.01 0.93 (0.82–1.11)
#   T = 25 ms: 2T 1.00 1.00 1.05 (0.93–1.11), 4T 1.03 1.03 1.05 (0.91–1.12), 10T 1.07 1.10 1.15 (0.91–1.16)
#   T = 40 ms: 2T 1.38 1.46 1.61 (1.09–1.63), 4T 1.34 1.39 1.49 (1.01–1.49), 10T 1.31 1.35 1.44 (0.87–1.55)
# Without the seed-independent error of the filter's phase prediction under the vibration
# (test_systematic_error_matches_a_run_without_noise) T = 20 ms, 10T read 2.0–2.9 at 10, 20,
# 30 s and 1.52 1.51 1.70 at 40 s, and T = 40 ms, 10T 1.52 1.60 1.72.
# At T = 40 ms the in-shot phase σ is 0.82 rad (0.98 rad with the turn-on biases; 11 % of the
# shot-channels beyond ±π/2): the excess is the readout's sine and fringe slips, which the
# linear prediction ignores (the predictor warns). The diagnosis is
# test_linear_regime_at_40_ms_is_predicted below.
_NONLINEAR = pytest.mark.xfail(strict=True, reason="T = 40 ms: phase σ 0.98 rad, beyond the linear analysis (readout sine, fringe slips); "
                                                   "MC RMS / prediction at 40 s 1.31–1.61")
SWEEP = [pytest.param(dict(T=T, shot_rate=0.0 if k is None else 1.0 / (k * T)), id=f"T{T}-period{k or 2}T",
                      marks=[pytest.mark.slow] + ([_NONLINEAR, pytest.mark.filterwarnings("ignore::RuntimeWarning")] if T == 0.04 else []))
         for T in (0.01, 0.02, 0.025, 0.04) for k in (None, 4, 10)]


@pytest.mark.parametrize("params", SWEEP)
def test_sweep_matches_the_true_error_prediction_within_30_percent(params):
    # every checkpoint, not only the end: a defect that comes and goes with time shows there
    ratio = _ratios(60, **params)[COLUMNS]
    assert (np.abs(ratio - 1) < 0.3).all().all(), ratio


@pytest.mark.slow
def test_linear_regime_at_40_ms_is_predicted(monkeypatch):
    """The excess at T = 40 ms is the readout's nonlinearity plus the vibration: with the
    navigation grade's white noise halved (in-shot phase σ 0.41 rad) and no vibration the
    prediction holds again (measured 1.01–1.05 ×), and the predictor does not warn."""
    import warnings

    from atomnav import imu

    quiet = ImuErrors.preset("navigation")
    quiet.accel.white *= 0.5
    quiet.gyro.white *= 0.5
    monkeypatch.setitem(imu._USER_PRESETS, "navigation_half_white", quiet)
    params = dict(T=0.04, imu="navigation_half_white", vibration=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        ratio = _ratios(60, **params)
    final = ratio[COLUMNS].iloc[-1]
    assert (np.abs(final - 1) < 0.3).all(), final


@pytest.mark.parametrize("period", [2, 4, 10])
def test_prediction_updates_at_the_filter_epochs(period):
    # the core applies shot j at the first filter epoch at or after its end: the Monte Carlo's
    # epochs are the 2T grid, every shot is processed, and its epoch is the predictor's
    key = _points(0.02, 1.0 / (period * 0.02), "navigation", 0.0, "earth", True, 1.0, 5.0)
    lin, core = _linear_model(key), _core_scenario(key)
    run = core.monte_carlo(0, [0])
    time = np.asarray(run["time"])
    assert np.allclose(time, np.arange(1, len(lin.measure)) * lin.step_s, rtol=0, atol=1e-9)
    assert np.isfinite(np.asarray(run["phase_error"])).all()
    applied = np.searchsorted(time, np.asarray(core.shots) + 2 * 0.02 - 1e-9) + 1
    assert np.array_equal(applied, np.flatnonzero(lin.measure))


def test_systematic_error_matches_a_run_without_noise():
    """The seed-independent error (the filter's phase prediction under the vibration, one
    shot per 10T = 0.2 s aliasing the 15.1 Hz line to 0.1 Hz) against the peer that has
    nothing else: the Monte Carlo's own nonlinear simulation with an error-free IMU and
    σ_p = 1e-9 (R then differs by < 5 %). Measured misfit 11 % (position, velocity) and 8 %
    (attitude), rms over the epochs; without the vibration the error is < 10 % of this."""
    import dataclasses

    from atomnav.cai.campaign import _scenario
    from atomnav.imu import TriadErrors

    key = _points(0.02, 5.0, "navigation", 0.0, "earth", True, 1.0, 5.0)
    lin = _linear_model(key)
    quiet = dataclasses.replace(lin.config, imu=ImuErrors(TriadErrors(), TriadErrors()), sensor=dataclasses.replace(lin.config.sensor, sigma_p=1e-9))
    run = _scenario(_motion(key), quiet)[0].monte_carlo(0, [0])
    exact = np.asarray(run["hybrid"])[0]
    linear = _systematic_error(key, lin)[1:]
    assert np.allclose(np.asarray(run["time"]), np.arange(1, len(linear) + 1) * lin.step_s)
    for block in (slice(0, 3), slice(3, 6), slice(6, 9)):
        misfit = np.sqrt(((exact[:, block] - linear[:, block]) ** 2).sum(axis=1).mean() / (exact[:, block] ** 2).sum(axis=1).mean())
        assert misfit < 0.2, (block, misfit)
    # the vibration makes it: without, the largest position and velocity errors are < 10 %
    # (measured 3.6 %)
    still = _linear_model(_points(0.02, 5.0, "navigation", 0.0, "earth", False, 1.0, 5.0))
    calm = _systematic_error(_points(0.02, 5.0, "navigation", 0.0, "earth", False, 1.0, 5.0), still)
    assert np.abs(calm[:, :6]).max() < 0.1 * np.abs(linear[:, :6]).max()


def test_predictor_warns_beyond_the_linear_regime():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        cai_car.predict(T=0.025)
    with pytest.warns(RuntimeWarning, match="beyond ±π/2"):
        cai_car.predict(T=0.04)


def test_run_is_bit_identical_whatever_the_cache_holds():
    first = cai_car(seed=7, T=0.02)
    cai_car(seed=8, T=0.025)  # another point in between
    _core_scenario.cache_clear()
    again = cai_car(seed=7, T=0.02)
    pd.testing.assert_frame_equal(first, again, check_exact=True)
    assert not first.equals(cai_car(seed=8, T=0.02))
    assert list(first.columns) == ["time_s", *COLUMNS] and (first[COLUMNS] >= 0).all().all()
    # checkpoints every 5 s: the filter epochs (every 2T = 40 ms) nearest to them, and the end
    assert np.allclose(first["time_s"], [5, 10, 15, 20, 25, 30, 35, 40])


def test_filter_follows_the_imu_grade():
    grade = ImuErrors.preset("precise")
    cfg = _configuration(_points(0.01, 0.0, "precise", 0.0, "earth", True, 1.0, 5.0))
    s = cfg.setup
    assert (s.accel_psd, s.gyro_psd) == (grade.accel.white**2, grade.gyro.white**2)
    assert (s.accel_bias_psd, s.gyro_bias_psd) == (grade.accel.bias_rw**2, grade.gyro.bias_rw**2)
    assert s.sigma0[3:] == (grade.accel.bias_sigma, grade.gyro.bias_sigma)
    assert cfg.sensor.inflation == (grade.accel.white**2, grade.gyro.white**2)
    assert s.predict_every == 4 and cfg.sensor.shot_period == 0.02


def _flicker_start_variance(fl) -> float:
    """Variance at the start of the simulated flicker, from the construction :mod:`atomnav.imu`
    documents: Gauss–Markov poles 2 per decade over [f_lo, f_hi] and 3 past each edge, all
    of one σ, started stationary. Poles log-spaced by r sum to the one-sided PSD
    Σ 4σ²τᵢ/(1 + (2πfτᵢ)²) ≈ (4σ²/ln r) ∫ τ/(1 + (2πfτ)²) d ln τ = σ²/(f ln r), which is
    B²/(πf) for σ² = B² ln r/π, r = √10."""
    poles = round(2 * np.log10(fl.f_hi / fl.f_lo)) + 1 + 2 * 3
    return poles * fl.b**2 * np.log(np.sqrt(10.0)) / np.pi


@pytest.mark.parametrize("grade", ["tactical", "mems"])
def test_grades_beyond_the_linear_model_run_with_the_filter_mapped_from_the_grade(grade):
    """The filter's bias model (random constant + random walk) for a grade with terms it
    lacks, computed here from the preset's numbers: initial variance = turn-on σ² + largest
    fixed bias² + flicker variance at the start; random-walk PSD = K² + the random walk
    whose Allan variance K²τ/3 meets the flicker floor (2 ln 2/π) B² at τ = 40 s (IEEE Std
    952-1997, Annex C)."""
    errors = ImuErrors.preset(grade)
    s = _configuration(_points(0.025, 0.0, grade, 0.0, "earth", True, 1.0, 5.0)).setup
    for triad, sigma0, psd in ((errors.accel, s.sigma0[3], s.accel_bias_psd), (errors.gyro, s.sigma0[4], s.gyro_bias_psd)):
        var0, rw = triad.bias_sigma**2 + max(abs(b) for b in triad.bias) ** 2, triad.bias_rw**2
        if triad.flicker is not None:
            var0 += _flicker_start_variance(triad.flicker)
            rw += 3 * (2 * np.log(2) / np.pi) * triad.flicker.b**2 / 40.0
        assert np.isclose(sigma0, np.sqrt(var0), rtol=1e-12, atol=0) and np.isclose(psd, rw, rtol=1e-12, atol=0), (sigma0, psd)
    assert (s.accel_psd, s.gyro_psd) == (errors.accel.white**2, errors.gyro.white**2)
    # the preset's terms as the mapping must see them (a silent change of a preset shows here)
    assert (errors.accel.flicker is not None) == (grade == "tactical") and (np.any(errors.accel.bias)) == (grade == "mems")
    # deterministic: the same seed gives the same table, another seed another
    first = cai_car(seed=3, imu=grade)
    pd.testing.assert_frame_equal(first, cai_car(seed=3, imu=grade), check_exact=True)
    assert not first.equals(cai_car(seed=4, imu=grade))
    assert list(first.columns) == ["time_s", *COLUMNS] and np.isfinite(first[COLUMNS].to_numpy()).all()


def test_gauss_markov_term_maps_to_initial_sigma_and_driving_psd(monkeypatch):
    from atomnav import imu
    from atomnav.imu import GaussMarkov

    grade = ImuErrors.preset("navigation")
    grade.accel.gauss_markov = GaussMarkov(3e-5, 20.0)
    monkeypatch.setitem(imu._USER_PRESETS, "navigation_gm", grade)
    s = _configuration(_points(0.025, 0.0, "navigation_gm", 0.0, "earth", True, 1.0, 5.0)).setup
    assert np.isclose(s.sigma0[3], np.hypot(2e-5, 3e-5), rtol=1e-12, atol=0)
    assert np.isclose(s.accel_bias_psd, 3e-5**2 + 2 * 3e-5**2 / 20.0, rtol=1e-12, atol=0)
    assert (s.sigma0[4], s.gyro_bias_psd) == (grade.gyro.bias_sigma, grade.gyro.bias_rw**2)


def test_tactical_hybrid_stays_bounded_beside_the_free_ins():
    """At T = 25 ms the tactical grade's phase error is ≈ 100 rad (turn-on bias 1 mg,
    k T² = 1.0e4 rad/(m/s²)): the CAI's sine readout carries almost nothing, the filter's R
    (inflated by the in-shot white noise) keeps its gain small, and the hybrid follows the
    free INS of the same IMU. Measured over 8 seeds, RMS at 40 s hybrid / free: position
    14.12 / 14.10 m, velocity 0.664 / 0.663 m/s, attitude 5.5e-4 / 5.5e-4 rad (30 seeds,
    T = 5–25 ms: 1.00–1.02 ×). Only finiteness is asserted: nothing guarantees that a
    suboptimal filter whose readout slips fringes beats the free INS."""
    key = _points(0.025, 0.0, "tactical", 0.0, "earth", True, 1.0, 5.0)
    run = _core_scenario(key).monte_carlo(0, list(range(8)))
    assert abs(np.asarray(run["time"])[-1] - 40.0) < 1e-9
    hybrid, free = (np.asarray(run[k])[:, -1] for k in ("hybrid", "free"))
    rms = {k: [np.sqrt((np.linalg.norm(e[:, 3 * i:3 * i + 3], axis=1) ** 2).mean()) for i in range(3)] for k, e in (("hybrid", hybrid), ("free", free))}
    print("RMS at 40 s (pos m, vel m/s, att rad):", rms)
    assert np.isfinite(np.asarray(run["hybrid"])).all() and np.isfinite(np.asarray(run["free"])).all()


BAD = {
    "unknown grade": (dict(imu="strategic"), "imu"),
    "grade without gyro errors": (dict(imu="electrostatic_space"), "imu"),
    "shot rate above 1/(2T)": (dict(T=0.025, shot_rate=20.5), "shot_rate"),
    "negative shot rate": (dict(shot_rate=-1.0), "shot_rate"),
    "infinite shot rate": (dict(shot_rate=float("inf")), "shot_rate"),
    "shot rate below one per profile": (dict(shot_rate=1e-300), "shot_rate"),
    "shot period off the 2T steps": (dict(T=0.02, shot_rate=3.7), "shot_rate"),
    "T = 0": (dict(T=0.0), "T"),
    "T < 0": (dict(T=-0.01), "T"),
    "2T off the IMU samples": (dict(T=0.0123), "T"),
    "unknown gravity": (dict(gravity="moon"), "gravity"),
    "contrast > 1": (dict(contrast=1.5), "contrast"),
    "lever NaN": (dict(lever=float("nan")), "lever"),
    "checkpoint spacing 0": (dict(checkpoint_s=0.0), "checkpoint_s"),
}


@pytest.mark.parametrize("case", list(BAD), ids=list(BAD))
@pytest.mark.parametrize("call", ["run", "predict"])
def test_bad_input_names_the_parameter(case, call):
    params, name = BAD[case]
    fn = cai_car if call == "run" else cai_car.predict
    with pytest.raises(an.InputError) as e:
        fn(**params)
    assert e.value.parameter == name, str(e.value)


@pytest.mark.parametrize("imu", ["tactical", "mems"])
def test_predictor_refuses_a_grade_beyond_its_linear_model_and_points_to_the_monte_carlo(imu):
    # tactical: flicker; mems: fixed biases. The run takes them (test_grades_beyond_the_linear_model_run)
    with pytest.raises(an.InputError, match="monte_carlo") as e:
        cai_car.predict(imu=imu)
    assert e.value.parameter == "imu", str(e.value)


def test_grade_with_a_flicker_band_beyond_nyquist_names_imu(monkeypatch):
    from atomnav import imu
    from atomnav.imu import Flicker

    fast = ImuErrors.preset("navigation")
    fast.accel.flicker = Flicker(1e-5, 1e-3, 150.0)  # valid at 400 Hz and above, not at the car's 200 Hz
    monkeypatch.setitem(imu._USER_PRESETS, "navigation_fast_flicker", fast)
    for fn in (cai_car, cai_car.predict):
        with pytest.raises(an.InputError, match="200 Hz") as e:
            fn(imu="navigation_fast_flicker")
        assert e.value.parameter == "imu", str(e.value)


@pytest.mark.parametrize("params", [dict(vibration="yes"), dict(imu=3), dict(gravity=None)], ids=["vibration", "imu", "gravity"])
def test_wrong_types_are_type_errors(params):
    (name,) = params
    with pytest.raises(TypeError, match=name):
        cai_car(**params)
    with pytest.raises(TypeError, match=name):
        cai_car.predict(**params)


def test_bad_seed_names_seed():
    with pytest.raises(an.InputError) as e:
        cai_car(seed=-1)
    assert e.value.parameter == "seed"
