"""atomnav.campaign.sweep and atomnav.campaign.plots on a random walk with a closed form:
the covariance sweep equals the closed-form RMS, the requirement boundary equals the
closed-form root within its tolerance (one and two continuous parameters, either feasible
side), a prediction that is not monotonic is flagged, the Monte-Carlo report equals RMS
values computed here from the runs, and the Monte Carlo confirms a boundary on both sides;
the figures hold the numbers they were given; bad input names the argument."""

import itertools

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

from atomnav import InputError  # noqa: E402
from atomnav.campaign import load  # noqa: E402
from atomnav.campaign import timing as timing_of  # noqa: E402
from atomnav.campaign import plots as cplots  # noqa: E402
from atomnav.campaign.plan import Campaign  # noqa: E402
from atomnav.campaign.scenario import predicted_by  # noqa: E402
from atomnav.campaign.sweep import compare, requirements, sweep  # noqa: E402

CHECKPOINTS_S = np.array([25.0, 50.0, 75.0, 100.0])


def _walk_rms(*, q=1.0, drift=0.0, dims=3, dt=1.0):
    """RMS over seeds of the walk's distance: E|e|² = dims (q t + (drift t)²), exactly."""
    t = CHECKPOINTS_S
    return pd.DataFrame({"time_s": t, "pos_error_m": np.sqrt(dims * (q * t + (drift * t) ** 2)),
                         "hpos_error_m": np.sqrt(min(dims, 2) * (q * t + (drift * t) ** 2))})


@predicted_by(_walk_rms)
def walk(*, seed=0, q=1.0, drift=0.0, dims=3, dt=1.0):
    """A walk in ``dims`` axes of N(drift·dt, q·dt) steps (m); its distance from the start
    (and over the first two axes) at the checkpoints."""
    steps = int(round(CHECKPOINTS_S[-1] / dt))
    x = np.cumsum(np.random.default_rng(seed).normal(drift * dt, np.sqrt(q * dt), (steps, dims)), axis=0)
    k = np.round(CHECKPOINTS_S / dt).astype(int) - 1
    return pd.DataFrame({"time_s": CHECKPOINTS_S, "pos_error_m": np.linalg.norm(x[k], axis=1),
                         "hpos_error_m": np.linalg.norm(x[k, :2], axis=1)})


def _bumpy_rms(*, x=0.0):
    """10 m at x = 10.5 on a line through 0, with a narrow spike there of +10 m."""
    return pd.DataFrame({"time_s": [1.0], "err_m": [10.0 * x / 10.5 + (10.0 if abs(x - 10.5) < 0.1 else 0.0)]})


@predicted_by(_bumpy_rms)
def bumpy(*, seed=0, x=0.0):
    return _bumpy_rms(x=x)


def _hump_rms(*, x=0.0):
    """12 − (x − 5)² m: above 10 m where |x − 5| < √2 only (not monotonic)."""
    return pd.DataFrame({"time_s": [1.0], "err_m": [12.0 - (x - 5.0) ** 2]})


@predicted_by(_hump_rms)
def hump(*, seed=0, x=0.0):
    return _hump_rms(x=x)


def _decay_rms(*, x=1.0):
    """100 m / x: the requirement of 10 m holds above x = 10."""
    return pd.DataFrame({"time_s": [1.0], "err_m": [100.0 / x]})


@predicted_by(_decay_rms)
def decay(*, seed=0, x=1.0):
    return _decay_rms(x=x)


def no_predictor(*, seed=0, x=1.0):
    return pd.DataFrame({"time_s": [1.0], "err_m": [x]})


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def closed_form(q, drift, dims, t):
    return np.sqrt(dims * (q * t + (drift * t) ** 2))


# ---- covariance sweep ---------------------------------------------------------------

