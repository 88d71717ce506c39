"""A toy campaign scenario with a closed form, for the campaign command-line tests and
benchmark: a 3-D random walk of independent Gaussian steps, whose root mean square
distance after k steps is sqrt(k · Σ σ_i²)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from atomnav.campaign.scenario import predicted_by


def _checkpoints(steps: int, checkpoints: int) -> np.ndarray:
    """The step counts of the table's rows: ``checkpoints`` evenly spaced ones, the last = ``steps``."""
    return np.unique(np.ceil(steps * np.arange(1, checkpoints + 1) / checkpoints).astype(int))


def rms(*, sigma_m=(1.0, 1.0, 1.0), steps=10, dt_s=1.0, checkpoints=5) -> pd.DataFrame:
    """The RMS distance over seeds, sqrt(k · Σ σ_i²) at each checkpoint (m)."""
    k = _checkpoints(steps, checkpoints)
    return pd.DataFrame({"time_s": k * dt_s, "pos_error_m": np.sqrt(k * np.sum(np.square(sigma_m)))})


@predicted_by(rms)
def random_walk(*, seed=0, sigma_m=(1.0, 1.0, 1.0), steps=10, dt_s=1.0, checkpoints=5) -> pd.DataFrame:
    """Distance from the start of a 3-D walk of ``steps`` Gaussian steps (σ per axis, m) at the checkpoints."""
    k = _checkpoints(steps, checkpoints)
    walk = np.cumsum(np.random.default_rng(seed).standard_normal((steps, 3)) * np.asarray(sigma_m), axis=0)
    return pd.DataFrame({"time_s": k * dt_s, "pos_error_m": np.linalg.norm(walk[k - 1], axis=1)})
