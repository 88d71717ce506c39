"""A campaign: a scenario, the parameter points it runs at (a grid or a list) and the seeds
of each point. Every run has an id and a seed that depend only on the campaign, so any
executor, in any order, draws the same numbers."""

from __future__ import annotations

import importlib
import itertools
import json
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .._validate import input_error, instance, integer
from .scenario import check_params, parameters

#: Largest number of runs of one campaign.
MAX_RUNS = 100_000_000


def _json_value(value, name: str):
    """A parameter value as JSON-able data (numbers, strings, bools, lists of them)."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        if not math.isfinite(value):
            raise input_error(name, f"must be finite, got {value}")
        return float(value)
    if isinstance(value, str):
        return value
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_json_value(v, name) for v in value]
    raise TypeError(f"{name}: expected numbers, strings, bools or lists of them, got {type(value).__name__}")


def _scenario_path(scenario: Callable) -> str:
    """``module:qualname`` of a module-level scenario function (how its configuration names it)."""
    return f"{scenario.__module__}:{scenario.__qualname__}"


def import_scenario(scenario: str) -> Callable:
    """The scenario function named ``module:qualname``.

    Parameters
    ----------
    scenario : str
        ``"package.module:function"``.

    Returns
    -------
    callable
        The function.

    Raises
    ------
    atomnav.InputError
        The module or the function cannot be found (``parameter`` is "scenario").
    """
    module, _, qualname = instance(scenario, str, "scenario").partition(":")
    try:
        obj = importlib.import_module(module)
        for part in qualname.split("."):
            obj = getattr(obj, part)
    except (ImportError, AttributeError, ValueError) as e:
        raise input_error("scenario", f"cannot import {scenario!r} ({e})") from None
    if not callable(obj):
        raise input_error("scenario", f"{scenario!r} is not a function")
    return obj


def _points(scenario: Callable, points) -> tuple[list[dict], dict | None]:
    """The explicit points of ``points`` (grid dict or list of dicts), and the grid if given as one."""
    if isinstance(points, dict):
        grid = {}
        for key, values in check_params(scenario, points).items():
            if isinstance(values, (str, bytes)) or not isinstance(values, (list, tuple, np.ndarray, range)):
                raise TypeError(f"points: the values of {key!r} must be a list, got {type(values).__name__}")
            grid[key] = [_json_value(v, "points") for v in values]
            if not grid[key]:
                raise input_error("points", f"{key!r} has no values: an empty grid has no runs")
        if not grid:
            raise input_error("points", "an empty grid has no runs")
        keys = list(grid)
        return [dict(zip(keys, combo)) for combo in itertools.product(*grid.values())], grid
    if isinstance(points, (list, tuple)):
        if not points:
            raise input_error("points", "an empty list of points has no runs")
        out = []
        for i, p in enumerate(points):
            if not isinstance(p, dict):
                raise TypeError(f"points: point {i} must be a dict of parameters, got {type(p).__name__}")
            out.append({k: _json_value(v, "points") for k, v in check_params(scenario, p).items()})
        return out, None
    raise TypeError(f"points: expected a grid (dict name -> list of values) or a list of dicts, got {type(points).__name__}")


@dataclass(frozen=True)
class Campaign:
    """A scenario run at parameter points, ``seeds`` times each.

    Run ``r`` is replicate ``r mod seeds`` of point ``r div seeds``; its seed is derived
    from (``seed``, ``r``) alone (:func:`numpy.random.SeedSequence` with ``r`` as the spawn
    key), so the same campaign gives the same numbers whatever executes it, in any order
    and after any interruption.

    Parameters
    ----------
    scenario : callable
        A scenario function ``f(*, seed, **params) -> pandas.DataFrame``
        (:mod:`atomnav.campaign.scenario`), defined at module level.
    points : dict or list of dict
        A grid (parameter name → list of values; every combination, the last name varying
        fastest) or a list of points (each a dict of parameters).
    seeds : int, default 1
        Runs per point.
    seed : int, default 0
        Campaign seed (0 … 2⁶⁴ − 1).
    fixed : dict, optional
        Parameters shared by every point (a point's own value wins).
    name : str, optional
        Name of the campaign and of its folder in the output; default the scenario's name.

    Raises
    ------
    atomnav.InputError
        ``points``/``fixed`` naming a parameter the scenario does not take, an empty grid
        or list, a non-finite value; ``seeds``/``seed`` out of range; more than
        :data:`MAX_RUNS` runs.
    TypeError
        ``scenario`` not a scenario function, ``points`` not a dict or list of dicts.
    """

    scenario: Callable
    points: dict | list
    seeds: int = 1
    seed: int = 0
    fixed: dict | None = None
    name: str | None = None
    _list: list = field(init=False, repr=False, compare=False)
    _grid: dict | None = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        parameters(self.scenario)
        fixed = {} if self.fixed is None else instance(self.fixed, dict, "fixed")
        fixed = {k: _json_value(v, "fixed") for k, v in check_params(self.scenario, fixed, "fixed").items()}
        listed, grid = _points(self.scenario, self.points)
        seeds = integer(self.seeds, "seeds", 1, MAX_RUNS)
        if len(listed) * seeds > MAX_RUNS:
            raise input_error("seeds", f"{len(listed)} points × {seeds} seeds is more than {MAX_RUNS} runs")
        name = self.scenario.__name__ if self.name is None else instance(self.name, str, "name")
        if not name or any(c in name for c in "/\\:") or name.startswith("."):
            raise input_error("name", f"{name!r} cannot name a folder")
        object.__setattr__(self, "fixed", fixed)
        object.__setattr__(self, "seeds", seeds)
        object.__setattr__(self, "seed", integer(self.seed, "seed", 0, 2**64 - 1))
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "_list", listed)
        object.__setattr__(self, "_grid", grid)

    @property
    def n_points(self) -> int:
        """Number of parameter points."""
        return len(self._list)

    @property
    def n_runs(self) -> int:
        """Number of runs (points × seeds)."""
        return len(self._list) * self.seeds

    def point(self, index: int) -> dict:
        """The full parameters of point ``index``.

        Parameters
        ----------
        index : int
            Point number, 0 … ``n_points`` − 1.

        Returns
        -------
        dict
            The scenario's defaults, overridden by ``fixed``, overridden by the point.
        """
        i = integer(index, "index", 0, self.n_points - 1)
        return {**parameters(self.scenario), **self.fixed, **self._list[i]}

    def run_seed(self, run: int) -> int:
        """The seed of a run, from the campaign seed and the run id only.

        Parameters
        ----------
        run : int
            Run id, 0 … ``n_runs`` − 1.

        Returns
        -------
        int
            Its seed, 0 … 2⁶⁴ − 1.
        """
        r = integer(run, "run", 0, self.n_runs - 1)
        words = np.random.SeedSequence(self.seed, spawn_key=(r,)).generate_state(2, np.uint32)
        return int(words[0]) | (int(words[1]) << 32)

    def varied(self) -> list[str]:
        """The parameters the points set.

        Returns
        -------
        list of str
            Their names, in the scenario's order.
        """
        names = {k for p in self._list for k in p}
        return [k for k in parameters(self.scenario) if k in names]

    def to_dict(self) -> dict:
        """The campaign as data.

        Returns
        -------
        dict
            JSON-able: the scenario's ``module:qualname``, the points (the grid, or the
            list), seeds, seed, fixed and name; what ``campaign.json`` holds.
        """
        return {"scenario": _scenario_path(self.scenario), "points": self._list if self._grid is None else self._grid,
                "seeds": self.seeds, "seed": self.seed, "fixed": self.fixed, "name": self.name}

    def to_json(self) -> str:
        """The campaign as JSON text.

        Returns
        -------
        str
            :meth:`to_dict`, indented.
        """
        return json.dumps(self.to_dict(), indent=2)

    @classmethod
    def from_dict(cls, d: dict) -> "Campaign":
        """The campaign of :meth:`to_dict`.

        Parameters
        ----------
        d : dict
            As :meth:`to_dict` gives it; the scenario is imported by its ``module:qualname``.

        Returns
        -------
        Campaign
            The campaign.
        """
        instance(d, dict, "campaign")
        return cls(import_scenario(d["scenario"]), d["points"], seeds=d["seeds"], seed=d["seed"], fixed=d["fixed"], name=d["name"])