def test_covariance_sweep_is_the_closed_form_in_grid_order():
    grid = {"q": [0.1, 0.5, 2.0], "dims": [1, 3], "drift": [0.0, 0.05]}
    out = sweep(walk, grid, at=50.0, progress=False)
    combos = list(itertools.product(*grid.values()))  # last name fastest
    assert list(out["point"]) == list(range(len(combos)))
    assert [tuple(r) for r in out[["q", "dims", "drift"]].itertuples(index=False)] == combos
    q, dims, drift = (np.array([c[i] for c in combos], dtype=float) for i in range(3))
    np.testing.assert_allclose(out["pos_error_m_cov"], closed_form(q, drift, dims, 50.0), rtol=1e-14)
    np.testing.assert_allclose(out["hpos_error_m_cov"], closed_form(q, drift, np.minimum(dims, 2), 50.0), rtol=1e-14)
    assert (out["time_s"] == 50.0).all()
    last = sweep(walk, {"q": [0.3]}, fixed={"dims": 2}, progress=False)  # default: the last checkpoint
    assert last["time_s"].tolist() == [100.0] and last["dims"].tolist() == [2]
    np.testing.assert_allclose(last["pos_error_m_cov"], closed_form(0.3, 0.0, 2, 100.0), rtol=1e-14)


def test_covariance_sweep_of_ten_thousand_points_with_a_progress_bar(capsys):
    q = np.linspace(0.01, 10.0, 10_000)
    out = sweep(walk, {"q": list(q)}, at=25.0)
    assert len(out) == 10_000
    np.testing.assert_allclose(out["pos_error_m_cov"], closed_form(q, 0.0, 3, 25.0), rtol=1e-14)
    assert "10000/10000" in capsys.readouterr().err


# ---- requirements -------------------------------------------------------------------

@pytest.mark.parametrize("tol", [1e-6, 1e-3])
def test_requirements_bisects_to_the_closed_form_boundary(tol):
    low, high, target, t = 0.01, 2.0, 10.0, 100.0
    out = requirements(walk, {"pos_error_m": target}, t, {"q": (low, high), "dims": [1, 2, 3]}, tol=tol)
    assert out.columns.tolist() == ["dims", "q", "pos_error_m", "feasible"]
    assert out["dims"].tolist() == [1, 2, 3]
    exact = target**2 / (np.array([1, 2, 3]) * t)  # dims q t = target²
    assert np.all(np.abs(out["q"] - exact) <= tol * (high - low) / 2)
    assert (out["feasible"] == "below").all()
    np.testing.assert_allclose(out["pos_error_m"], closed_form(out["q"], 0.0, out["dims"], t), rtol=1e-14)


def test_requirements_takes_the_tighter_of_two_targets():
    # hpos (2 axes) of dims = 3: 10 m at q = 0.5; pos at q = 1/3 for 10 m, at q = 0.75 for 15 m
    out = requirements(walk, {"pos_error_m": 15.0, "hpos_error_m": 10.0}, 100.0, {"q": (0.01, 2.0)}, tol=1e-9)
    assert out["q"].iloc[0] == pytest.approx(0.5, abs=1e-8)
    assert out["hpos_error_m"].iloc[0] == pytest.approx(10.0, rel=1e-7)


def test_requirements_over_two_continuous_parameters_is_the_boundary_curve():
    low, high, target, t = 0.0, 0.2, 10.0, 100.0
    out = requirements(walk, {"pos_error_m": target}, t, {"dims": [2, 3], "q": (0.01, 0.3), "drift": (low, high)},
                       fixed={"dt": 0.5}, samples=7, tol=1e-7)
    assert out.columns.tolist() == ["dims", "q", "drift", "pos_error_m", "feasible"]
    assert out["dims"].tolist() == [2] * 7 + [3] * 7
    np.testing.assert_allclose(out["q"], np.tile(np.linspace(0.01, 0.3, 7), 2), rtol=1e-15)
    exact = np.sqrt(target**2 / out["dims"] - out["q"] * t) / t  # dims (q t + (b t)²) = target²
    assert np.all(np.abs(out["drift"] - exact) <= 1e-7 * (high - low) / 2)
    assert (out["feasible"] == "below").all()


def test_requirements_reports_the_feasible_side_and_the_ranges_without_a_crossing():
    above = requirements(decay, {"err_m": 10.0}, 1.0, {"x": (1.0, 50.0)})
    assert above["feasible"].tolist() == ["above"] and above["x"].iloc[0] == pytest.approx(10.0, abs=1e-6 * 49)
    every = requirements(walk, {"pos_error_m": 10.0}, 100.0, {"q": (0.01, 0.2)})
    never = requirements(walk, {"pos_error_m": 10.0}, 100.0, {"q": (0.5, 2.0)})
    assert every["feasible"].tolist() == ["all"] and never["feasible"].tolist() == ["none"]
    assert np.isnan(every["q"].iloc[0]) and np.isnan(never["pos_error_m"].iloc[0])


