"""Campaign files: a design study written down as TOML or YAML, read once into a
:class:`CampaignFile` and run with ``atomnav campaign FILE`` (or
:meth:`CampaignFile.campaign` and :func:`atomnav.campaign.run` from Python).

The format (TOML; YAML takes the same keys and nesting)::

    scenario = "cai_car"      # a built-in scenario, or "package.module:function" of your own
    name = "car_pulse_time"   # optional: the results' sub-folder (default: the function's name)
    seeds = 20                # runs per parameter point (default 1)
    seed = 7                  # the campaign seed; run r draws its own seed from (seed, r) (default 0)
    output = "results"        # results folder, relative to this file's folder (default: that folder)

    [grid]                    # every combination, last key fastest ...
    T = [0.01, 0.02, 0.025]
    shot_rate = [0.0, 5.0]    # Hz (0: one shot per 2T)

    # ... or [points]: lists of equal length, point i takes the i-th value of each,
    # or [[points]] tables, one per point. One of [grid] and [points], not both.

    [fixed]                   # parameters shared by every point
    imu = "navigation"
    lever = 0.1

    [executor]                # optional; the command line's --workers / --scheduler win
    workers = 2               # a LocalCluster of 2 single-threaded worker processes ...
    # scheduler = "tcp://10.0.0.5:8786"   # ... or an existing dask.distributed cluster

A parameter value is a bool, an integer, a finite float, a string or a list of finite
numbers (a vector); every parameter not given keeps the scenario's default. A key the
format does not know is an error naming it (a misspelt ``seeds`` does not silently run
one seed). YAML files need PyYAML (``pip install pyyaml``); TOML is read with the
standard library's ``tomllib`` (the ``tomli`` package on Python 3.10).

Scenarios and the campaign itself follow the conventions of :mod:`atomnav.campaign`
(the run seed of run ``r`` is ``SeedSequence(seed, spawn_key=(r,))``, as in NumPy's
parallel random-number guidance).
"""

from __future__ import annotations

import dataclasses
import importlib
import importlib.util
import pkgutil
import re
from collections.abc import Mapping, Sequence
from contextlib import contextmanager
from pathlib import Path
from typing import Union

from .._core import InputError
from .._validate import input_error, integer, path as _path
from .plan import Campaign, _json_value, import_scenario
from .scenario import check_params, parameters

_Value = Union[bool, int, float, str, tuple]  # a parameter value: a scalar or a vector (a tuple of numbers)

_DOTTED = re.compile(r"^[A-Za-z_]\w*(\.[A-Za-z_]\w*)*$")
_NAME = re.compile(r"^[A-Za-z_]\w*$")
_SUFFIXES = {".toml": "TOML", ".yaml": "YAML", ".yml": "YAML"}
_KEYS = ("scenario", "name", "seeds", "seed", "output", "grid", "points", "fixed", "executor")


@dataclasses.dataclass(frozen=True)
class Executor:
    """Where the runs of a campaign file execute (the file's ``[executor]`` table).

    Parameters
    ----------
    scheduler : str or None
        Address of the scheduler of a running dask.distributed cluster, e.g.
        ``"tcp://10.0.0.5:8786"``.
    workers : int or None
        Number of single-threaded worker processes of a LocalCluster started for the
        campaign (>= 1).

    Raises
    ------
    InputError
        Both given; ``workers`` < 1; an empty address.
    TypeError
        ``scheduler`` not a str, ``workers`` not an integer.

    Notes
    -----
    Neither: the runs execute one after the other in the calling process.
    """

    scheduler: str | None = None
    workers: int | None = None

    def __post_init__(self):
        if self.scheduler is not None:
            if not isinstance(self.scheduler, str):
                raise TypeError(f"scheduler: expected an address str, got {type(self.scheduler).__name__}")
            if not self.scheduler.strip():
                raise input_error("scheduler", "empty address; give e.g. 'tcp://10.0.0.5:8786'")
        if self.workers is not None:
            object.__setattr__(self, "workers", _at_least_one(self.workers, "workers"))
        if self.scheduler is not None and self.workers is not None:
            raise input_error("workers", "give scheduler (an existing cluster) or workers (a local one), not both")


