"""The built-in campaign scenarios strapdown_free and gnss_tight against their covariance
predictors (Monte-Carlo RMS over seeds inside the χ² band of an RMS over N runs), the free
INS against the Schuler closed forms, determinism, and bad input. The default variants are
reduced; the full sizes are `slow`.

The band. In one run the squared error norm of a block is |e|² = Σ_i λ_i χ²₁,i over the
eigenvalues λ_i of the block's covariance P (plus a deterministic part where the grade has a
fixed bias), so E|e|² = tr P, and the mean square over N independent seeds, MS, has
N·MS/tr P = Σ_i (λ_i/tr P)·χ²_N,i: a weighted sum of χ²_N variables with weights summing to
one. Its spread is largest when one eigenvalue carries the whole trace, where it is χ²_N
itself (a noncentral part only narrows it), so RMS/predicted = √(MS/tr P) lies in
√(χ²_N quantiles / N) with at least the quantiles' probability. The checkpoints and columns
of one run are correlated, so the α = 1 % of a test is split over all its checks
(Bonferroni), which is conservative.
"""

import hashlib
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest
from scipy.stats import chi2

import atomnav as an
from atomnav.campaign.gnss_tight import gnss_tight
from atomnav.campaign.scenario import check_params
from atomnav.campaign.strapdown_free import strapdown_free
from atomnav.imu import Flicker, GaussMarkov, ImuErrors, TriadErrors

ALPHA = 0.01
OMEGA_IE = 7.292115e-5  # Earth rate, rad/s


def _mc_ratio(scenario, runs: int, **params) -> pd.DataFrame:
    """RMS over seeds 0 … runs−1 divided by the prediction, per checkpoint and column."""
    pred = scenario.predict(**params)
    tables = [scenario(seed=s, **params) for s in range(runs)]
    for t in tables:
        assert list(t.columns) == list(pred.columns)
        np.testing.assert_array_equal(t["time_s"].to_numpy(), pred["time_s"].to_numpy())
    ms = sum(t.iloc[:, 1:].to_numpy() ** 2 for t in tables) / runs
    return pd.DataFrame(np.sqrt(ms) / pred.iloc[:, 1:].to_numpy(), columns=pred.columns[1:], index=pred["time_s"])


def _assert_in_band(ratio: pd.DataFrame, runs: int) -> None:
    a = ALPHA / ratio.size
    lo, hi = np.sqrt(chi2.ppf([a / 2, 1 - a / 2], runs) / runs)
    flat = ratio.stack()
    bad = flat[(flat < lo) | (flat > hi)]
    assert bad.empty, f"RMS/predicted outside [{lo:.3f}, {hi:.3f}] for N = {runs}:\n{bad}\n{ratio.round(3)}"


@pytest.fixture
def presets(monkeypatch):
    """User grades for one test (removed after it): fixed biases for the closed forms, and a
    grade of Gauss–Markov and flicker terms only."""
    grades = {
        "accel_bias_north": ImuErrors(accel=TriadErrors(bias=(1e-3, 0.0, 0.0))),
        "gyro_bias_east": ImuErrors(gyro=TriadErrors(bias=(0.0, 1e-6, 0.0))),
        "correlated": ImuErrors(accel=TriadErrors(gauss_markov=GaussMarkov(5e-4, 100.0), white=2e-4),
                                gyro=TriadErrors(flicker=Flicker(2e-6, 1e-4, 0.1))),
    }
    for name, errors in grades.items():
        monkeypatch.setitem(an.imu._USER_PRESETS, name, errors)
    return grades


# ---- strapdown_free: Monte Carlo against the linear covariance analysis ---------------------

@pytest.mark.parametrize("params, runs", [
    (dict(imu="tactical", rate_hz=10.0, duration=300.0, checkpoint_s=30.0), 100),  # turn-on bias, white noise, flicker
    (dict(imu="mems", rate_hz=10.0), 100),                                          # fixed bias, white noise, bias random walk
    (dict(imu="medium", rate_hz=10.0, duration=300.0, checkpoint_s=30.0, latitude_deg=-30.0, bias_scale=0.3, noise_scale=3.0), 200),
    (dict(imu="tactical", motion="sinusoidal", duration=90.0, checkpoint_s=30.0, rate_hz=50.0), 100),
])
def test_strapdown_free_rms_matches_its_covariance(params, runs):
    _assert_in_band(_mc_ratio(strapdown_free, runs, **params), runs)