def test_requirements_flags_a_prediction_that_is_not_monotonic():
    # the hump crosses 10 m twice in [0, 10] (at 5 ± √2): the scan sees both
    with pytest.warns(RuntimeWarning, match="not monotonic"):
        out = requirements(hump, {"err_m": 10.0}, 1.0, {"x": (0.0, 10.0)})
    assert out["feasible"].tolist() == ["non-monotonic"] and np.isnan(out["x"].iloc[0])
    # the spike at 10.5 lies between two scan points (10 and 11) and is hit by the first bisection step
    with pytest.warns(RuntimeWarning, match="not monotonic"):
        out = requirements(bumpy, {"err_m": 10.0}, 1.0, {"x": (0.0, 16.0)}, samples=17)
    assert out["feasible"].tolist() == ["non-monotonic"]


# ---- Monte Carlo --------------------------------------------------------------------

def test_monte_carlo_report_equals_the_rms_over_the_runs(tmp_path):
    points, seeds = {"q": [0.2, 1.0], "dims": [2]}, 40
    out = sweep(walk, points, method="monte_carlo", seeds=seeds, seed=7, at=75.0, folder=tmp_path, progress=False)
    campaign = Campaign(walk, points, seeds=seeds, seed=7)
    for i, q in enumerate(points["q"]):
        runs = [walk(seed=campaign.run_seed(i * seeds + j), q=q, dims=2) for j in range(seeds)]
        e = np.array([r.loc[r["time_s"] == 75.0, "pos_error_m"].iloc[0] for r in runs])
        row = out.iloc[i]
        assert row["q"] == q and row["dims"] == 2 and row["seeds"] == seeds and row["time_s"] == 75.0
        assert row["pos_error_m_mc"] == pytest.approx(np.sqrt(np.mean(e**2)), rel=1e-13)
        se = np.std(e**2, ddof=1) / np.sqrt(seeds) / (2 * np.sqrt(np.mean(e**2)))
        assert row["pos_error_m_mc_se"] == pytest.approx(se, rel=1e-12)
        assert row["pos_error_m_cov"] == pytest.approx(closed_form(q, 0.0, 2, 75.0), rel=1e-14)
        assert row["pos_error_m_ratio"] == pytest.approx(row["pos_error_m_mc"] / row["pos_error_m_cov"], rel=1e-14)
    table = load(tmp_path, "walk")
    again = compare(table, campaign, 75.0)  # the same report from the stored table
    pd.testing.assert_frame_equal(again, out)
    shuffled = table.sample(frac=1.0, random_state=1).rename(columns={"q": "renamed"})  # parameters come from the campaign
    pd.testing.assert_frame_equal(compare(shuffled, campaign, 75.0), out)
    other = Campaign(walk, {"q": [0.2, 1.5], "dims": [2]}, seeds=seeds, seed=7)
    with pytest.raises(InputError, match="'q' holds 1.0 at point 1 where the campaign has 1.5") as e:
        compare(table, other)  # the table of another campaign
    assert e.value.parameter == "table"
    with pytest.raises(InputError, match="'q' holds '0.2'"):
        compare(table.astype({"q": str}), campaign)
    one = compare(table[table["point"] == 1], campaign)  # a part of the table, at the last checkpoint
    assert one["point"].tolist() == [1] and one["time_s"].tolist() == [100.0]
    assert one["pos_error_m_cov"].iloc[0] == pytest.approx(closed_form(1.0, 0.0, 2, 100.0), rel=1e-14)


