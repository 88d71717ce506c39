"""Design studies at scale: campaigns of a scenario over parameter points and seeds, run in
this process or on a Dask cluster, every finished run written at once to a Parquet dataset
and resumed from it.

- :mod:`~atomnav.campaign.scenario`: what a scenario and its covariance predictor are.
- :class:`Campaign`: a scenario, its points (grid or list) and seeds; each run's seed
  depends on (campaign seed, run id) only.
- :func:`run`, :func:`load`, :func:`timing`: execute or resume a campaign, read it back.
- :func:`sweep`, :func:`compare`, :func:`requirements`: covariance predictions over large
  grids, Monte Carlo to confirm chosen points, and the feasible region of a target.
- :mod:`~atomnav.campaign.plots`: error versus parameter, error maps, throughput.
- Built-in scenarios, each with its covariance predictor: :func:`cai_car` (the CAI-aided
  car of Tennstedt et al. 2023), :func:`gnss_tight` (the tightly coupled GNSS/INS of
  Demidov 2009), :func:`strapdown_free` (the free INS of an IMU grade).
"""

from . import plots
from .cai_car import cai_car
from .execute import load, run, timing
from .gnss_tight import gnss_tight
from .plan import Campaign
from .scenario import parameters, predicted_by
from .strapdown_free import strapdown_free
from .sweep import compare, requirements, sweep

__all__ = ["Campaign", "run", "load", "timing", "parameters", "predicted_by", "sweep", "compare", "requirements", "plots",
           "cai_car", "gnss_tight", "strapdown_free"]
