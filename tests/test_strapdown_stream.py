"""Streaming strapdown as a user drives it: record-wide row numbers across chunks,
divergence carrying the rows computed before it, restarting from a state, options
checked by the core, keyword-only options."""

import re

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav import _core
from atomnav.strapdown import Strapdown, integrate
from atomnav.trajectory import COLUMNS, IMU_COLUMNS


@pytest.fixture(scope="module")
def traj():
    return an.trajectory.sinusoidal(120.0, rate_hz=100.0)


def _diverging(growth_from=6000, seconds=1400.0):
    """A stationary record whose x specific force grows tenfold every 8 samples from row
    `growth_from` (finite, so the input checks pass): the solution overflows ~1200 rows later."""
    long = an.trajectory.stationary(seconds, 10.0)
    imu = long.ideal_imu("increments")
    imu["dv_x_mps"] += 10.0 ** np.minimum(np.maximum(np.arange(len(imu)) - growth_from, 0) / 8.0, 300.0)
    return long, imu


def test_chunks_are_numbered_in_the_record(traj):
    imu = traj.ideal_imu("increments").iloc[:9000]
    sd = Strapdown(**traj.initial_state())
    parts = [sd.run(imu.iloc[i:i + 2500]) for i in range(0, len(imu), 2500)]
    assert [p.index[0] for p in parts] == [0, 2500, 5000, 7500]
    pd.testing.assert_frame_equal(pd.concat(parts), integrate(imu, **traj.initial_state()))


def test_bad_row_in_a_later_chunk_names_its_record_row(traj):
    imu = traj.ideal_imu("increments").iloc[:6000].reset_index(drop=True)
    imu.loc[5321, "dtheta_z_rad"] = np.inf
    sd = Strapdown(**traj.initial_state())
    sd.run(imu.iloc[:3000])
    with pytest.raises(an.InputError, match=r"dtheta_z_rad.*index 5321") as info:
        sd.run(imu.iloc[3000:])
    assert (info.value.parameter, info.value.index) == ("imu", 5321)


def test_streaming_divergence_raises_with_the_rows_before_it():
    long, imu = _diverging()
    sd = Strapdown(**long.initial_state())
    first = sd.run(imu.iloc[:5000])
    with pytest.raises(an.NumericalError) as info:
        sd.run(imu.iloc[5000:])
    err = info.value
    k = int(re.search(r"diverged at sample (\d+)", str(err)).group(1))
    assert err.row == k and 6000 < k < len(imu)
    assert err.time_s == imu["time_s"].iloc[k]
    partial = err.partial
    assert list(partial.columns) == COLUMNS
    assert partial.index[0] == 5000 and partial.index[-1] == k - 1
    # independent of the failing run: the record cut before the failing sample runs
    # through, and the two chunks' rows are its rows
    whole = integrate(imu.iloc[:k], **long.initial_state())
    pd.testing.assert_frame_equal(pd.concat([first, partial]), whole)


def test_integrate_divergence_names_row_and_time(monkeypatch):
    long, imu = _diverging()
    monkeypatch.setattr(an.strapdown, "CHUNK", 4000)
    with pytest.raises(an.NumericalError) as info:
        integrate(imu, **long.initial_state(), progress=False)
    err = info.value
    assert err.time_s == imu["time_s"].iloc[err.row]
    assert len(err.partial) == err.row and err.partial.index[-1] == err.row - 1
    pd.testing.assert_frame_equal(err.partial, integrate(imu.iloc[:err.row], **long.initial_state()))


def _fault_at(k: int):
    """A 200 s stationary record at 100 Hz and its copy with an absurd (finite) velocity
    increment of 1e308 m/s on every axis at row ``k``: the velocity of that step
    overflows, so the solution diverges exactly at row ``k`` and nowhere before."""
    long = an.trajectory.stationary(200.0, 100.0)
    clean = long.ideal_imu("increments")
    bad = clean.copy()
    bad.loc[k, ["dv_x_mps", "dv_y_mps", "dv_z_mps"]] = 1e308
    return long, clean, bad


def _init(row: pd.DataFrame) -> dict:
    """Constructor arguments of a Strapdown starting from a one-row solution."""
    return dict(t0=row["time_s"].item(), lla=row[COLUMNS[1:4]].to_numpy()[0], vel_ned=row[COLUMNS[4:7]].to_numpy()[0],
                q_nb=row[COLUMNS[7:11]].to_numpy()[0])