def _confirm(scenario, metric, target, at, space, seeds, folder, fixed=None, step=0.15):
    """The boundary of ``requirements`` and the Monte Carlo ``step`` (relative) inside and
    outside it."""
    (name, _), = ((k, v) for k, v in space.items() if isinstance(v, tuple))
    boundary = requirements(scenario, {metric: target}, at, space, fixed=fixed)
    assert boundary["feasible"].tolist() == ["below"]
    b = boundary[name].iloc[0]
    mc = sweep(scenario, {name: [(1 - step) * b, (1 + step) * b]}, fixed=fixed, method="monte_carlo", seeds=seeds, at=at,
               folder=folder, progress=False)
    rms, se = mc[metric + "_mc"].to_numpy(), mc[metric + "_mc_se"].to_numpy()
    assert np.all(se < 0.03 * rms)  # the MC RMS is known to a few %
    assert rms[0] <= target < rms[1], (boundary, mc)  # inside meets the target, outside does not
    assert rms[0] + 2 * se[0] < target < rms[1] - 2 * se[1], (boundary, mc)  # and not by chance (2 SE)
    return b, mc


def test_monte_carlo_confirms_the_requirement_boundary_on_both_sides(tmp_path):
    b, mc = _confirm(walk, "pos_error_m", 10.0, 100.0, {"q": (0.01, 2.0)}, 1000, tmp_path)
    assert b == pytest.approx(1.0 / 3.0, abs=1e-5)


def test_monte_carlo_confirms_the_bias_a_free_ins_tolerates(tmp_path):
    from atomnav.campaign.strapdown_free import strapdown_free

    fixed = {"duration": 120.0, "checkpoint_s": 60.0, "rate_hz": 20.0}
    b, mc = _confirm(strapdown_free, "pos_error_m", 100.0, 120.0, {"bias_scale": (0.1, 3.0)}, 300, tmp_path, fixed)
    assert 0.1 < b < 3.0


@pytest.mark.slow
def test_monte_carlo_confirms_the_bias_a_moving_free_ins_tolerates_within_ten_percent(tmp_path):
    from atomnav.campaign.strapdown_free import strapdown_free

    fixed = {"duration": 300.0, "checkpoint_s": 60.0, "rate_hz": 50.0, "motion": "sinusoidal", "imu": "navigation"}
    _confirm(strapdown_free, "hpos_error_m", 20.0, 300.0, {"bias_scale": (0.05, 5.0)}, 1000, tmp_path, fixed, step=0.1)


# ---- plots --------------------------------------------------------------------------

def test_error_vs_parameter_draws_the_predictions_and_the_monte_carlo(tmp_path):
    report = pd.DataFrame({"q": [1.0, 0.5, 2.0], "time_s": 100.0, "pos_error_m_cov": [3.0, 2.0, 5.0],
                           "pos_error_m_mc": [3.1, 1.9, 5.2], "pos_error_m_mc_se": [0.1, 0.05, 0.2]})
    fig = cplots.error_vs_parameter(report, "q", "pos_error_m")
    fig.savefig(tmp_path / "e.png")
    ax = fig.axes[0]
    (line,) = [ln for ln in ax.lines if ln.get_label() == "covariance"]
    np.testing.assert_array_equal(line.get_xdata(), [0.5, 1.0, 2.0])
    np.testing.assert_array_equal(line.get_ydata(), [2.0, 3.0, 5.0])
    bars = ax.containers[0]
    np.testing.assert_array_equal(bars.lines[0].get_ydata(), [1.9, 3.1, 5.2])
    segments = bars.lines[2][0].get_segments()
    np.testing.assert_allclose([s[1, 1] - s[0, 1] for s in segments], 2 * 1.96 * np.array([0.05, 0.1, 0.2]))
    with pytest.raises(InputError) as e:
        cplots.error_vs_parameter(pd.concat([report, report]), "q", "pos_error_m")
    assert e.value.parameter == "report"


def test_error_vs_parameter_of_a_covariance_sweep_per_series(tmp_path):
    out = sweep(walk, {"dims": [1, 3], "q": [0.1, 0.2, 0.4]}, progress=False)
    with pytest.raises(InputError, match="monte_carlo=False"):
        cplots.error_vs_parameter(out, "q", "pos_error_m", by="dims")
    fig = cplots.error_vs_parameter(out, "q", "pos_error_m", monte_carlo=False, by="dims")
    fig.savefig(tmp_path / "s.png")
    for dims in (1, 3):
        (line,) = [ln for ln in fig.axes[0].lines if ln.get_label() == f"covariance, dims = {dims}"]
        np.testing.assert_allclose(line.get_ydata(), closed_form(np.array([0.1, 0.2, 0.4]), 0.0, dims, 100.0), rtol=1e-14)


