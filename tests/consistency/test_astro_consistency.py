"""Reported mount σ against the Monte-Carlo scatter of the calibrated mount angles on two
rotation programs unlike the paper's stand (Vasilyuk et al. 2024).

Each draw simulates the whole chain the user runs: gyro increments of a two-axis stand
(the motion of :func:`atomnav.trajectory.rotary_stand`, exact ideal IMU, 50 Hz) corrupted with the paper's gyro
budget (errors white per sample), star observations of the synthetic catalog through the
paper's three cameras, star attitudes by Wahba, increments and :func:`astro.calibrate`.
The criterion is std(β̂ − β̆) / RMS(√diag P_β) per Euler angle.

- "turntable": the turntable advances 150° every interval while the tilt follows
  20° sin(2πn/24): nearly the same large turn about a slowly swinging axis.
- "blocks": twelve blocks of five equal 20° turns, each block at its own tilt.

On both the paper's sandwich (independent increments) is off by up to 3× (turntable
heading) and 1.4× (blocks tilts); the neighbour correlation of increments that share a
star epoch accounts for it (docs/departures.md#correlated-increment-residuals).
"""

import numpy as np
import pytest

from atomnav import _core, astro
from atomnav.astro import NED_TO_ENU as T

SITE = (np.radians(55.6), np.radians(38.2), 150.0)
OMEGA_EARTH = 7.292115e-5  # rad/s, WGS84
PERIOD = 0.02  # s, 50 Hz gyro (the paper's 200 Hz takes 4× longer to simulate)
EPOCHS = 0.5023 + 21.0007 * np.arange(73)  # s, the paper's camera epochs


def _s_gcrs_enu(t):
    """S_GCRS^ENU(t) = R_z(Ωt)[E N U]_ECEF at the site (GCRS = ECEF at t = 0)."""
    lat, lon = SITE[:2]
    enu = np.array([[-np.sin(lon), -np.sin(lat) * np.cos(lon), np.cos(lat) * np.cos(lon)],
                    [np.cos(lon), -np.sin(lat) * np.sin(lon), np.cos(lat) * np.sin(lon)],
                    [0.0, np.cos(lat), np.sin(lat)]])
    c, s = np.cos(OMEGA_EARTH * t), np.sin(OMEGA_EARTH * t)
    rz = np.zeros((len(t), 3, 3))
    rz[:, 0, 0], rz[:, 0, 1], rz[:, 1, 0], rz[:, 1, 1], rz[:, 2, 2] = c, -s, s, c, 1.0
    return rz @ enu


def _turntable():
    n = np.arange(len(EPOCHS))
    return np.column_stack([20.0 * np.sin(2 * np.pi * n / 24), 150.0 * n])


def _blocks():
    tilts = [0.0, 15.0, -10.0, 5.0, -15.0, 10.0, 0.0, 12.0, -5.0, 15.0, -12.0, 8.0]
    states = [(tilts[0], 0.0)]
    for b, tilt in enumerate(tilts):
        states += [(tilt, states[-1][1] + 20.0 * (k + 1)) for k in range(5)]
        states.append((tilts[(b + 1) % len(tilts)], states[-1][1]))
    return np.array(states[:len(EPOCHS)])


def _stand(states_deg, move_starts, period):
    """Gyro increments ρ (K, 3) in MF (right-forward-up, rad) every ``period`` s from 0 and
    the stand attitudes C_ENU^MF (N, 3, 3) at the epochs."""
    m = _core.Motion.rotary_stand(np.array(SITE), np.radians(np.asarray(states_deg, float)), np.asarray(move_starts, float),
                                  12.0, EPOCHS[-1] + 0.5)
    times = np.arange(int((EPOCHS[-1] + 0.5) / period) + 1) * period
    rho = m.ideal_imu(times, "increments")["gyro"] @ T  # FRD → right-forward-up (T = Tᵀ)
    c_nb = np.array([_dcm(x) for x in m.truth(EPOCHS)["q_nb"]])
    return rho, T @ c_nb @ T


@pytest.fixture(scope="module")
def paper_truth():
    return astro.Vasilyuk2024().truth()