@dataclasses.dataclass(frozen=True)
class CampaignFile:
    """A campaign file's content, checked: what to run, on which parameter points, how
    many seeds, where the results go and where the runs execute.

    Parameters
    ----------
    scenario : str
        A built-in scenario's name (``"cai_car"``) or ``"package.module:function"``.
    grid : mapping of str to sequence, optional
        Parameter name -> values; the campaign runs every combination (last key fastest).
        Stored as a tuple of ``(name, values)`` pairs.
    points : sequence of mappings, optional
        Explicit parameter points, each a mapping parameter name -> value. Stored as a
        tuple of tuples of ``(name, value)`` pairs. Exactly one of ``grid`` and ``points``
        is non-empty.
    seeds : int, default 1
        Runs per parameter point (>= 1).
    seed : int, default 0
        The campaign seed, in [0, 2**64 - 1].
    fixed : mapping of str to value, optional
        Parameters shared by every point. Stored as a tuple of ``(name, value)`` pairs.
    name : str or None, default None
        The campaign's name, the results' sub-folder; None: the scenario function's name.
    output : path-like, default "."
        The results folder (the campaign writes ``output/<name>/``).
    executor : Executor, default Executor()
        Where the runs execute.

    Raises
    ------
    InputError
        A value out of range, neither or both of ``grid`` and ``points``, an empty value
        list, a malformed scenario reference; the message names the key (``grid.T``,
        ``points[2].T``).
    TypeError
        A value of the wrong type (a parameter value that is no bool, number, string or
        list of numbers), naming the key.

    Notes
    -----
    Values are stored as tuples, so the object is immutable, hashable and picklable;
    :meth:`campaign` hands lists to the scenario's vectors.

    Examples
    --------
    >>> from atomnav.campaign.config_file import CampaignFile
    >>> study = CampaignFile("cai_car", grid={"T": [0.01, 0.02]}, seeds=4)
    >>> study.grid
    (('T', (0.01, 0.02)),)
    """

    scenario: str
    _: dataclasses.KW_ONLY
    grid: tuple[tuple[str, tuple[_Value, ...]], ...] = ()
    points: tuple[tuple[tuple[str, _Value], ...], ...] = ()
    seeds: int = 1
    seed: int = 0
    fixed: tuple[tuple[str, _Value], ...] = ()
    name: str | None = None
    output: Path = Path(".")
    executor: Executor = Executor()

    def __post_init__(self):
        if not isinstance(self.scenario, str):
            raise TypeError(f"scenario: expected a str, got {type(self.scenario).__name__}")
        if not _reference(self.scenario):
            raise input_error("scenario", f"expected a built-in name or 'package.module:function', got {self.scenario!r}")
        set_ = object.__setattr__
        set_(self, "grid", tuple((k, _values(v, f"grid.{k}")) for k, v in _pairs(self.grid, "grid")))
        set_(self, "points", tuple(tuple((k, _value(v, f"points[{i}].{k}")) for k, v in _pairs(p, f"points[{i}]"))
                                   for i, p in enumerate(_sequence(self.points, "points"))))
        if bool(self.grid) == bool(self.points):
            raise input_error("points", "give the parameter points ([points]) or a grid of them ([grid]): exactly one"
                              if self.grid else "missing: give [points] (the parameter points) or [grid] (every combination)")
        set_(self, "seeds", _at_least_one(self.seeds, "seeds"))
        set_(self, "seed", integer(self.seed, "seed", 0, 2**64 - 1))
        set_(self, "fixed", tuple((k, _value(v, f"fixed.{k}")) for k, v in _pairs(self.fixed, "fixed")))
        if self.name is not None and not isinstance(self.name, str):
            raise TypeError(f"name: expected a str, got {type(self.name).__name__}")
        set_(self, "output", _path(self.output, "output"))
        if not isinstance(self.executor, Executor):
            raise TypeError(f"executor: expected an Executor, got {type(self.executor).__name__}")

    def campaign(self):
        """The :class:`atomnav.campaign.plan.Campaign` this file describes.

        Returns
        -------
        atomnav.campaign.plan.Campaign
            The scenario imported, the grid or points, seeds, seed, fixed parameters and name.

        Raises
        ------
        InputError
            ``scenario`` names no built-in scenario or no importable function; a
            parameter the scenario does not take (named under ``grid``, ``points`` or
            ``fixed``).
        """
        scenario = _scenario(self.scenario)
        fixed = {k: _plain(v) for k, v in self.fixed}
        check_params(scenario, fixed, name="fixed")
        if self.grid:
            points = {k: [_plain(v) for v in values] for k, values in self.grid}
            check_params(scenario, dict.fromkeys(points), name="grid")
        else:
            points = [{k: _plain(v) for k, v in p} for p in self.points]
            for p in points:
                check_params(scenario, p, name="points")
        return Campaign(scenario, points, seeds=self.seeds, seed=self.seed, fixed=fixed or None, name=self.name)