def test_error_map_draws_the_grid_and_the_requirement_contour(tmp_path):
    qs, drifts = np.linspace(0.05, 0.6, 12), np.linspace(0.0, 0.1, 11)
    out = sweep(walk, {"drift": list(drifts), "q": list(qs)}, progress=False)
    fig = cplots.error_map(out, "q", "drift", "pos_error_m_cov", target=10.0)
    fig.savefig(tmp_path / "m.png")
    ax = fig.axes[0]
    mesh = ax.collections[0]
    expected = closed_form(qs[None, :], drifts[:, None], 3, 100.0)
    np.testing.assert_allclose(np.asarray(mesh.get_array()).reshape(expected.shape), expected, rtol=1e-14)
    (contour,) = [c for c in ax.collections[1:]]
    assert list(contour.levels) == [10.0]
    vertices = np.concatenate([p.vertices for p in contour.get_paths()])
    assert len(vertices) > 5
    # linear interpolation between grid nodes: on the closed-form 10 m line within the grid's curvature
    np.testing.assert_allclose(closed_form(vertices[:, 0], vertices[:, 1], 3, 100.0), 10.0, rtol=0.02)
    with pytest.raises(InputError) as e:
        cplots.error_map(out.iloc[:-1], "q", "drift", "pos_error_m_cov")
    assert e.value.parameter == "report"


def test_throughput_counts_runs_per_worker(tmp_path):
    timing = pd.DataFrame({"run": [0, 1, 2, 3, 4], "point": 0, "worker": ["a", "b", "a", "a", "b"],
                           "elapsed_s": [1.0, 2.0, 1.0, 2.0, 0.5]})
    fig = cplots.throughput(timing)
    fig.savefig(tmp_path / "t.png")
    bars = fig.axes[1].patches
    np.testing.assert_allclose([b.get_height() for b in bars], [3 / 4.0, 2 / 2.5])
    left = {ln.get_label(): ln for ln in fig.axes[0].lines}
    np.testing.assert_array_equal(left["a"].get_ydata(), [1.0, 1.0, 2.0])
    with pytest.raises(InputError) as e:
        cplots.throughput(timing.drop(columns="worker"))
    assert e.value.parameter == "timing"


def test_throughput_of_a_campaign_run(tmp_path):
    sweep(walk, {"q": [0.5, 1.0]}, method="monte_carlo", seeds=6, folder=tmp_path, progress=False)
    timing = timing_of(tmp_path, "walk")
    assert len(timing) == 12 and (timing["elapsed_s"] > 0).all()
    fig = cplots.throughput(timing)
    fig.savefig(tmp_path / "t.png")
    per = timing.groupby("worker")["elapsed_s"].agg(["size", "sum"]).sort_index()
    np.testing.assert_allclose([b.get_height() for b in fig.axes[1].patches], per["size"] / per["sum"], rtol=1e-14)


# ---- bad input ----------------------------------------------------------------------

