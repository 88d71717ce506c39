"""Where a campaign's runs live: a Parquet dataset per campaign, partitioned by parameter
point, with the campaign's configuration beside it as JSON.

``folder/<name>/campaign.json`` holds :meth:`Campaign.to_dict`;
``folder/<name>/runs/point=<k>/part-<first run>.parquet`` hold the finished runs of point
k, each file written whole (to a temporary name, then renamed), so a process killed at any
moment leaves only complete files. A folder holds any number of campaigns under their
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
        self.runs_dir = self.dir / "runs"
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
        self.runs_dir.mkdir(parents=True, exist_ok=True)
        if not config.exists():
            tmp = config.with_name(f".campaign.json.{uuid.uuid4().hex}")
            tmp.write_text(campaign.to_json())
            os.replace(tmp, config)
        self._params = _parameter_frame(campaign)

    def _files(self) -> list[Path]:
        return sorted(self.runs_dir.glob("point=*/part-*.parquet"))

    def done(self) -> set[int]:
        """The ids of the runs on disk."""
        import pyarrow.parquet as pq

        out: set[int] = set()
        for f in self._files():
            out.update(pq.read_table(f, columns=["run"]).column("run").to_pylist())
        return out

    def rows(self, run: int, table: pd.DataFrame, worker: str, elapsed_s: float) -> pd.DataFrame:
        """Run ``run``'s table with its keys, parameters and timing in front."""
        c = self.campaign
        point, replicate = divmod(run, c.seeds)
        n = len(table)
        head = pd.DataFrame({"run": np.full(n, run, np.int64), "point": np.full(n, point, np.int64),
                             "replicate": np.full(n, replicate, np.int64), "seed": np.full(n, c.run_seed(run), np.uint64)})
        params = self._params.iloc[[point] * n].reset_index(drop=True)
        timing = pd.DataFrame({"worker": [worker] * n, "elapsed_s": np.full(n, elapsed_s)})
        clash = set(table.columns) & (set(KEYS) | set(params.columns) | set(TIMING))
        if clash:
            raise input_error("scenario", f"{c.scenario.__name__} returned columns {sorted(clash)} that name a run key, "
                              "a parameter or a timing column")
        return pd.concat([head, params, table.reset_index(drop=True), timing], axis=1)

    def write(self, rows: pd.DataFrame) -> None:
        """Write finished runs (frames of :meth:`rows`, concatenated) at once, one file per point."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        for point, part in rows.groupby("point", sort=True):
            d = self.runs_dir / f"point={int(point):06d}"
            d.mkdir(exist_ok=True)
            target = d / f"part-{int(part['run'].min()):09d}.parquet"
            tmp = d / f".tmp-{uuid.uuid4().hex}"
            pq.write_table(pa.Table.from_pandas(part, preserve_index=False), tmp)
            os.replace(tmp, target)

    def _frame(self) -> pd.DataFrame:
        import pyarrow as pa
        import pyarrow.parquet as pq

        files = self._files()
        if not files:
            return pd.DataFrame()
        try:
            whole = pa.concat_tables([pq.read_table(f) for f in files])
        except pa.ArrowInvalid as e:
            raise input_error("scenario", f"the runs of {self.campaign.name!r} returned different columns ({e})") from None
        df = whole.to_pandas()
        return df.sort_values("run", kind="stable").reset_index(drop=True)

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