def load(path) -> CampaignFile:
    """Read a campaign file (``.toml``, ``.yaml`` or ``.yml``; the format is in this
    module's documentation).

    Parameters
    ----------
    path : str or path-like
        The campaign file. Its ``output`` is taken relative to the file's folder.

    Returns
    -------
    CampaignFile
        The file's content, checked, with ``output`` an absolute path.

    Raises
    ------
    InputError
        Another suffix, a file that is no valid UTF-8 TOML or YAML, a top level that is
        not a table, an unknown key, no ``scenario``, or any error of :class:`CampaignFile` (``parameter``
        names the key, e.g. ``seeds`` or ``executor.workers``; ``path`` for the whole file).
    TypeError
        ``path`` not a str or path-like; a value of the wrong type, naming the key.
    OSError
        The file cannot be read (``FileNotFoundError`` when it does not exist).
    ImportError
        A YAML file without PyYAML installed.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from atomnav.campaign.config_file import load
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> _ = (folder / "study.toml").write_text('scenario = "cai_car"\\nseeds = 3\\n[grid]\\nT = [0.01, 0.02]\\n')
    >>> study = load(folder / "study.toml")
    >>> study.seeds, study.grid, study.output == folder.resolve()
    (3, (('T', (0.01, 0.02)),), True)
    """
    path = _path(path, "path")
    kind = _SUFFIXES.get(path.suffix.lower())
    if kind is None:
        raise input_error("path", f"expected a .toml, .yaml or .yml file, got {path.name!r}")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as e:
        raise input_error("path", f"not UTF-8 text ({e.reason} at byte {e.start})") from None
    data = _parse_toml(text) if kind == "TOML" else _parse_yaml(text)
    if not isinstance(data, Mapping):
        raise input_error("path", f"expected a table of keys at the top of the file, got {type(data).__name__}")
    unknown = sorted(set(data) - set(_KEYS), key=str)
    if unknown:
        raise input_error(str(unknown[0]), f"unknown key; the keys are {', '.join(_KEYS)}")
    if "scenario" not in data:
        raise input_error("scenario", "missing: name a built-in scenario or 'package.module:function'")
    fields = {k: v for k, v in data.items() if k not in ("executor", "points", "output")}
    if "points" in data:
        fields["points"] = _zipped(data["points"]) if isinstance(data["points"], Mapping) else data["points"]
    output = data.get("output", ".")
    if not isinstance(output, str):
        raise TypeError(f"output: expected a folder name str, got {type(output).__name__}")
    fields["output"] = (path.parent / _path(output, "output")).resolve()
    table = data.get("executor", {})
    if not isinstance(table, Mapping):
        raise TypeError(f"executor: expected a table, got {type(table).__name__}")
    with _section("executor"):
        extra = sorted(set(table) - {"scheduler", "workers"}, key=str)
        if extra:
            raise input_error(str(extra[0]), "unknown key; the keys are scheduler, workers")
        fields["executor"] = Executor(**table)
    return CampaignFile(**fields)


def _parse_toml(text: str):
    try:
        import tomllib
    except ModuleNotFoundError:  # Python 3.10
        import tomli as tomllib
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise input_error("path", f"not valid TOML: {e}") from None


def _parse_yaml(text: str):
    try:
        import yaml
    except ModuleNotFoundError:
        raise ImportError("reading a YAML campaign file needs PyYAML: pip install pyyaml "
                          "(or write the campaign as TOML)") from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as e:
        raise input_error("path", f"not valid YAML: {' '.join(str(e).split())}") from None


