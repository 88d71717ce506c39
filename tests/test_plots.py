"""atomnav.plots on real library outputs: the plotted numbers read back from the figure
equal the input converted by unit factors written out here, the ±3σ envelopes equal
3σ of the right state (the N/E/D mapping checked against a filter whose fixes are
anisotropic), the χ² bands equal scipy's quantiles and the share inside equals a count
made here; bad input names the argument."""

import subprocess
import sys

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402
from scipy.stats import chi2  # noqa: E402

import atomnav as an  # noqa: E402
from atomnav import plots  # noqa: E402

# unit factors written out (independent of atomnav.units)
DEG = np.pi / 180.0
DEG_PER_HOUR = DEG / 3600.0
MICRO_G = 9.80665e-6
WGS84 = (6378137.0, 1.0 / 298.257223563)
PZ90 = (6378136.0, 1.0 / 298.25784)
NAV_BLOCKS = ("position", "velocity", "attitude")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def line(ax, label: str):
    """The line of ``ax`` whose legend label starts with ``label``."""
    found = [ln for ln in ax.lines if ln.get_label().startswith(label)]
    assert len(found) == 1, [ln.get_label() for ln in ax.lines]
    return found[0]


def legend_texts(ax) -> list[str]:
    return [t.get_text() for t in ax.get_legend().get_texts()]


def ned_numpy(lla: np.ndarray, origin: np.ndarray, ellipsoid=WGS84) -> np.ndarray:
    """NED (m) of geodetic points from an origin on an ellipsoid (a, f), closed form."""
    a, f = ellipsoid
    e2 = f * (2 - f)

    def ecef(p):
        lat, lon, h = p[..., 0], p[..., 1], p[..., 2]
        n = a / np.sqrt(1 - e2 * np.sin(lat) ** 2)
        return np.stack([(n + h) * np.cos(lat) * np.cos(lon), (n + h) * np.cos(lat) * np.sin(lon),
                         (n * (1 - e2) + h) * np.sin(lat)], axis=-1)

    lat, lon = origin[0], origin[1]
    c_en = np.array([[-np.sin(lat) * np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat)],
                     [-np.sin(lon), np.cos(lon), 0.0],
                     [-np.cos(lat) * np.cos(lon), -np.cos(lat) * np.sin(lon), -np.sin(lat)]])
    return (ecef(lla) - ecef(origin)) @ c_en.T


