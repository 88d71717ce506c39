"""Where a campaign's runs live: a Parquet dataset per campaign, partitioned by parameter
point, with the campaign's configuration beside it as JSON.

``folder/<name>/campaign.json`` holds :meth:`Campaign.to_dict`;
``folder/<name>/runs/point=<k>/part-<first run>.parquet`` hold the finished runs of point
k (a Hive-partitioned dataset: ``pandas.read_parquet(folder/<name>/runs)`` and Dask read
it as it is), each file written whole (to a temporary name, then renamed), so a process
killed at any moment leaves only complete files. A folder holds any number of campaigns under their
names; two of them must not share a campaign seed (their runs would draw the same numbers).
"""

from __future__ import annotations

import json
import os
import uuid
from pathlib import Path

import numpy as np
import pandas as pd

from .._validate import input_error, path
from .plan import Campaign

#: Columns that say how a run went (kept on disk, read by :func:`timing`), not what it gave.
TIMING = ("worker", "elapsed_s")
#: The columns that identify a run in the table, before its parameters.
KEYS = ("run", "point", "replicate", "seed")


def _differences(a: dict, b: dict) -> list[str]:
    return sorted(k for k in set(a) | set(b) if a.get(k) != b.get(k))


class _Store:
    """The on-disk dataset of one campaign (see the module docstring).

    Parameters
    ----------
    folder : str or path-like
        The output folder (created if missing).
    campaign : Campaign
        The campaign.

    Raises
    ------
    atomnav.InputError
        ``folder`` holds another campaign under the same name (naming the fields that
        differ), or ``seed`` is the campaign seed of another campaign in the folder.
    """

    def __init__(self, folder, campaign: Campaign):
        self.root = path(folder, "folder")
        if self.root.exists() and not self.root.is_dir():
            raise input_error("folder", f"{self.root} is a file, not a folder")
        self.campaign = campaign
        self.dir = self.root / campaign.name
        self.dataset = _Dataset(self.dir)
        mine = json.loads(campaign.to_json())
        config = self.dir / "campaign.json"
        if config.exists():
            theirs = json.loads(config.read_text())
            if theirs != mine:
                raise input_error("folder", f"{self.dir} holds another campaign named {campaign.name!r} "
                                  f"(differing in {', '.join(_differences(theirs, mine))}); choose another name or folder")
        if self.root.is_dir():
            for other in sorted(self.root.glob("*/campaign.json")):
                if other != config and json.loads(other.read_text()).get("seed") == campaign.seed:
                    raise input_error("seed", f"campaign {other.parent.name!r} in {self.root} already uses seed {campaign.seed}: "
                                      "its runs would repeat the same random draws; choose another seed")
        self.dataset.runs.mkdir(parents=True, exist_ok=True)
        if not config.exists():
            tmp = config.with_name(f".campaign.json.{uuid.uuid4().hex}")
            tmp.write_text(campaign.to_json())
            os.replace(tmp, config)
        self._params = _parameter_frame(campaign)

    def rows(self, results) -> pd.DataFrame:
        """Finished runs as stored rows: each run's table with its keys, parameters and
        timing beside it.

        ``results`` holds (run id, table, worker, elapsed s) per run."""
        c = self.campaign
        tables = [table.reset_index(drop=True) for _, table, _, _ in results]
        counts = np.array([len(t) for t in tables])
        runs = np.repeat(np.array([r for r, *_ in results], dtype=np.int64), counts)
        point, replicate = np.divmod(runs, c.seeds)
        seeds = np.repeat(np.array([c.run_seed(r) for r, *_ in results], dtype=np.uint64), counts)
        body = pd.concat(tables, ignore_index=True)
        clash = set(body.columns) & (set(KEYS) | set(self._params.columns) | set(TIMING))
        if clash:
            raise input_error("scenario", f"{c.scenario.__name__} returned columns {sorted(clash)} that name a run key, "
                              "a parameter or a timing column")
        head = pd.DataFrame({"run": runs, "point": point, "replicate": replicate, "seed": seeds})
        params = self._params.iloc[point].reset_index(drop=True)
        timing = pd.DataFrame({"worker": np.repeat([w for *_, w, _ in results], counts),
                               "elapsed_s": np.repeat([e for *_, e in results], counts).astype(float)})
        return pd.concat([head, params, body, timing], axis=1)

    def write(self, rows: pd.DataFrame) -> None:
        """Write stored rows (:meth:`rows`) at once: one file per point, each written to a
        temporary name and renamed, so a file on disk is always whole."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        for point, part in rows.groupby("point", sort=True):
            d = self.dataset.runs / f"point={int(point)}"
            d.mkdir(exist_ok=True)
            target = d / f"part-{int(part['run'].min()):09d}.parquet"
            tmp = d / f".tmp-{uuid.uuid4().hex}"
            pq.write_table(pa.Table.from_pandas(part.drop(columns="point"), preserve_index=False), tmp)
            os.replace(tmp, target)


class _Dataset:
    """The runs on disk of the campaign in ``folder`` (read without its scenario's code)."""

    def __init__(self, folder: Path):
        self.runs = folder / "runs"
        self.name = folder.name

    def _files(self) -> list[Path]:
        return sorted(self.runs.glob("point=*/part-*.parquet"))

    def done(self) -> set[int]:
        """The ids of the runs on disk."""
        import pyarrow.parquet as pq

        out: set[int] = set()
        for f in self._files():
            out.update(pq.read_table(f, columns=["run"]).column("run").to_pylist())
        return out

    def _frame(self) -> pd.DataFrame:
        import pyarrow as pa
        import pyarrow.dataset as ds

        if not self._files():
            return pd.DataFrame()
        hive = ds.partitioning(pa.schema([("point", pa.int64())]), flavor="hive")
        try:
            df = ds.dataset(self.runs, format="parquet", partitioning=hive).to_table().to_pandas()
        except pa.ArrowInvalid as e:
            raise input_error("scenario", f"the runs of {self.name!r} returned different columns ({e})") from None
        columns = list(df.columns)
        columns.remove("point")
        columns.insert(1, "point")
        return df[columns].sort_values("run", kind="stable").reset_index(drop=True)

    def table(self) -> pd.DataFrame:
        """Every finished run, sorted by run id (keys, parameters, the scenario's columns)."""
        df = self._frame()
        return df.drop(columns=[c for c in TIMING if c in df.columns])

    def timing(self) -> pd.DataFrame:
        """One row per finished run: run, point, worker, elapsed_s (s)."""
        df = self._frame()
        if df.empty:
            return pd.DataFrame({"run": [], "point": [], "worker": [], "elapsed_s": []})
        return df.groupby("run", sort=True).first().reset_index()[["run", "point", "worker", "elapsed_s"]]


def _parameter_frame(campaign: Campaign) -> pd.DataFrame:
    """One row per point, one column per parameter that varies or is fixed (lists as JSON text)."""
    names = [k for k in campaign.varied()] + [k for k in campaign.fixed if k not in campaign.varied()]
    rows = []
    for i in range(campaign.n_points):
        p = campaign.point(i)
        rows.append({k: json.dumps(list(p[k])) if isinstance(p[k], (list, tuple)) else p[k] for k in names})
    return pd.DataFrame(rows, columns=names)