@contextmanager
def _section(prefix: str):
    """Errors raised inside the block name their key under ``prefix`` (``executor.workers``)."""
    try:
        yield
    except InputError as e:
        reason = str(e)[len(e.parameter) + 2:]
        raise input_error(f"{prefix}.{e.parameter}", reason, e.index) from None
    except TypeError as e:
        raise TypeError(f"{prefix}.{e}") from None


def _reference(text: str) -> bool:
    """``text`` is a built-in name or ``package.module:function``."""
    module, colon, function = text.partition(":")
    return bool(_DOTTED.match(module)) and (not colon or bool(_NAME.match(function)))


def _scenario(reference: str):
    """The scenario function ``reference`` names: a built-in or ``package.module:function``."""
    if ":" in reference:
        return import_scenario(reference)
    f = _builtin(reference)
    if f is None:
        known = [m.name for m in pkgutil.iter_modules([str(Path(__file__).parent)]) if not m.name.startswith("_") and _builtin(m.name)]
        raise input_error("scenario", f"unknown built-in scenario {reference!r}; the built-ins are {', '.join(known)}, "
                          "or give 'package.module:function'")
    return f


def _builtin(name: str):
    """The built-in scenario ``name`` (module ``atomnav.campaign.<name>``, function ``<name>``), or None."""
    if importlib.util.find_spec(f"{__package__}.{name}") is None:
        return None
    f = getattr(importlib.import_module(f"{__package__}.{name}"), name, None)
    try:
        parameters(f)
    except TypeError:  # no function of the module's name, or no scenario (e.g. the sweep helper)
        return None
    return f


def _at_least_one(x, name: str) -> int:
    n = integer(x, name, 0)
    if n < 1:
        raise input_error(name, f"must be ≥ 1, got {n}")
    return n


def _pairs(x, name: str) -> tuple:
    """A mapping (or a tuple of ``(key, value)`` pairs) as a tuple of pairs with str keys."""
    if isinstance(x, Mapping):
        items = tuple(x.items())
    elif isinstance(x, tuple) and all(isinstance(p, tuple) and len(p) == 2 for p in x):
        items = x
    else:
        raise TypeError(f"{name}: expected a table of parameter names and values, got {type(x).__name__}")
    for k, _ in items:
        if not isinstance(k, str) or not _NAME.match(k):
            raise input_error(name, f"{k!r} is no parameter name")
    if len({k for k, _ in items}) < len(items):
        raise input_error(name, "a parameter appears twice")
    return items


def _sequence(x, name: str) -> Sequence:
    if isinstance(x, (str, bytes, Mapping)) or not isinstance(x, Sequence):
        raise TypeError(f"{name}: expected a list, got {type(x).__name__}")
    return x


def _values(x, name: str) -> tuple:
    """A non-empty list of parameter values, as a tuple."""
    x = _sequence(x, name)
    if not x:
        raise input_error(name, "empty list of values")
    return tuple(_value(v, f"{name}[{i}]") for i, v in enumerate(x))


def _value(x, name: str) -> _Value:
    """A parameter value (bool, int, finite float, str, or a list of numbers as a tuple)."""
    v = _json_value(x, name)
    if not isinstance(v, list):
        return v
    for i, e in enumerate(v):
        if isinstance(e, bool) or not isinstance(e, (int, float)):
            raise TypeError(f"{name}[{i}]: a vector holds numbers, got {type(e).__name__} {e!r}")
    return tuple(v)


def _plain(v: _Value):
    """A stored value as a scenario receives it (vectors as lists)."""
    return list(v) if isinstance(v, tuple) else v


def _zipped(table: Mapping) -> list[dict]:
    """A ``[points]`` table of equal-length lists as one mapping per point."""
    columns = {k: _sequence(v, f"points.{k}") for k, v in table.items()}
    lengths = {k: len(v) for k, v in columns.items()}
    if len(set(lengths.values())) > 1:
        raise input_error("points", "the lists must have equal lengths (point i takes the i-th value of each), got "
                          + ", ".join(f"{k}: {n}" for k, n in lengths.items()))
    n = next(iter(lengths.values()), 0)
    return [{k: v[i] for k, v in columns.items()} for i in range(n)]
