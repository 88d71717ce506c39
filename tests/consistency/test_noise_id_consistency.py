"""Monte-Carlo consistency of the ML readout-noise identification (Tennstedt et al. 2021,
Eqs. 18–26): the scatter of (σ_p0, σ_φ) and of the identifiable a, b over independent
batches equals the standard errors ``identify_noise`` reports.

The readouts are simulated here with numpy from the nonlinear fringe
p = (p0 + n_p0) + (A + n_A) cos(φ + n_φ) and the residuals taken about the true fringe, on
two programs that are not the paper's: phases spread over the whole fringe, and a
two-point scan alternating between the fringe top and mid-fringe. σ_A is held at its true value
(only two of the three are identifiable). Criterion: scatter/se in [0.85, 1.15] over
B batches of 200 readouts (the ratio's sampling spread is ≈ 1/√(2B): B = 300 in CI).
"""

import numpy as np
import pytest

from atomnav import cai

PROGRAMS = {
    "whole_fringe": dict(sigma=(0.01, 0.1, 0.005), amplitude=0.2, phase=lambda rng, n: rng.uniform(-np.pi, np.pi, n)),
    # a two-point scan: alternately at the fringe top (sees σ_p0 and σ_A) and mid-fringe (σ_φ)
    "two_point": dict(sigma=(0.02, 0.15, 0.01), amplitude=0.3,
                      phase=lambda rng, n: np.where(np.arange(n) % 2, np.pi / 2, 0.0) + rng.uniform(-0.2, 0.2, n)),
}


def _ratios(program, batches, batch=200, seed=4):
    cfg = PROGRAMS[program]
    s_p0, s_phi, s_a = cfg["sigma"]
    n = batches * batch
    rng = np.random.default_rng(seed)
    phase = cfg["phase"](rng, n)
    amp = cfg["amplitude"]
    p = 0.5 + rng.normal(0, s_p0, n) + (amp + rng.normal(0, s_a, n)) * np.cos(phase + rng.normal(0, s_phi, n))
    x = p - (0.5 + amp * np.cos(phase))
    r = cai.identify_noise(x, phase, np.full(n, amp), free=("p0", "phi"), theta0=(s_p0, s_phi, s_a), batch=batch)
    assert r.converged.all()
    out = {}
    for est, se in (("sigma_p0", "se_sigma_p0"), ("sigma_phi_rad", "se_sigma_phi_rad"), ("a", "se_a"), ("b", "se_b")):
        out[est] = np.std(r[est], ddof=1) / np.sqrt(np.mean(r[se] ** 2))
    return out, r


@pytest.mark.parametrize("program", list(PROGRAMS))
def test_identified_noise_standard_errors_match_the_scatter_reduced(program):
    ratios, r = _ratios(program, batches=300)
    assert all(0.85 < v < 1.15 for v in ratios.values()), ratios
    assert (r["se_sigma_A"] == 0).all()          # held fixed: no uncertainty


@pytest.mark.slow
@pytest.mark.parametrize("program", list(PROGRAMS))
def test_identified_noise_standard_errors_match_the_scatter_full(program):
    ratios, _ = _ratios(program, batches=3000, seed=9)
    assert all(0.95 < v < 1.05 for v in ratios.values()), ratios