@pytest.mark.parametrize("call, parameter", [
    (lambda: sweep(walk, {"qq": [1.0]}, progress=False), "points"),
    (lambda: sweep(walk, {}, progress=False), "points"),
    (lambda: sweep(walk, {"q": []}, progress=False), "points"),
    (lambda: sweep(walk, {"q": [1.0]}, method="kalman", progress=False), "method"),
    (lambda: sweep(walk, {"q": [1.0]}, at=30.0, progress=False), "at"),
    (lambda: sweep(walk, {"q": [1.0]}, at=float("nan"), progress=False), "at"),
    (lambda: sweep(walk, {"q": [1.0]}, fixed={"zz": 1}, progress=False), "fixed"),
    (lambda: sweep(walk, {"q": [1.0]}, folder="x", progress=False), "folder"),
    (lambda: sweep(walk, {"q": [1.0]}, method="monte_carlo", progress=False), "folder"),
    (lambda: sweep(walk, {"q": [1.0]}, method="monte_carlo", seeds=1, folder="x", progress=False), "seeds"),
    (lambda: sweep(no_predictor, {"x": [1.0]}, progress=False), "scenario"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {"qq": (0.1, 1.0)}), "space"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {}), "space"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {"q": (1.0, 0.1)}), "space"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {"q": (0.1, 1.0, 2.0)}), "space"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {"dims": [1, 2]}), "space"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {"q": (0.1, 1.0), "dims": []}), "space"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0,
                          {"q": (0.1, 1.0), "drift": (0.0, 1.0), "dt": (0.5, 1.0)}), "space"),
    (lambda: requirements(walk, {"vel_error_mps": 1.0}, 100.0, {"q": (0.1, 1.0)}), "target"),
    (lambda: requirements(walk, {}, 100.0, {"q": (0.1, 1.0)}), "target"),
    (lambda: requirements(walk, {"pos_error_m": -1.0}, 100.0, {"q": (0.1, 1.0)}), "target['pos_error_m']"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 60.0, {"q": (0.1, 1.0)}), "at"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {"q": (0.1, 1.0)}, fixed={"q": 1.0}), "fixed"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {"q": (0.1, 1.0)}, fixed={"zz": 1.0}), "fixed"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {"q": (0.1, 1.0)}, tol=1.5), "tol"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {"q": (0.1, 1.0)}, samples=2), "samples"),
    (lambda: requirements(walk, {"pos_error_m": 1.0}, 100.0, {"q": (0.1, 1.0)}, method="monte_carlo"), "method"),
    (lambda: compare(pd.DataFrame({"point": [0], "q": [1.0]}), Campaign(walk, {"q": [1.0]})), "table"),
    (lambda: compare(pd.DataFrame({"point": [0, 2], "time_s": 100.0, "pos_error_m": 1.0, "hpos_error_m": 1.0}),
                     Campaign(walk, {"q": [1.0, 2.0]})), "table"),
    (lambda: compare(pd.DataFrame({"point": [0], "time_s": 100.0, "pos_error_m": 1.0, "hpos_error_m": 1.0}),
                     Campaign(walk, {"q": [1.0]})), "table"),
    (lambda: compare(pd.DataFrame({"point": [0, 0], "time_s": 100.0, "pos_error_m": [1.0, np.nan], "hpos_error_m": 1.0}),
                     Campaign(walk, {"q": [1.0]})), "table"),
    (lambda: compare(pd.DataFrame({"point": [0, 0], "time_s": 100.0, "pos_error_m": 1.0, "hpos_error_m": 1.0}),
                     Campaign(walk, {"q": [1.0]}), at=50.0), "at"),
    (lambda: compare(pd.DataFrame({"point": [0, 0], "time_s": 1.0, "err_m": 1.0}), Campaign(no_predictor, {"x": [1.0]})),
     "campaign"),
    (lambda: cplots.error_vs_parameter(pd.DataFrame({"q": [1.0], "time_s": 1.0}), "q", "pos_error_m"), "report"),
])
def test_bad_input_names_the_argument(call, parameter):
    with pytest.raises(InputError) as e:
        call()
    assert e.value.parameter == parameter, str(e.value)


def test_wrong_types_are_type_errors():
    with pytest.raises(TypeError, match="space"):
        requirements(walk, {"pos_error_m": 1.0}, 100.0, {"q": 0.5})
    with pytest.raises(TypeError, match="target"):
        requirements(walk, [("pos_error_m", 1.0)], 100.0, {"q": (0.1, 1.0)})
    with pytest.raises(TypeError, match="table"):
        compare([1, 2], Campaign(walk, {"q": [1.0]}))
    with pytest.raises(TypeError, match="campaign"):
        compare(pd.DataFrame({"point": [0]}), walk)


def test_monte_carlo_on_a_dask_client_equals_the_in_process_report(tmp_path):
    distributed = pytest.importorskip("distributed")
    points = {"q": [0.5, 1.0]}
    here = sweep(walk, points, method="monte_carlo", seeds=8, seed=3, folder=tmp_path / "here", progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        there = sweep(walk, points, method="monte_carlo", seeds=8, seed=3, folder=tmp_path / "there", client=client,
                      progress=False)
    pd.testing.assert_frame_equal(there, here)
    assert set(timing_of(tmp_path / "there", "walk")["worker"]) <= {"0", "1"}