class _Program:
    """Truth of a stand program (tilt, turntable) in degrees, one state per epoch, each
    move of 12 s starting 4 s after an epoch; the paper's mount, cameras and catalog."""

    def __init__(self, states_deg, tr):
        self.truth = tr
        self.rho, c_enu_mf = _stand(states_deg, EPOCHS[:-1] + 4.0, PERIOD)
        self.s_gcrs_vf = _s_gcrs_enu(EPOCHS) @ c_enu_mf @ tr["c_true"]
        self.up = _s_gcrs_enu(EPOCHS)[:, :, 2]
        self.catalog = astro.Catalog(tr["catalog_dirs"], tr["catalog_mags"], np.arange(len(tr["catalog_mags"])))
        self.gyro = astro.GyroErrorModel.vasilyuk2024()
        self.beta_true = astro.euler_from_dcm(tr["c_true"])

    def draw(self, seed):
        """One noisy chain: gyro increments (paper budget, white per sample) and star attitudes."""
        rng = np.random.default_rng(seed)
        g, r2 = self.gyro, self.rho ** 2
        var = (g.sigma_k ** 2 * r2 + g.sigma_phi_rad ** 2 * (r2.sum(axis=1, keepdims=True) - r2)
               + (g.sigma_b_rad_s * PERIOD) ** 2 + g.sigma_w_rad_sqrt_s ** 2 * PERIOD)
        inc = astro.gyro_increments(0.0, PERIOD, self.rho + rng.standard_normal(self.rho.shape) * np.sqrt(var), EPOCHS, g)
        tr = self.truth
        obs = astro.simulate_observations(self.catalog, self.s_gcrs_vf, self.up, tr["cameras"], fov_half_rad=tr["fov_half"],
                                          m_lim=tr["m_lim"], sigma_s_rad=tr["sigma_s"], n_refr=tr["n_refr"],
                                          seed=int(rng.integers(2**63)))
        att = astro.star_attitudes(obs, len(EPOCHS), tr["cameras"], tr["sigma_s"], up_gcrs=self.up, n_refr=tr["n_refr"])
        return inc, astro.astro_increments(att.s_gcrs_vf, att.p_avu).ds_avu, att.p_avu


def _dcm(q):
    """C_nb of a scalar-first unit quaternion."""
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


PROGRAMS = {"turntable": _turntable, "blocks": _blocks}


@pytest.fixture(scope="module", params=sorted(PROGRAMS))
def program(request, paper_truth):
    return request.param, _Program(PROGRAMS[request.param](), paper_truth)


def _ratios(prog, draws):
    """scatter/σ per angle for the default σ without covariances ("residual") and with
    e_imu, p_avu ("model"), over ``draws`` fixed seeds."""
    err, sigma = [], {"residual": [], "model": []}
    for seed in range(draws):
        inc, ds_avu, p_avu = prog.draw(seed)
        cal = astro.calibrate(inc.dcm, ds_avu)
        with_cov = astro.calibrate(inc.dcm, ds_avu, e_imu=inc.cov, p_avu=p_avu)
        assert (cal.covariance, with_cov.covariance) == ("residual", "model")
        err.append(cal.beta - prog.beta_true)
        sigma["residual"].append(cal.sigma_beta_rad)
        sigma["model"].append(with_cov.sigma_beta_rad)
    sd = np.std(err, axis=0)
    return {k: sd / np.sqrt(np.mean(np.square(v), axis=0)) for k, v in sigma.items()}


def test_program_truth_is_the_papers_construction(paper_truth):
    # the builder above, run on the paper's stand, gives the scenario's own truth: its
    # attitudes, and its 200 Hz increments summed in fours (∫ω dt adds over sub-intervals)
    tr = paper_truth
    states = [(0.0, 50.0), (0.0, 170.0), (0.0, 90.0), (15.0, 90.0), (15.0, 245.0), (15.0, 297.0), (0.0, 297.0),
              (0.0, 240.0), (-7.0, 240.0), (-7.0, 110.0), (-7.0, 60.0), (0.0, 60.0), (0.0, 150.0)]
    rho, c_enu_mf = _stand(states, [EPOCHS[6 * j] + 4.0 for j in range(12)], PERIOD)
    k = len(rho)
    assert k == len(tr["rho_true"]) // 4 and tr["period"] * 4 == PERIOD
    assert np.abs(rho - tr["rho_true"][:4 * k].reshape(k, 4, 3).sum(axis=1)).max() < 1e-10  # quadrature of ∫ω dt
    assert np.abs(_s_gcrs_enu(EPOCHS) @ c_enu_mf @ tr["c_true"] - tr["s_gcrs_vf"]).max() < 1e-12


# The residual σ (no covariances given) of the heading on the turntable is conservative:
# the star part of the score telescopes along the turntable axis, the gyro part there is
# the difference of moments dominated by star noise, and where it makes P_θ indefinite
# the star part alone is reported (docs/departures.md#correlated-increment-residuals).
# Measured scatter/σ of that angle: 0.845 (200 draws, 50 Hz), 0.86–0.90 (200–600 draws at
# the paper's 200 Hz); its band below is [0.75, ·], every other band is the 3-sigma one.
def _check(name, ratios, band):
    for form, r in ratios.items():
        low = np.full(3, band[0])
        if (name, form) == ("turntable", "residual"):
            low[0] = min(band[0], 0.75)
        assert np.all((r > low) & (r < band[1])), (name, form, r)


# 100 draws: a scatter/σ ratio has a sampling spread of about 1/√(2·100) = 0.071, so the
# honest 3-sigma band is [0.79, 1.21]; the paper's sandwich reads 0.33 (turntable heading),
# 1.50 (turntable roll) and 0.68–0.70 (blocks tilts) and fails it.
def test_default_sigma_matches_scatter_reduced(program):
    name, prog = program
    _check(name, _ratios(prog, 100), (0.79, 1.21))


@pytest.mark.slow
def test_default_sigma_matches_scatter_full(program):
    # 200 draws: sampling spread 0.05, [0.85, 1.15] is 3 sigma
    name, prog = program
    _check(name, _ratios(prog, 200), (0.85, 1.15))
