"""The astro boundary never kills the Python process: counts and seeds from input are
checked before anything is sized from them, validity checks (rotations, the aberration
limit, refraction index) live in the core, and every option name is checked by the core
under the caller's parameter name."""

from __future__ import annotations

import numpy as np
import pytest

import atomnav
from atomnav import _core, astro

AS = np.pi / 180 / 3600
G = np.eye(3)


def _obs():
    return astro.Observations(epoch=np.zeros(3, dtype=np.int64), camera=np.zeros(3, dtype=np.int64), s_cf=G.copy(), g=G.copy())


def _input_error(parameter, fn, *args, index=None, **kw):
    with pytest.raises(atomnav.InputError) as e:
        fn(*args, **kw)
    assert (e.value.parameter, e.value.index) == (parameter, index), str(e.value)
    return e.value


def test_huge_epoch_count_is_checked_before_allocation():
    s, p, k = astro.star_attitudes(_obs(), 1, G[None], 16 * AS)
    assert s.shape == (1, 3, 3) and list(k) == [3]
    e = _input_error("obs", astro.star_attitudes, _obs(), 2**62, G[None], 16 * AS)
    assert "epoch at index 1 has 0 stars" in str(e)
    for n in (2**64, -1, 0):
        _input_error("n_epochs", astro.star_attitudes, _obs(), n, G[None], 16 * AS)


def test_aberration_limit_in_the_core():
    v = np.array([[0.0, 0.0, 3e4], [0.0, 0.0, 3.1e5]])
    e = _input_error("velocity_mps", astro.aberration, np.vstack([G[:2]]), v, index=1)
    assert "1e-3 c" in str(e)


def test_refraction_index_and_rotations_in_the_core():
    _input_error("n", astro.refraction_correct, G, G, 0.5)
    bad = np.stack([G, np.diag([1.0, 1.0, -1.0])])
    _input_error("c", astro.euler_from_dcm, bad, index=1)
    _input_error("ds_avu", astro.observability, bad, index=1)


@pytest.mark.parametrize("seed", [-1, 2**64])
def test_seeds_outside_u64_are_input_errors(seed):
    _input_error("seed", astro.synthetic_catalog, 5.6, seed)
    _input_error("catalog_seed", _core.AstroScenario, seed)


def test_full_u64_seed_range_accepted():
    a = astro.synthetic_catalog(2.0, 2**64 - 1)
    assert len(a.mags) == round(10 ** (0.985 + 0.455 * 2.0))


@pytest.fixture(scope="module")
def scn():
    return astro.Vasilyuk2024()


def test_scenario_counts_and_options(scn):
    _input_error("runs", scn.monte_carlo, -1)
    _input_error("runs", scn.monte_carlo, 2**64)
    _input_error("seed0", scn.monte_carlo, 1, seed0=-1)
    _input_error("seed", scn.run, 2**64)
    _input_error("p_diff", scn.run, 1, p_diff="diagonal")
    _input_error("p_diff", scn.monte_carlo, 1, p_diff="diagonal")
    _input_error("init", scn.run, 1, init="given")  # "given" needs c0, which a scenario run has not
    _input_error("init", scn.run, 1, init="identity")


def _increments():
    rng = np.random.default_rng(1)
    ds = np.array([np.linalg.qr(rng.normal(size=(3, 3)))[0] for _ in range(6)])
    return ds * np.sign(np.linalg.det(ds))[:, None, None]


BAD_OPTIONS = [
    ("init", lambda ds: astro.calibrate(ds, ds, init="closest")),
    ("solver", lambda ds: astro.calibrate(ds, ds, solver="lm")),
    ("residual_form", lambda ds: astro.calibrate(ds, ds, residual_form="block")),
    ("c0", lambda ds: astro.calibrate(ds, ds, init="given")),
    ("max_iter", lambda ds: astro.calibrate(ds, ds, max_iter=0)),
    ("max_iter", lambda ds: astro.calibrate(ds, ds, max_iter=2**64)),
    ("gyro_error_model", lambda ds: astro.Vasilyuk2024(gyro_error_model="white")),
    ("taylor_variant", lambda ds: astro.gyro_increments(0.0, 0.005, np.zeros((10, 3)), [0.01, 0.02],
                                                        astro.GyroErrorModel.vasilyuk2024(), taylor_variant="exact")),
]


@pytest.mark.parametrize("parameter, call", BAD_OPTIONS, ids=[f"{p}-{i}" for i, (p, _) in enumerate(BAD_OPTIONS)])
def test_bad_option_names_its_parameter(parameter, call):
    _input_error(parameter, call, _increments())


def test_keyword_only_options():
    ds = _increments()
    with pytest.raises(TypeError):
        astro.calibrate(ds, ds, "axes")
    assert _core.OPTIONS["DiffForm"] == ["full", "paper"]
    assert _core.OPTIONS["CalibrationSolver"] == ["so3", "paper_euler"]


def test_wrappers_name_their_own_parameters():
    up = np.array([[0.0, 0.0, 1.0]])
    _input_error("s", astro.refraction_apply, np.float64(3), up, 1.0003)
    with pytest.raises(TypeError, match="^height_m: "):
        astro.refractive_index("emulated")
    with pytest.raises(TypeError, match="^catalog: "):
        astro.simulate_observations(None, G[None], up, G[None], fov_half_rad=0.3, m_lim=5.0, sigma_s_rad=1e-5,
                                    n_refr=1.0, seed=1)
    with pytest.raises(TypeError, match="^dcm: "):
        atomnav.rotation.quat_from_dcm("soft")


def test_refractive_index_domain():
    # fuzz seed 20261202: H = -1e308 m returned inf; above the model's 44.3 km ceiling the
    # base of the power turned negative (NaN)
    with pytest.raises(atomnav.InputError) as e:
        atomnav._core.astro_refractive_index(height=-1e308)
    assert e.value.parameter == "height"
    with pytest.raises(atomnav.InputError) as e:
        astro.refractive_index(-2e4)
    assert e.value.parameter == "height_m"
    assert astro.refractive_index(5e4) == 1.0
    # n − 1 = 2.7783e-4 (1 − 2.25577e-5 H)^4.25588 at H = 1 km, by hand
    assert abs(astro.refractive_index(1000.0) - 1.0 - 2.7783e-4 * (1 - 2.25577e-2) ** 4.25588) < 1e-15


def test_file_names_with_nul_are_input_errors(tmp_path):
    # fuzz seed 13: numpy's "embedded null byte" ValueError
    for call in (lambda: astro.results.Calibration.load("\x00"), lambda: astro.load_catalog("a\x00b")):
        with pytest.raises(atomnav.InputError) as e:
            call()
        assert e.value.parameter == "path"
    with pytest.raises(TypeError, match="^path: "):
        astro.load_catalog(3)