@pytest.fixture(scope="module")
def run():
    """Two minutes of sinusoidal motion, tactical IMU, 1 Hz position fixes."""
    traj = an.trajectory.sinusoidal(120.0, rate_hz=100.0)
    meas = an.imu.corrupt(traj.ideal_imu("increments"), errors="tactical", dt=0.01, kind="increments", seed=7)
    st = traj.initial_state()
    fix_t = np.arange(1.0, 120.0, 1.0)
    fix_lla = traj.lla[np.searchsorted(traj.time, fix_t)]
    p0 = np.diag(np.r_[[1.0] * 3, [0.01] * 3, [1e-6] * 3, [1e-4] * 3, [1e-10] * 3])
    ins = an.filter.position_aided_ins(st["t0"], st["lla"], st["vel_ned"], st["q_nb"], "increments", fix_t, fix_lla,
                                       np.tile(np.eye(3), (len(fix_t), 1, 1)), p0=p0, accel_psd=1e-6, gyro_psd=1e-10,
                                       predict_every=10)
    res = ins.run(meas["time_s"].to_numpy(), meas[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(),
                  meas[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy(), progress=False)
    free = an.strapdown.integrate(meas, **st)
    return dict(traj=traj, meas=meas, res=res, err=traj.errors(res.nav), free=free)


# ---- trajectory ---------------------------------------------------------------------

def test_trajectory_map_view_is_north_east_from_the_first_point(run):
    nav, ref = run["res"].nav, run["traj"]
    fig = plots.trajectory(nav, ref)
    assert isinstance(fig, matplotlib.figure.Figure)
    ax = fig.axes[0]
    assert "(m)" in ax.get_xlabel() and "east" in ax.get_xlabel()
    assert "(m)" in ax.get_ylabel() and "north" in ax.get_ylabel()
    assert ax.get_title()
    lla = nav[["lat_rad", "lon_rad", "h_m"]].to_numpy()
    want = ned_numpy(lla, lla[0])
    np.testing.assert_allclose(line(ax, "solution").get_xydata(), want[:, [1, 0]], rtol=0, atol=1e-6)
    want_ref = ned_numpy(ref.lla, lla[0])  # the reference from the solution's first point
    np.testing.assert_allclose(line(ax, "reference").get_xydata(), want_ref[:, [1, 0]], rtol=0, atol=1e-6)
    np.testing.assert_array_equal(line(ax, "origin").get_xydata(), [[0.0, 0.0]])


def test_trajectory_of_a_free_inertial_solution_and_a_trajectory_object(run):
    fig = plots.trajectory(run["free"])
    lla = run["free"][["lat_rad", "lon_rad", "h_m"]].to_numpy()
    np.testing.assert_allclose(line(fig.axes[0], "solution").get_xydata(), ned_numpy(lla, lla[0])[:, [1, 0]], rtol=0, atol=1e-6)
    fig = plots.trajectory(run["traj"])  # a Trajectory is read through its table
    want = ned_numpy(run["traj"].lla, run["traj"].lla[0])
    np.testing.assert_allclose(line(fig.axes[0], "solution").get_xydata(), want[:, [1, 0]], rtol=0, atol=1e-6)


def test_trajectory_of_spp_columns_leaves_out_and_counts_epochs_without_a_solution(run):
    lla = run["traj"].lla[::500]
    spp = pd.DataFrame(np.nan, index=range(len(lla)), columns=an.gnss.spp.SPP_COLUMNS)
    spp[["lat_rad", "lon_rad", "h_m"]] = lla
    spp["time_s"] = run["traj"].time[::500]
    spp.loc[[0, 3], ["lat_rad", "lon_rad", "h_m"]] = np.nan  # two epochs without a solution
    fig = plots.trajectory(spp)
    ax = fig.axes[0]
    kept = np.delete(lla, [0, 3], axis=0)
    np.testing.assert_allclose(line(ax, "solution").get_xydata(), ned_numpy(kept, kept[0])[:, [1, 0]], rtol=0, atol=1e-6)
    assert "solution (2 rows with NaN left out)" in legend_texts(ax)


def test_trajectory_uses_the_ellipsoid_of_a_trajectory_object():
    traj = an.trajectory.sinusoidal(10.0, rate_hz=10.0, amp_ned=(2000.0, 1500.0, 20.0), ellipsoid="PZ90.11")
    want = {"PZ90.11": ned_numpy(traj.lla, traj.lla[0], PZ90), "WGS84": ned_numpy(traj.lla, traj.lla[0], WGS84)}
    assert np.abs(want["PZ90.11"] - want["WGS84"]).max() > 1e-4  # the test can tell them apart
    for fig, name in ((plots.trajectory(traj), "PZ90.11"), (plots.trajectory(traj.df), "WGS84"),
                      (plots.trajectory(traj.df, ellipsoid="PZ90.11"), "PZ90.11")):
        np.testing.assert_allclose(line(fig.axes[0], "solution").get_xydata(), want[name][:, [1, 0]], rtol=0, atol=1e-6)
    with pytest.raises(an.InputError) as e:
        plots.trajectory(traj, ellipsoid="WGS-84")
    assert e.value.parameter == "ellipsoid"


# ---- errors -------------------------------------------------------------------------

def test_errors_plot_the_error_columns_and_3_sigma_of_the_same_state(run):
    err, nav = run["err"], run["res"].nav
    fig = plots.errors(err, run["res"])
    axes = np.array(fig.axes).reshape(3, 3)
    units_ = ("(m)", "(m/s)", "(°)")
    for r, (prefix, factor) in enumerate((("dpos", 1.0), ("dvel", 1.0), ("psi", DEG))):
        for c, axis in enumerate("ned"):
            ax = axes[r, c]
            assert units_[r] in ax.get_ylabel() and ("north", "east", "down")[c] in ax.get_ylabel()
            col = [k for k in err.columns if k.startswith(f"{prefix}_{axis}_")]
            assert len(col) == 1
            xy = line(ax, "error").get_xydata()
            np.testing.assert_array_equal(xy[:, 0], err["time_s"])
            np.testing.assert_allclose(xy[:, 1], err[col[0]] / factor, rtol=1e-15, atol=0)
            sigma = nav[f"sigma_{NAV_BLOCKS[r]}[{c}]"].to_numpy() / factor
            upper = line(ax, "±3σ").get_xydata()
            np.testing.assert_array_equal(upper[:, 0], nav["time_s"])
            np.testing.assert_allclose(upper[:, 1], 3 * sigma, rtol=1e-15, atol=0)
            lower = [ln for ln in ax.lines if ln.get_label() == "_nolegend_"][0].get_xydata()
            np.testing.assert_allclose(lower[:, 1], -3 * sigma, rtol=1e-15, atol=0)
    for ax in axes[-1]:
        assert ax.get_xlabel() == "time (s)"
    assert fig._suptitle.get_text()


def test_errors_sigma_columns_map_to_north_east_down_in_any_column_order():
    t = np.arange(4.0)
    err = pd.DataFrame({"time_s": t, **{c: np.zeros(4) for c in an._core.NAV_ERROR_COLUMNS}})
    values = {f"sigma_{b}[{i}]": float(10 * r + i + 1) for r, b in enumerate(NAV_BLOCKS) for i in range(3)}
    names = list(values)[::-1]  # reversed column order, plus an unrelated column
    sigma = pd.DataFrame({"time_s": t, "other": 99.0, **{k: np.full(4, values[k]) for k in names}})
    axes = np.array(plots.errors(err, sigma).axes).reshape(3, 3)
    for r in range(3):
        for c in range(3):
            factor = DEG if r == 2 else 1.0
            np.testing.assert_allclose(line(axes[r, c], "±3σ").get_ydata(), 3 * (10 * r + c + 1) / factor, rtol=1e-15)


def test_errors_envelope_axes_follow_the_filter_state_order():
    """Fixes with σ_N = 1, σ_E = 10, σ_D = 100 m: the filter's position σ must come out
    smallest on the north axis and largest on the down axis. At rest the tilt ψ_E is seen
    through the north velocity (δv̇_N = g ψ_E) and ψ_N through the east one, whose fixes
    are worse, while heading ψ_D is not seen at all: its σ stays at the initial 1 mrad."""
    lat, lon, h = 0.8, 0.2, 100.0
    omega, n = 7.292115e-5, 6001
    t = np.arange(n) / 100.0
    gyro = np.tile([omega * np.cos(lat), 0.0, -omega * np.sin(lat)], (n, 1))
    accel = np.tile([0.0, 0.0, -an.earth.gravity(lat, h)], (n, 1))
    fix_t = np.arange(1.0, 60.0, 1.0)
    cov = np.tile(np.diag([1.0, 100.0, 10000.0]), (len(fix_t), 1, 1))
    p0 = np.diag(np.r_[[1e4] * 3, [0.01] * 3, [1e-6] * 3, [1e-6] * 3, [1e-12] * 3])
    ins = an.filter.position_aided_ins(0.0, [lat, lon, h], [0, 0, 0], [1, 0, 0, 0], "rates", fix_t,
                                       np.tile([lat, lon, h], (len(fix_t), 1)), cov, p0=p0, accel_psd=1e-8,
                                       gyro_psd=1e-14, predict_every=10)
    res = ins.run(t, gyro, accel, progress=False)
    err = pd.DataFrame({"time_s": res.nav["time_s"], **{c: 0.0 for c in an._core.NAV_ERROR_COLUMNS}})
    axes = np.array(plots.errors(err, res).axes).reshape(3, 3)
    last = [line(axes[0, c], "±3σ").get_ydata()[-1] / 3 for c in range(3)]
    assert last[0] < 1.0 < last[1] < 10.0 < last[2] < 100.0
    psi = [line(axes[2, c], "±3σ").get_ydata()[-1] / 3 * DEG for c in range(3)]  # rad
    assert psi[1] < psi[0] < 0.5 * psi[2]
    assert abs(psi[2] - 1e-3) < 1e-5


def test_errors_without_sigma_has_no_envelope(run):
    fig = plots.errors(run["err"])
    for ax in fig.axes:
        assert [ln.get_label() for ln in ax.lines] == ["error"]


# ---- IMU errors ---------------------------------------------------------------------

def test_imu_errors_estimates_envelope_and_truth(run):
    nav, meas = run["res"].nav, run["meas"]
    fig = plots.imu_errors(run["res"], truth=meas)
    axes = np.array(fig.axes).reshape(2, 3)
    for r, (sensor, unit_col, block, factor, label) in enumerate(
            (("accel_bias", "mps2", "accel_bias", MICRO_G, "(µg)"), ("gyro_bias", "rad_s", "gyro_bias", DEG_PER_HOUR, "(°/h)"))):
        for c, axis in enumerate("xyz"):
            ax = axes[r, c]
            assert label in ax.get_ylabel()
            col = f"{sensor}_{axis}_{unit_col}"
            est = line(ax, "estimate").get_xydata()
            np.testing.assert_array_equal(est[:, 0], nav["time_s"])
            np.testing.assert_allclose(est[:, 1], nav[col] / factor, rtol=1e-14)
            sigma = nav[f"sigma_{block}[{c}]"].to_numpy() / factor
            upper = line(ax, "±3σ").get_ydata()
            lower = [ln for ln in ax.lines if ln.get_label() == "_nolegend_"][0].get_ydata()
            np.testing.assert_allclose(upper - est[:, 1], 3 * sigma, rtol=1e-9)
            np.testing.assert_allclose(est[:, 1] - lower, 3 * sigma, rtol=1e-9)
            true = line(ax, "true").get_xydata()
            np.testing.assert_array_equal(true[:, 0], meas["time_s"])
            np.testing.assert_allclose(true[:, 1], meas[col] / factor, rtol=1e-14)
    for ax in axes[-1]:
        assert ax.get_xlabel() == "time (s)"


# ---- NIS / NEES ---------------------------------------------------------------------

def test_consistency_bands_are_scipys_and_the_share_is_counted(run):
    res, err = run["res"], run["err"]
    e = err[list(an._core.NAV_ERROR_COLUMNS)].to_numpy()
    s = res.nav[[f"sigma_{b}[{i}]" for b in NAV_BLOCKS for i in range(3)]].to_numpy()
    nees = pd.DataFrame({"time_s": err["time_s"], "nees": ((e / s) ** 2).sum(axis=1)})
    fig = plots.consistency(nis=res, nees=nees, dof=9)
    ax_nis, ax_nees = fig.axes
    for ax, x, t, dof, name in ((ax_nis, res.measurements["nis"].to_numpy(), res.measurements["time_s"], 3, "NIS"),
                                (ax_nees, nees["nees"].to_numpy(), nees["time_s"], 9, "NEES")):
        assert ax.get_xlabel() == "time (s)" and "(dimensionless)" in ax.get_ylabel() and name in ax.get_title()
        np.testing.assert_array_equal(line(ax, name).get_xydata(), np.c_[t, x])
        lo, hi = chi2.ppf([0.025, 0.975], dof)
        band = line(ax, "95 % band")
        np.testing.assert_allclose(band.get_ydata(), lo, rtol=1e-12)
        other = [ln for ln in ax.lines if ln.get_label() == "_nolegend_"][0]
        np.testing.assert_allclose(other.get_ydata(), hi, rtol=1e-12)
        inside = sum(1 for v in x if lo <= v <= hi)
        assert band.get_label() == f"95 % band χ²({dof}) [{lo:.3g}, {hi:.3g}]: {100 * inside / len(x):.1f} % of {len(x)} inside"


def test_consistency_nis_dof_per_measurement_and_nan_left_out():
    meas = pd.DataFrame({"time_s": [1.0, 2.0, 3.0, 4.0, 5.0, 6.0], "rows": [2, 3, 2, 3, 3, 2],
                         "nis": [0.01, 8.0, np.nan, 10.0, 0.1, 7.0], "rejected_rows": 0})
    fig = plots.consistency(nis=meas, p=0.9)
    ax = fig.axes[0]
    b2, b3 = chi2.ppf([0.05, 0.95], 2), chi2.ppf([0.05, 0.95], 3)
    band = line(ax, "90 % band")
    np.testing.assert_allclose(band.get_ydata(), [b2[0], b3[0], b2[0], b3[0], b3[0], b2[0]], rtol=1e-12)
    # inside: 0.01 < b2[0]=0.103 no; 8.0 in [0.352, 7.81] no; 10 no; 0.1 no (b3[0]=0.352); 7.0 in [0.103, 5.99] no
    x = meas["nis"].to_numpy()
    lo = np.where(meas["rows"] == 2, b2[0], b3[0])
    hi = np.where(meas["rows"] == 2, b2[1], b3[1])
    inside = int(sum(1 for v, a, b in zip(x, lo, hi) if a <= v <= b))
    assert f"{100 * inside / 5:.1f} % of 5 inside" in band.get_label()
    assert f"χ²(2) [{b2[0]:.3g}, {b2[1]:.3g}], χ²(3) [{b3[0]:.3g}, {b3[1]:.3g}]" in band.get_label()
    assert "NIS (1 value with NaN left out)" in legend_texts(ax)
    meas.loc[2, "nis"] = 1.0  # inside χ²(2)'s band: the share counts it
    band = line(plots.consistency(nis=meas, p=0.9).axes[0], "90 % band")
    assert f"{100 * (inside + 1) / 6:.1f} % of 6 inside" in band.get_label()


# ---- Allan --------------------------------------------------------------------------

@pytest.fixture(scope="module")
def gyro_log():
    """One hour of a gyro in °/h at 10 Hz: white noise of ARW 0.1 °/√h plus a bias."""
    rng = np.random.default_rng(5)
    tau0, arw = 0.1, 0.1
    w = 2.0 + arw * 60.0 / np.sqrt(tau0) * rng.standard_normal(36000)
    return w, tau0


def test_allan_points_error_bars_and_fitted_terms(gyro_log):
    w, tau0 = gyro_log
    table = an.noise.allan.allan_variance(w, tau0)
    fit = an.noise.allan.fit_allan(w, tau0, terms=("arw", "bias_instability"))
    fig = plots.allan(table, fit, unit=an.units.DEG_PER_HOUR)
    ax = fig.axes[0]
    assert ax.get_xlabel() == "averaging time τ (s)" and ax.get_ylabel() == "Allan deviation (°/h)"
    assert ax.get_xscale() == ax.get_yscale() == "log"
    data, _, (bars,) = ax.containers[0].lines
    np.testing.assert_allclose(data.get_xydata(), table[["tau_s", "dev"]].to_numpy(), rtol=1e-14)
    segs = np.array(bars.get_segments())  # (K, 2, 2): (τ, dev_lo), (τ, dev_hi)
    np.testing.assert_allclose(segs[:, 0, 1], table["dev_lo"], rtol=1e-12)
    np.testing.assert_allclose(segs[:, 1, 1], table["dev_hi"], rtol=1e-12)
    # ARW in °/√h: U·√s with U = °/h is /60 (√h = 60 √s); the line is √(A₋₁/τ)
    arw = line(ax, "ARW")
    assert arw.get_label() == f"ARW {fit.arw / 60.0:.3g} °/√h"
    assert abs(fit.arw / 60.0 - 0.1) < 0.01  # the simulated 0.1 °/√h
    tau = arw.get_xdata()
    np.testing.assert_allclose(arw.get_ydata(), np.sqrt(fit.coeffs[1] / tau), rtol=1e-12)
    legend = legend_texts(ax)
    if fit.coeffs[2] > 0:
        assert f"bias instability {fit.bias_instability:.3g} °/h" in legend
    else:
        assert not any(t.startswith("bias instability") for t in legend)
    np.testing.assert_allclose(line(ax, "five-term fit").get_ydata(), np.sqrt(fit.curve(tau)), rtol=1e-12)


def test_allan_of_an_si_accelerometer_log_in_micro_g():
    rng = np.random.default_rng(6)
    vrw = 50.0 * MICRO_G  # 50 µg/√Hz in m/s/√s
    a = vrw / np.sqrt(0.01) * rng.standard_normal(20000)
    table = an.noise.allan.allan_variance(a, 0.01)
    fit = an.noise.allan.fit_allan(a, 0.01, terms=("arw",))
    ax = plots.allan(table, fit, angular=False).axes[0]
    assert ax.get_ylabel() == "Allan deviation (µg)"
    np.testing.assert_allclose(ax.containers[0].lines[0].get_ydata(), table["dev"] / MICRO_G, rtol=1e-14)
    assert line(ax, "VRW").get_label() == f"VRW {fit.arw / MICRO_G:.3g} µg/√Hz"
    assert abs(fit.arw / MICRO_G - 50.0) < 5.0


def test_allan_rows_with_nan_are_left_out_and_counted(gyro_log):
    w, tau0 = gyro_log
    table = an.noise.allan.allan_variance(w, tau0)
    table.loc[1, "dev_hi"] = np.nan
    ax = plots.allan(table).axes[0]
    np.testing.assert_allclose(ax.containers[0].lines[0].get_xdata(), table["tau_s"].drop(index=1), rtol=0)
    assert "Allan deviation (1 row with NaN left out)" in legend_texts(ax)


# ---- bad input and imports ----------------------------------------------------------

def test_missing_columns_name_the_argument_and_the_column(run):
    res, err = run["res"], run["err"]
    cases = [
        (lambda: plots.trajectory(res.nav.drop(columns="lon_rad")), "nav", "lon_rad"),
        (lambda: plots.trajectory(res.nav, reference=run["traj"].df.drop(columns="h_m")), "reference", "h_m"),
        (lambda: plots.errors(err.drop(columns="dvel_e_mps")), "err", "dvel_e_mps"),
        (lambda: plots.errors(err, res.nav.drop(columns="sigma_attitude[2]")), "sigma", "sigma_attitude[2]"),
        (lambda: plots.imu_errors(res.nav.drop(columns="sigma_gyro_bias[1]")), "result", "sigma_gyro_bias[1]"),
        (lambda: plots.imu_errors(res, truth=run["meas"].drop(columns="gyro_bias_z_rad_s")), "truth", "gyro_bias_z_rad_s"),
        (lambda: plots.consistency(nis=res.measurements.drop(columns="rows")), "nis", "rows"),
        (lambda: plots.consistency(nees=pd.DataFrame({"time_s": [0.0]}), dof=3), "nees", "nees"),
        (lambda: plots.allan(pd.DataFrame({"tau_s": [1.0], "dev": [1.0], "dev_lo": [0.5]})), "table", "dev_hi"),
    ]
    for call, parameter, column in cases:
        with pytest.raises(an.InputError, match=column.replace("[", r"\[").replace("]", r"\]")) as e:
            call()
        assert e.value.parameter == parameter


def test_wrong_types_are_type_errors_naming_the_argument(run):
    arr = run["res"].nav.to_numpy()
    cases = [
        (lambda: plots.trajectory(arr), "nav"),
        (lambda: plots.trajectory(run["res"].nav, reference="truth.csv"), "reference"),
        (lambda: plots.errors(arr), "err"),
        (lambda: plots.errors(run["err"], sigma=arr), "sigma"),
        (lambda: plots.imu_errors(arr), "result"),
        (lambda: plots.imu_errors(run["res"], truth=arr), "truth"),
        (lambda: plots.consistency(nis=arr), "nis"),
        (lambda: plots.consistency(nees=arr, dof=3), "nees"),
        (lambda: plots.consistency(nees=pd.DataFrame({"time_s": [0.0], "nees": [1.0]}), dof=2.5), "dof"),
        (lambda: plots.allan(arr), "table"),
        (lambda: plots.allan(pd.DataFrame(), fit="fit"), "fit"),
        (lambda: plots.allan(pd.DataFrame(), angular="gyro"), "angular"),
        (lambda: plots.allan(pd.DataFrame(), unit="deg/h"), "unit"),
    ]
    for call, parameter in cases:
        with pytest.raises(TypeError, match=f"^{parameter}:"):
            call()


def test_bad_values_are_input_errors(run):
    res, err = run["res"], run["err"]
    nav = res.nav.copy()
    nav.loc[5, "lat_rad"] = np.inf
    with pytest.raises(an.InputError, match="lat_rad.*index 5") as e:
        plots.trajectory(nav)
    assert (e.value.parameter, e.value.index) == ("nav", 5)
    bad = err.copy()
    bad.loc[7, "psi_d_rad"] = -np.inf
    with pytest.raises(an.InputError, match="psi_d_rad.*index 7") as e:
        plots.errors(bad)
    assert (e.value.parameter, e.value.index) == ("err", 7)
    meas = res.measurements.copy()
    meas.loc[2, "rows"] = 0
    with pytest.raises(an.InputError, match="rows.*index 2") as e:
        plots.consistency(nis=meas)
    assert (e.value.parameter, e.value.index) == ("nis", 2)
    with pytest.raises(an.InputError) as e:
        plots.consistency(nees=pd.DataFrame({"time_s": [0.0], "nees": [1.0]}))
    assert e.value.parameter == "dof"
    with pytest.raises(an.InputError) as e:
        plots.consistency()
    assert e.value.parameter == "nis"
    with pytest.raises(an.InputError) as e:
        plots.consistency(nis=res, dof=3)  # the NIS's degrees of freedom are its rows
    assert e.value.parameter == "dof"
    meas = meas.astype({"rows": float})
    meas.loc[2, "rows"] = 1e30
    with pytest.raises(an.InputError, match="rows.*index 2") as e:
        plots.consistency(nis=meas)
    assert (e.value.parameter, e.value.index) == ("nis", 2)
    with pytest.raises(an.InputError) as e:
        plots.consistency(nis=res, p=1.0)
    assert e.value.parameter == "p"
    with pytest.raises(an.InputError) as e:
        plots.allan(an.noise.allan.allan_variance(np.arange(100.0), 1.0), unit=-1.0)
    assert e.value.parameter == "unit"
    empty = res.nav.copy()
    empty[["lat_rad", "lon_rad", "h_m"]] = np.nan
    with pytest.raises(an.InputError, match="no row has a position") as e:
        plots.trajectory(empty)
    assert e.value.parameter == "nav"


def test_longitude_in_degrees_warns_naming_the_argument(run):
    nav = run["res"].nav.copy()
    nav["lon_rad"] = np.degrees(nav["lon_rad"]) + 30.0  # degrees, beyond 2π
    with pytest.warns(an.UnitWarning, match="^reference") as rec:
        plots.trajectory(run["res"].nav, reference=nav)
    assert all(str(w.message).startswith("reference") for w in rec if issubclass(w.category, an.UnitWarning))


def test_import_atomnav_plots_does_not_load_matplotlib_or_scipy_stats():
    code = ("import sys, atomnav; atomnav.plots; "
            "print('matplotlib' in sys.modules, 'scipy.stats' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
    assert out == ["False", "False"]


def test_time_as_timedelta_is_its_seconds_and_datetime_is_a_type_error(run):
    err = run["err"]
    as_td = err.assign(time_s=pd.to_timedelta(err["time_s"], unit="s"))
    xy = line(plots.errors(as_td).axes[0], "error").get_xydata()
    np.testing.assert_allclose(xy[:, 0], err["time_s"], rtol=1e-12)
    as_date = err.assign(time_s=pd.Timestamp("2024-01-01") + pd.to_timedelta(err["time_s"], unit="s"))
    with pytest.raises(TypeError, match="^err: column 'time_s' holds datetimes"):
        plots.errors(as_date)
    meas = run["res"].measurements
    with pytest.raises(TypeError, match="^nis: column 'time_s' holds datetimes"):
        plots.consistency(nis=meas.assign(time_s=pd.Timestamp("2024-01-01") + pd.to_timedelta(meas["time_s"], unit="s")))


def test_the_docs_images_script_runs_and_keeps_each_image_small(tmp_path, monkeypatch):
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parent.parent / "docs" / "make_plot_images.py"
    spec = importlib.util.spec_from_file_location("make_plot_images", path)
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    monkeypatch.setattr(script, "OUT", tmp_path)
    script.main()
    images = sorted(p.name for p in tmp_path.iterdir())
    assert images == [f"plots_{n}.png" for n in ("allan", "campaign_error_map", "campaign_error_vs_parameter", "campaign_throughput",
                                                 "consistency", "errors", "imu_errors", "spp", "trajectory")]
    assert max(p.stat().st_size for p in tmp_path.iterdir()) < 100_000


def test_spp_plot_shows_the_sky_the_residuals_and_the_enu_error():
    """On a real station file (DELF, RINEX 2.11): the sky plot's points are the satellite
    table's look angles (radius 90° − elevation), the residual lines its residuals, and the
    E/N/U lines the solution minus the reference rotated by a local-level frame written
    here (Groves 2013, Eq. 2.150)."""
    import warnings
    from pathlib import Path

    from atomnav.gnss import rinex

    d = Path(__file__).parent / "data" / "rinex_stations"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        eph = rinex.read_nav(d / "brdc0010_cut.21n.gz")
        obs = rinex.read_obs(d / "delf0010_cut.21o.gz", eph)
    r = an.gnss.solve(eph, obs.table)
    ref = np.array([3924687.7020, 301132.7660, 5001910.7750])
    fig = plots.spp(r, ref)
    sky, counts, res, enu = (fig.axes[i] for i in range(4))
    seen = r.satellites[np.isfinite(r.satellites["elevation_rad"])]
    first = seen[seen["sat"] == sorted(seen["sat"].unique())[0]]
    used = first[first["used"]]
    np.testing.assert_allclose(sky.lines[0].get_ydata(), 90.0 - np.degrees(used["elevation_rad"]))
    np.testing.assert_allclose(res.lines[0].get_ydata(), used["residual_m"])
    lat, lon = np.arctan2(ref[2], np.hypot(ref[0], ref[1]) * (1 - 6.69437999014e-3)), np.arctan2(ref[1], ref[0])
    east = np.array([-np.sin(lon), np.cos(lon), 0.0])
    up = np.array([np.cos(lat) * np.cos(lon), np.cos(lat) * np.sin(lon), np.sin(lat)])
    d_xyz = r.epochs[["x_m", "y_m", "z_m"]].to_numpy() - ref
    np.testing.assert_allclose(enu.lines[0].get_ydata(), d_xyz @ east, atol=1e-9)
    np.testing.assert_allclose(enu.lines[2].get_ydata(), d_xyz @ up, atol=1e-3)   # geodetic vs the formula's latitude
    assert [t.get_text() for t in counts.get_yticklabels()] == list(an.gnss.spp.EXCLUSIONS)
    plt.close(fig)
    with pytest.raises(an.InputError) as e:
        plots.spp(r, [1.0, 2.0, 3.0])
    assert e.value.parameter == "reference"
    with pytest.raises(TypeError):
        plots.spp(r.epochs)
