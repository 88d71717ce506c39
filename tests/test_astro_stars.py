"""Star-camera front end (spec E9–E13, D4, D13): simulator, refraction, Wahba, P^avu."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from atomnav import astro, units

AS = units.ARCSEC


@pytest.fixture(scope="module")
def scn():
    return astro.Vasilyuk2024().truth()


def _simulate(tr, sigma, seed, n_refr=None):
    cat = astro.Catalog(tr["catalog_dirs"], tr["catalog_mags"], np.arange(len(tr["catalog_mags"])))
    return astro.simulate_observations(cat, tr["s_gcrs_vf"], tr["up_gcrs"], tr["cameras"], fov_half_rad=tr["fov_half"],
                                       m_lim=tr["m_lim"], sigma_s_rad=sigma, n_refr=tr["n_refr"] if n_refr is None else n_refr,
                                       seed=seed)


def test_catalog_is_deterministic_with_the_d4_count():
    a, b = astro.synthetic_catalog(5.6, 3), astro.synthetic_catalog(5.6, 3)
    assert len(a.mags) == round(10 ** (0.985 + 0.455 * 5.6)) == 3412
    assert np.array_equal(a.dirs, b.dirs) and a.mags.max() <= 5.6
    assert np.abs(np.linalg.norm(a.dirs, axis=1) - 1).max() < 1e-15


def test_refraction_matches_snell_and_round_trips():
    n = astro.refractive_index(150.0)
    assert n - 1 == pytest.approx(2.7385e-4, rel=1e-4)
    z = np.radians([10.0, 30.0, 45.0, 60.0, 80.0])
    true = np.column_stack([np.sin(z), np.zeros_like(z), np.cos(z)])
    up = np.tile([0.0, 0.0, 1.0], (len(z), 1))
    app = astro.refraction_apply(true, up, n)
    z_app = np.arctan2(np.hypot(app[:, 0], app[:, 1]), app[:, 2])
    assert np.abs(z_app - np.arcsin(np.sin(z) / n)).max() / AS < 1e-6  # Snell: sin z = n sin z_obs
    assert np.abs(astro.refraction_correct(app, up, n) - true).max() < 1e-15


def test_noise_free_stars_give_the_true_attitudes(scn):
    obs = _simulate(scn, 0.0, 1)
    s, p, count = astro.star_attitudes(obs, len(scn["epochs"]), scn["cameras"], 16 * AS, up_gcrs=scn["up_gcrs"],
                                       n_refr=scn["n_refr"])
    err = Rotation.from_matrix(np.einsum("nji,njk->nik", scn["s_gcrs_vf"], s)).magnitude()
    assert err.max() < 1e-12
    assert 100 <= count.mean() <= 120 and count.min() >= 3  # spec row 16: 108.7 per epoch


def test_attitude_covariance_model_is_consistent(scn):
    # spec row 17: mean χ² of θ^avu under P^avu = σ_s² K is ≈ 3 (Monte Carlo over noise seeds)
    chi2 = []
    for seed in range(6):
        obs = _simulate(scn, 16 * AS, 100 + seed)
        s, p, _ = astro.star_attitudes(obs, len(scn["epochs"]), scn["cameras"], 16 * AS, up_gcrs=scn["up_gcrs"],
                                       n_refr=scn["n_refr"])
        th = Rotation.from_matrix(np.einsum("nji,njk->nik", scn["s_gcrs_vf"], s)).as_rotvec()
        chi2.append(np.einsum("ni,nij,nj->n", th, np.linalg.inv(p), th))
    assert np.mean(chi2) == pytest.approx(3.0, abs=0.25)


def test_astro_increments_compose_and_propagate(scn):
    s = scn["s_gcrs_vf"][:4]
    p = np.stack([np.diag([1.0, 2.0, 3.0]) * 1e-10] * 4)
    ds, e = astro.astro_increments(s, p)
    assert np.abs(s[:-1] @ ds - s[1:]).max() < 1e-15
    assert np.allclose(e[0], p[1] + ds[0].T @ p[0] @ ds[0], rtol=1e-14, atol=0)


def test_user_catalog_from_file(tmp_path):
    f = tmp_path / "cat.csv"
    f.write_text("id,ra_deg,dec_deg,mag\n1,0,0,1.5\n2,90,0,2.0\n3,0,90,3.1\n")
    cat = astro.load_catalog(f)
    assert np.allclose(cat.dirs, np.eye(3), atol=1e-15) and list(cat.ids) == [1, 2, 3]
    assert np.allclose(cat.mags, [1.5, 2.0, 3.1])


def _three_stars():
    g = np.eye(3)
    return astro.Observations(epoch=np.array([0, 0, 0, 1, 1, 1]), camera=np.zeros(6, dtype=np.int64),
                              s_cf=np.vstack([g, g]), g=np.vstack([g, g]))


def test_fewer_than_three_stars_rejected():
    o = _three_stars()
    o = astro.Observations(o.epoch[:5], o.camera[:5], o.s_cf[:5], o.g[:5])
    with pytest.raises(ValueError, match="obs: epoch at index 1 has 2 stars"):
        astro.star_attitudes(o, 2, np.eye(3)[None], 16 * AS)


def test_non_unit_direction_rejected():
    o = _three_stars()
    o.s_cf[4] *= 1.01
    with pytest.raises(ValueError, match="obs: not a unit vector at index 4"):
        astro.star_attitudes(o, 2, np.eye(3)[None], 16 * AS)


def test_camera_not_a_rotation_rejected():
    cams = np.stack([np.eye(3), np.diag([1.0, 1.0, -1.0])])
    with pytest.raises(ValueError, match="cameras.*not a rotation matrix at index 1"):
        astro.star_attitudes(_three_stars(), 2, cams, 16 * AS)


def test_aberration_matches_exact_relativistic_formula():
    # Oracle: special relativity, cos θ' = (cos θ + β)/(1 + β cos θ) for the angle θ between
    # the geometric direction and the observer velocity (Einstein 1905 §7); first order
    # θ − θ' = β sin θ. Earth's orbital speed, β ≈ 1e-4: agreement to O(β²).
    v = np.array([0.0, 0.0, 29_780.0])
    beta = np.linalg.norm(v) / 299_792_458.0
    th = np.radians([5.0, 30.0, 60.0, 90.0, 120.0, 175.0])
    lam = np.radians([0.0, 40.0, 100.0, 200.0, 290.0, 330.0])
    s = np.column_stack([np.sin(th) * np.cos(lam), np.sin(th) * np.sin(lam), np.cos(th)])
    app = astro.aberration(s, v)
    th_app = np.arccos(np.clip(app[:, 2], -1, 1))
    exact = np.arccos((np.cos(th) + beta) / (1 + beta * np.cos(th)))
    assert np.abs(th_app - exact).max() < beta ** 2
    assert np.abs((th - th_app) - beta * np.sin(th)).max() < beta ** 2
    assert np.abs(np.arctan2(app[:, 1], app[:, 0]) - np.arctan2(s[:, 1], s[:, 0])).max() < 1e-12  # toward v only
    # per-row velocities give the same answer
    assert np.abs(astro.aberration(s, np.tile(v, (len(s), 1))) - app).max() == 0.0


def test_aberration_rejects_relativistic_velocity():
    with pytest.raises(ValueError, match="velocity.*index 0"):
        astro.aberration(np.eye(3), [0.0, 0.0, 1e6])


def test_aberration_rejects_non_unit_direction():
    with pytest.raises(ValueError, match="directions.*not a unit vector at index 1"):
        astro.aberration(np.array([[1.0, 0, 0], [0, 1.1, 0]]), [0.0, 0.0, 3e4])


@pytest.fixture(scope="module")
def run7():
    return astro.Vasilyuk2024().run(7)


def _attitudes(tr, r, **kw):
    return astro.star_attitudes(r["observations"], len(tr["epochs"]), tr["cameras"], tr["sigma_s"],
                                up_gcrs=tr["up_gcrs"], n_refr=tr["n_refr"], **kw)


def test_user_p_avu_replaces_default_and_drives_p_beta(scn, run7):
    r, cal = run7, run7["calibration"]
    s, p_def, _ = _attitudes(scn, r)
    # the Python model_covariance reproduces the scenario's P_β^model from the default P^avu
    pb_def, _ = astro.model_covariance(cal, r["ds_imu"], r["ds_avu"], r["e_imu"], p_def)
    assert np.allclose(pb_def, r["p_beta_model"], rtol=1e-10, atol=0)
    # a user P^avu: the default plus (10″)² about the VF z axis at every epoch
    extra = np.zeros_like(p_def)
    extra[:, 2, 2] = (10 * AS) ** 2
    s_u, p_u, _ = _attitudes(scn, r, p_avu=p_def + extra)
    assert np.array_equal(p_u, p_def + extra) and np.array_equal(s_u, s)
    ds_avu, e_avu = astro.astro_increments(s_u, p_u)
    want = extra[1:] + np.einsum("nji,njk,nkl->nil", ds_avu, extra[:-1], ds_avu)
    assert np.abs(e_avu - r["e_avu"] - want).max() < 1e-9 * np.abs(want).max()
    pb_u, _ = astro.model_covariance(cal, r["ds_imu"], ds_avu, r["e_imu"], p_u)
    # predicted change: P_β^model is linear in (E^imu, P^avu), so the increase is exactly the
    # P_β^model of the added term alone, positive semi-definite, and doubling P^avu doubles it
    zero = np.zeros_like(r["e_imu"])
    pb_extra, _ = astro.model_covariance(cal, r["ds_imu"], ds_avu, zero, extra)
    assert np.allclose(pb_u - pb_def, pb_extra, rtol=1e-8, atol=1e-12 * np.abs(pb_extra).max())
    assert np.linalg.eigvalsh(pb_extra).min() > -1e-12 * np.abs(pb_extra).max()
    assert np.all(np.diag(pb_u) > np.diag(pb_def) * 1.1)
    pb2, _ = astro.model_covariance(cal, r["ds_imu"], ds_avu, zero, 2 * extra)
    assert np.allclose(pb2, 2 * pb_extra, rtol=1e-12, atol=0)
    # P^mfa of a new fix uses it as well (Eq. 8)
    assert np.allclose(cal.p_mfa(p_u[0]) - cal.p_mfa(p_def[0]), cal.c @ extra[0] @ cal.c.T, rtol=1e-12, atol=0)


def _bad_p_avu(scn, run7, p, match):
    with pytest.raises(ValueError, match=match):
        _attitudes(scn, run7, p_avu=p)


def test_user_p_avu_wrong_shape_rejected(scn, run7):
    _bad_p_avu(scn, run7, np.tile(np.eye(3) * 1e-10, (72, 1, 1)), "p_avu: expected 73 covariances, got 72")


def test_user_p_avu_non_finite_rejected(scn, run7):
    p = np.tile(np.eye(3) * 1e-10, (73, 1, 1))
    p[4, 1, 1] = np.nan
    _bad_p_avu(scn, run7, p, "p_avu: non-finite value NaN at index 4")


def test_user_p_avu_not_symmetric_rejected(scn, run7):
    p = np.tile(np.eye(3) * 1e-10, (73, 1, 1))
    p[5, 0, 1] = 1e-11
    _bad_p_avu(scn, run7, p, "p_avu: not symmetric.*at index 5")


def test_user_p_avu_not_psd_rejected(scn, run7):
    p = np.tile(np.eye(3) * 1e-10, (73, 1, 1))
    p[2] = np.array([[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]]) * 1e-10
    _bad_p_avu(scn, run7, p, "p_avu: not positive semi-definite.*at index 2")


def test_named_results_unpack_and_pickle(scn):
    import copy
    import pickle

    obs = _simulate(scn, 16 * AS, 3)
    att = astro.star_attitudes(obs, len(scn["epochs"]), scn["cameras"], 16 * AS, up_gcrs=scn["up_gcrs"], n_refr=scn["n_refr"])
    assert isinstance(att, astro.StarAttitudes)
    s, p, count = att  # unpacks in the old tuple order
    assert s is att.s_gcrs_vf and p is att.p_avu and count is att.stars
    inc = astro.astro_increments(att.s_gcrs_vf, att.p_avu)
    ds, e = inc
    assert isinstance(inc, astro.AstroIncrements) and ds is inc.ds_avu and e is inc.e_avu
    assert np.abs(att.s_gcrs_vf[:-1] @ inc.ds_avu - att.s_gcrs_vf[1:]).max() < 1e-14
    for obj in (att, inc):
        for back in (pickle.loads(pickle.dumps(obj)), copy.deepcopy(obj)):
            assert type(back) is type(obj)
            for a, b in zip(obj, back):
                assert a.dtype == b.dtype and np.array_equal(a, b)