@pytest.mark.parametrize("k", [5000, 6234, 9999])  # first, inner and last row of the second chunk
def test_divergence_at_a_known_row_of_a_later_chunk(k):
    """Streaming in chunks of 5000 rows, a fault at record row ``k`` (second chunk) raises
    with ``.row == k``, ``.time_s`` its time stamp and ``.partial`` the DataFrame a normal
    run returns for that chunk up to the last row before the fault (record rows 5000…k−1):
    together with the first chunk, the clean record's rows 0…k−1 bit for bit. ``reset``
    to the last good row and going on with the clean samples equals a fresh object
    started from that row, bit for bit."""
    long, clean, bad = _fault_at(k)
    sd = Strapdown(**long.initial_state())
    first = sd.run(bad.iloc[:5000])
    with pytest.raises(an.NumericalError, match=f"diverged at sample {k} ") as info:
        sd.run(bad.iloc[5000:10000])
    err = info.value
    assert (err.row, err.time_s) == (k, bad["time_s"].iloc[k])
    assert isinstance(err.partial, pd.DataFrame) and list(err.partial.columns) == COLUMNS
    assert err.partial.index.equals(pd.RangeIndex(5000, k))  # last index k - 1, the last finite row
    before = pd.concat([first, err.partial])
    pd.testing.assert_frame_equal(before, integrate(clean.iloc[:k], **long.initial_state()), check_exact=True)
    last = before.iloc[[-1]]
    sd.reset(last)
    again = sd.run(clean.iloc[k:12000])
    fresh = Strapdown(**_init(last)).run(clean.iloc[k:12000])
    pd.testing.assert_frame_equal(again, fresh, check_exact=True)
    assert again.index.equals(pd.RangeIndex(0, 12000 - k)) and np.isfinite(again.to_numpy()).all()


@pytest.mark.parametrize("k", [4000, 6234])  # first row of the second call into the core, and inside it
def test_integrate_diverges_at_the_known_record_row(monkeypatch, k):
    """The batch run over calls of 4000 rows: ``.row == k`` record-wide, ``.partial`` the
    clean record's rows 0…k−1 bit for bit."""
    long, clean, bad = _fault_at(k)
    monkeypatch.setattr(an.strapdown, "CHUNK", 4000)
    with pytest.raises(an.NumericalError) as info:
        integrate(bad, **long.initial_state(), progress=False)
    err = info.value
    assert (err.row, err.time_s) == (k, bad["time_s"].iloc[k])
    pd.testing.assert_frame_equal(err.partial, integrate(clean.iloc[:k], **long.initial_state()), check_exact=True)


@pytest.mark.parametrize("kind", ["rates", "increments"])
@pytest.mark.parametrize("as_dict", [False, True])
def test_reset_equals_a_fresh_object(traj, kind, as_dict):
    imu = traj.ideal_imu(kind).iloc[:8000].reset_index(drop=True)
    sd = Strapdown(**traj.initial_state(), kind=kind, vertical="damped", zeta=0.6, omega=0.02)
    h = traj.df["h_m"].to_numpy()[: len(imu)] + 3.0
    nav = sd.run(imu.iloc[:5000], h_ref=h[:5000])
    k = 4321
    row = nav.loc[[k]]
    state = row if not as_dict else {"t0": row["time_s"].item(), "lla": row[["lat_rad", "lon_rad", "h_m"]].to_numpy()[0],
                                     "vel_ned": row[["vn_mps", "ve_mps", "vd_mps"]].to_numpy()[0],
                                     "q_nb": row[["qw", "qx", "qy", "qz"]].to_numpy()[0]}
    sd.reset(state)
    # with rates the sample at the restart time primes the integrator again
    rest = slice(k, None) if kind == "rates" else slice(k + 1, None)
    again = sd.run(imu.iloc[rest], h_ref=h[rest])
    init = dict(t0=row["time_s"].item(), lla=row[["lat_rad", "lon_rad", "h_m"]].to_numpy()[0],
                vel_ned=row[["vn_mps", "ve_mps", "vd_mps"]].to_numpy()[0], q_nb=row[["qw", "qx", "qy", "qz"]].to_numpy()[0])
    fresh = Strapdown(**init, kind=kind, vertical="damped", zeta=0.6, omega=0.02).run(imu.iloc[rest], h_ref=h[rest])
    pd.testing.assert_frame_equal(again, fresh, check_exact=True)
    assert again.index[0] == 0


def test_reset_after_divergence_continues():
    long, imu = _diverging(growth_from=2000, seconds=400.0)
    sd = Strapdown(**long.initial_state())
    with pytest.raises(an.NumericalError):
        sd.run(imu)
    sd.reset(long.initial_state())
    pd.testing.assert_frame_equal(sd.run(imu.iloc[:1500]), integrate(imu.iloc[:1500], **long.initial_state()))


