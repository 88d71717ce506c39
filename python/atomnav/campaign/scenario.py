"""What a campaign runs: a *scenario* is a plain function of keyword parameters and a seed
that returns one run's result table; its *covariance predictor* gives the RMS over seeds of
the same table without simulating noise.

A scenario ``f(*, seed, **params) -> pandas.DataFrame``:

- takes keyword-only parameters, each with a default, and ``seed`` (0 … 2⁶⁴ − 1);
- returns one row per checkpoint, ``time_s`` first, then error metrics as norms of the
  error vectors with their units in the name (``pos_error_m``, ``vel_error_mps``,
  ``att_error_rad``), the same checkpoints for every seed of one parameter point;
- is deterministic: the same seed and parameters give the same table bit for bit, in
  whichever process it runs.

A predictor ``g(**params) -> pandas.DataFrame`` has the same columns and rows and gives
√E[|e|²], the root of the trace of the matching covariance block, which is what the root
mean square over Monte-Carlo seeds converges to. :func:`predicted_by` attaches it.
"""

from __future__ import annotations

import inspect
from typing import Callable

import pandas as pd

from .._validate import input_error

#: The keyword every scenario takes for its run's seed.
SEED = "seed"


def _signature(fn: Callable, name: str) -> inspect.Signature:
    if not callable(fn):
        raise TypeError(f"{name}: expected a scenario function f(*, seed, **params), got {type(fn).__name__}")
    try:
        return inspect.signature(fn)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name}: cannot read the parameters of {fn!r} ({e})") from None


def parameters(scenario: Callable) -> dict:
    """The parameters of a scenario and their defaults (every keyword but ``seed``).

    Parameters
    ----------
    scenario : callable
        A scenario function ``f(*, seed, **params)``.

    Returns
    -------
    dict
        Parameter name → default value, in the function's order.

    Raises
    ------
    TypeError
        ``scenario`` is not a function of keyword parameters with defaults and ``seed``.
    """
    sig = _signature(scenario, "scenario")
    out = {}
    for p in sig.parameters.values():
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD, p.POSITIONAL_ONLY):
            raise TypeError(f"scenario: {scenario.__name__} must take named parameters only, not {p}")
        if p.name == SEED:
            continue
        if p.default is p.empty:
            raise TypeError(f"scenario: parameter {p.name!r} of {scenario.__name__} needs a default")
        out[p.name] = p.default
    if SEED not in sig.parameters:
        raise TypeError(f"scenario: {scenario.__name__} must take the keyword {SEED!r}")
    return out


def check_params(scenario: Callable, params: dict, name: str = "points") -> dict:
    """``params`` checked against the parameters of ``scenario``.

    Parameters
    ----------
    scenario : callable
        A scenario function.
    params : dict
        Parameter name → value.
    name : str
        The argument the parameters came from, named in the error.

    Returns
    -------
    dict
        ``params`` as a new dict.

    Raises
    ------
    atomnav.InputError
        A name the scenario does not take (``parameter`` is ``name``; the message lists
        the scenario's parameters).
    """
    known = parameters(scenario)
    for key in params:
        if key not in known:
            raise input_error(name, f"{key!r} is not a parameter of {scenario.__name__} (it takes {', '.join(known) or 'none'})")
    return dict(params)


def predicted_by(predictor: Callable) -> Callable:
    """Attach a covariance predictor to a scenario (``f.predict = predictor``).

    Parameters
    ----------
    predictor : callable
        ``g(**params) -> pandas.DataFrame``, taking the scenario's parameters (without
        ``seed``) and returning its table's columns as RMS over seeds.

    Returns
    -------
    callable
        A decorator returning the scenario itself.

    Raises
    ------
    TypeError
        The predictor's parameters differ from the scenario's.
    """
    def attach(scenario: Callable) -> Callable:
        own = list(parameters(scenario))
        sig = _signature(predictor, "predictor")
        theirs = [p.name for p in sig.parameters.values()]
        if theirs != own:
            raise TypeError(f"predictor: {predictor.__name__} takes {theirs}, {scenario.__name__} takes {own}")
        scenario.predict = predictor
        return scenario

    return attach


def predictor(scenario: Callable) -> Callable:
    """The covariance predictor attached to ``scenario``.

    Parameters
    ----------
    scenario : callable
        A scenario function.

    Returns
    -------
    callable
        Its predictor ``g(**params) -> pandas.DataFrame``.

    Raises
    ------
    TypeError
        ``scenario`` is not a scenario function.
    atomnav.InputError
        ``scenario`` has no predictor (see :func:`predicted_by`).
    """
    parameters(scenario)
    g = getattr(scenario, "predict", None)
    if not callable(g):
        raise input_error("scenario", f"{scenario.__name__!r} has no covariance predictor (attach one with predicted_by)")
    return g


def _checked_table(table, scenario: Callable) -> pd.DataFrame:
    """One run's table, checked to be a DataFrame starting with ``time_s``."""
    if not isinstance(table, pd.DataFrame):
        raise TypeError(f"scenario: {scenario.__name__} returned {type(table).__name__}, expected a pandas DataFrame")
    if len(table.columns) == 0 or table.columns[0] != "time_s":
        raise input_error("scenario", f"{scenario.__name__} returned columns {list(table.columns)}; the first must be time_s")
    return table