def test_strapdown_free_gauss_markov_and_flicker_terms(presets):
    """A grade of a Gauss–Markov accelerometer term and flicker gyros only: the augmented
    pole systems of the predictor alone."""
    _assert_in_band(_mc_ratio(strapdown_free, 100, imu="correlated", rate_hz=10.0, duration=300.0, checkpoint_s=30.0), 100)


@pytest.mark.slow
@pytest.mark.parametrize("params", [
    dict(imu="tactical"),
    dict(imu="tactical", motion="sinusoidal"),
    dict(imu="navigation", motion="sinusoidal"),
    dict(imu="coarse", motion="sinusoidal", checkpoint_s=30.0),
])
def test_strapdown_free_rms_matches_its_covariance_full(params):
    _assert_in_band(_mc_ratio(strapdown_free, 400, **params), 400)


# ---- strapdown_free: closed forms ------------------------------------------------------------

@pytest.mark.parametrize("grade", ["accel_bias_north", "gyro_bias_east"])
def test_strapdown_free_at_rest_follows_the_schuler_closed_forms(presets, grade):
    """Level, north-pointing INS at rest, one fixed bias (Titterton & Weston 2004, §12.3):
    a north accelerometer bias b gives a north error b(1 − cos ω_s t)/ω_s² (≈ ½ b t²), an
    east gyro bias ε one of g ε (t − sin(ω_s t)/ω_s)/ω_s² (≈ g ε t³/6), ω_s² = g/(R_M + h).
    The closed forms leave out the Earth-rate coupling (Foucault rotation of the error,
    heading coupling through the north Earth rate), whose relative effect on the norm is of
    order (Ω_ie t)² (1.9e-3 at 600 s): that is the tolerance. Both the predictor and a run
    (deterministic: the grade has no random term) are checked; bias_scale scales b or ε."""
    lat, h, scale = np.radians(55.75), 200.0, 0.5
    params = dict(imu=grade, rate_hz=100.0, checkpoint_s=30.0, latitude_deg=55.75, bias_scale=scale)
    traj = an.trajectory.stationary(1.0, 10.0, origin=(lat, an.trajectory.MOSCOW[1], h))
    g = np.linalg.norm(traj.ideal_imu("rates")[["accel_x_mps2", "accel_y_mps2", "accel_z_mps2"]].to_numpy()[0])
    ws = np.sqrt(g / (an.earth.radii(lat)[0] + h))
    pred, run = strapdown_free.predict(**params), strapdown_free(seed=3, **params)
    t = pred["time_s"].to_numpy()
    if grade == "accel_bias_north":
        want = scale * 1e-3 * (1 - np.cos(ws * t)) / ws**2
    else:
        want = g * scale * 1e-6 * (t - np.sin(ws * t) / ws) / ws**2
    for table in (pred, run):
        for col in ("hpos_error_m", "pos_error_m"):
            rel = table[col].to_numpy() / want - 1
            assert np.all(np.abs(rel) <= (OMEGA_IE * t) ** 2), (col, rel)


def test_strapdown_free_bias_scale_is_a_continuous_grade():
    """The predicted error grows with bias_scale (what a requirement bisection needs), and
    with no bias and no noise there is none."""
    p = [strapdown_free.predict(imu="tactical", rate_hz=10.0, bias_scale=s)["hpos_error_m"].iloc[-1] for s in (0.25, 0.5, 1.0, 2.0)]
    assert np.all(np.diff(p) > 0), p
    zero = strapdown_free.predict(imu="tactical", rate_hz=10.0, bias_scale=0.0, noise_scale=0.0)
    assert (zero.iloc[:, 1:].to_numpy() == 0).all()


# ---- gnss_tight: Monte Carlo against the filter's own covariance --------------------------

@pytest.mark.parametrize("params, runs", [
    (dict(imu_class="precise", duration=120.0, rate_hz=10.0), 50),
    (dict(imu_class="coarse", duration=150.0, outage_s=60.0, rate_hz=10.0), 50),
])
def test_gnss_tight_rms_matches_the_filter_covariance(params, runs):
    _assert_in_band(_mc_ratio(gnss_tight, runs, **params), runs)


@pytest.mark.slow
@pytest.mark.parametrize("params", [
    dict(),
    dict(outage_s=120.0),
    dict(imu_class="medium", outage_s=60.0),
    dict(imu_class="coarse", outage_s=120.0),
])
def test_gnss_tight_rms_matches_the_filter_covariance_full(params):
    _assert_in_band(_mc_ratio(gnss_tight, 200, **params), 200)