@pytest.mark.parametrize("state, why", [
    (dict(q_nb=[1.0 + 2e-6, 0, 0, 0]), "norm"),
    (dict(lla=[1.5708, 0.0, 0.0]), "latitude"),
    (dict(lla=[0.3, 0.0, -1.1e4]), "height"),
    (dict(lla=[0.3, 0.0, 1.1e6]), "height"),
    (dict(vel_ned=[0.0, np.nan, 0.0]), "non-finite"),
    (dict(q_nb=[1.0, 0.0, 0.0]), r"shape \(4,\)"),
])
def test_reset_rejects_a_bad_state_and_changes_nothing(traj, state, why):
    sd = Strapdown(**traj.initial_state())
    before = sd.state()
    with pytest.raises(an.InputError, match=why) as info:
        sd.reset({**traj.initial_state(), **state})
    assert info.value.parameter == "state"
    pd.testing.assert_frame_equal(sd.state(), before)


def test_reset_rejects_missing_fields_and_wrong_types(traj):
    sd = Strapdown(**traj.initial_state())
    with pytest.raises(an.InputError, match="state.*missing.*q_nb"):
        sd.reset({k: v for k, v in traj.initial_state().items() if k != "q_nb"})
    with pytest.raises(an.InputError, match="state.*one row"):
        sd.reset(pd.concat([sd.state(), sd.state()]))
    with pytest.raises(TypeError, match="state"):
        sd.reset([0.0, 1.0])


@pytest.mark.parametrize("option, value", [("kind", "samples"), ("ellipsoid", "GRS67"), ("vertical", "baro")])
def test_one_bad_value_per_option_is_rejected_by_the_core(traj, option, value):
    with pytest.raises(an.InputError, match=f"{option}: unknown option") as info:
        Strapdown(**traj.initial_state(), **{option: value})
    assert info.value.parameter == option
    with pytest.raises(TypeError, match="str"):
        Strapdown(**traj.initial_state(), **{option: 3})


@pytest.mark.parametrize("name", ["zeta", "omega"])
def test_baro_loop_gains_must_be_positive(traj, name):
    # the error names the gain the caller gave, not the option that enables the loop
    with pytest.raises(an.InputError, match=f"{name}: the baro loop's .* must be finite and > 0.*, got -1") as info:
        Strapdown(**traj.initial_state(), vertical="damped", **{name: -1.0})
    assert info.value.parameter == name


def test_option_lists_come_from_the_core():
    assert _core.OPTIONS["Vertical"] == ["free", "damped"]
    assert sorted(IMU_COLUMNS) == sorted(_core.OPTIONS["ImuKind"])
    assert _core.NAV_COLUMNS == COLUMNS


def test_options_are_keyword_only(traj):
    init = traj.initial_state()
    args = (init["t0"], init["lla"], init["vel_ned"], init["q_nb"])
    with pytest.raises(TypeError):
        Strapdown(*args, "rates")
    with pytest.raises(TypeError):
        integrate(traj.ideal_imu("rates"), *args, "rates")
    with pytest.raises(TypeError):
        _core.Strapdown(*args, "rates")
    with pytest.raises(TypeError):
        an.diagnostics.stationary_errors(0.0, 0.1, 10.0)


def test_default_baro_loop_is_the_cores(traj):
    """zeta/omega left out: the core's 0.707 and 0.01 rad/s, as if given."""
    imu = traj.ideal_imu("increments").iloc[:3000]
    h = traj.df["h_m"].to_numpy()[1:3001] + 5.0
    a = integrate(imu, **traj.initial_state(), vertical="damped", h_ref=h)
    b = integrate(imu, **traj.initial_state(), vertical="damped", h_ref=h, zeta=0.707, omega=0.01)
    pd.testing.assert_frame_equal(a, b, check_exact=True)


def test_any_memory_layout_gives_the_same_rows(traj):
    """The core reads C- and Fortran-ordered arrays in place and copies others: same rows."""
    imu = traj.ideal_imu("rates").iloc[:5000]
    want = integrate(imu, **traj.initial_state(), kind="rates")
    c_order = np.ascontiguousarray(imu[IMU_COLUMNS["rates"]].to_numpy())
    pd.testing.assert_frame_equal(integrate(c_order, **traj.initial_state(), kind="rates"), want)
    sd = _core.Strapdown(*traj.initial_state().values(), kind="rates")
    t, g, a = c_order[:, 0].copy(), c_order[:, 1:4], c_order[:, 4:7]  # strided views
    np.testing.assert_array_equal(sd.run(t, g, np.ascontiguousarray(a)).T, want.to_numpy())


def test_first_index_out_of_range_is_an_input_error(traj):
    sd = _core.Strapdown(*traj.initial_state().values())
    imu = traj.ideal_imu("increments").to_numpy()[:10]
    with pytest.raises(an.InputError, match="first_index"):
        sd.run(imu[:, 0], imu[:, 1:4], imu[:, 4:7], None, -1)
    with pytest.raises(an.InputError, match="first_index"):
        sd.run(imu[:, 0], imu[:, 1:4], imu[:, 4:7], None, 2**70)