def test_gnss_tight_outage_shows_the_drift():
    """During an outage at the end the predicted error grows past its aided level."""
    p = gnss_tight.predict(imu_class="coarse", duration=150.0, outage_s=60.0, rate_hz=10.0, checkpoint_s=10.0)
    h = p.set_index("time_s")["hpos_error_m"]
    assert h[150.0] > 5 * h[90.0] and np.all(np.diff(h.loc[100.0:].to_numpy()) > 0)


# ---- determinism -----------------------------------------------------------------------------

SHORT = {strapdown_free: dict(duration=60.0, rate_hz=20.0, checkpoint_s=20.0),
         gnss_tight: dict(duration=30.0, rate_hz=10.0, checkpoint_s=10.0)}


@pytest.mark.parametrize("scenario", list(SHORT), ids=lambda f: f.__name__)
def test_same_seed_same_table_bit_for_bit(scenario):
    params = SHORT[scenario]
    a, b = scenario(seed=2**64 - 1, **params), scenario(seed=2**64 - 1, **params)
    pd.testing.assert_frame_equal(a, b, check_exact=True)
    c = scenario(seed=2**64 - 2, **params)
    assert not np.any(c.iloc[:, 1:].to_numpy() == a.iloc[:, 1:].to_numpy())
    pred = scenario.predict(**params)
    assert list(pred.columns) == list(a.columns) == ["time_s", "pos_error_m", "hpos_error_m", "vel_error_mps", "att_error_rad"]
    np.testing.assert_array_equal(pred["time_s"], a["time_s"])


def _digest(table: pd.DataFrame) -> str:
    return hashlib.sha256(np.ascontiguousarray(table.to_numpy()).tobytes()).hexdigest()


def test_a_run_is_the_same_in_another_process():
    params = SHORT[strapdown_free]
    code = ("import hashlib, numpy as np; from atomnav.campaign.strapdown_free import strapdown_free as f; "
            f"t = f(seed=12345, **{params!r}); "
            "print(hashlib.sha256(np.ascontiguousarray(t.to_numpy()).tobytes()).hexdigest())")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=120)
    assert out.stdout.strip() == _digest(strapdown_free(seed=12345, **params))


# ---- bad input ---------------------------------------------------------------------------------

@pytest.mark.parametrize("name, value", [
    ("imu", "ring_laser"), ("motion", "flying"), ("duration", -1.0), ("rate_hz", 0.0), ("checkpoint_s", 0.0),
    ("checkpoint_s", 700.0), ("checkpoint_s", 0.005), ("latitude_deg", 95.0), ("bias_scale", -1.0),
    ("noise_scale", float("nan")), ("duration", float("inf")), ("duration", 1e6), ("rate_hz", 1e9),
])
def test_strapdown_free_bad_values_name_the_parameter(name, value):
    for fn in (strapdown_free, strapdown_free.predict):
        with pytest.raises(an.InputError) as e:
            fn(**{name: value})
        assert e.value.parameter == name


def test_strapdown_free_flicker_band_above_nyquist_names_the_term():
    with pytest.raises(an.InputError) as e:
        strapdown_free.predict(imu="tactical", rate_hz=0.1, checkpoint_s=60.0)
    assert e.value.parameter == "accel.flicker.f_hi"


@pytest.mark.parametrize("name, value", [
    ("imu_class", "tactical"), ("outage_s", 300.0), ("outage_s", 1.5), ("satellites", 25), ("satellites", -1),
    ("checkpoint_s", 0.5), ("checkpoint_s", 400.0), ("duration", 0.0), ("duration", 1e6), ("rate_hz", 12.5), ("rate_hz", 1e6),
])
def test_gnss_tight_bad_values_name_the_parameter(name, value):
    for fn in (gnss_tight, gnss_tight.predict):
        with pytest.raises(an.InputError) as e:
            fn(**{name: value})
        assert e.value.parameter == name


@pytest.mark.parametrize("scenario", list(SHORT), ids=lambda f: f.__name__)
def test_bad_seed_and_unknown_parameter(scenario):
    for seed in (-1, 2**64):
        with pytest.raises(an.InputError) as e:
            scenario(seed=seed)
        assert e.value.parameter == "seed"
    with pytest.raises(TypeError):
        scenario(seed=1.5)
    with pytest.raises(an.InputError, match="grade"):
        check_params(scenario, {"grade": "tactical"})
