"""Running a campaign: in this process (a thread pool; the core's own loops release the
GIL) or on a Dask cluster, writing every finished run to the campaign's Parquet dataset at
once and resuming from it."""

from __future__ import annotations

import math
import os
import time
from collections import deque
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

import pandas as pd

from .._validate import flag, instance, integer
from .plan import Campaign
from .scenario import _checked_table
from .store import _Dataset, _Store

#: Length of one Dask task (s) the automatic batching aims at: at ≈ 5 ms of scheduler and
#: transfer cost per task, it keeps the overhead near 0.5 % of the run time.
TASK_S = 1.0
#: Tasks in flight per worker thread (bounds the results held on the client).
IN_FLIGHT = 2
#: In this process, finished runs are written together at most this often (s), and at once
#: on an interruption or an error.
FLUSH_S = 0.25


def _execute(campaign: Campaign, runs: list[int], worker: str) -> list[tuple[int, pd.DataFrame, str, float]]:
    """Runs ``runs`` of ``campaign``: (run id, table, worker, elapsed s) each."""
    out = []
    for r in runs:
        t0 = time.perf_counter()
        params = campaign.point(r // campaign.seeds)
        table = _checked_table(campaign.scenario(seed=campaign.run_seed(r), **params), campaign.scenario)
        out.append((r, table, worker, time.perf_counter() - t0))
    return out


def _on_worker(campaign: Campaign, runs: list[int]):
    from distributed import get_worker

    return _execute(campaign, runs, str(get_worker().name))


class _Writer:
    """Collects finished runs and writes them; reports progress."""

    def __init__(self, store: _Store, bar, callback, total: int, done: int):
        self.store, self.bar, self.callback, self.total, self.done = store, bar, callback, total, done
        self.pending: list = []
        self.last = time.monotonic()

    def add(self, results) -> None:
        self.pending.extend(results)

    def flush(self, force: bool = True) -> None:
        if not self.pending or (not force and time.monotonic() - self.last < FLUSH_S):
            return
        n = len(self.pending)
        self.store.write(self.store.rows(self.pending))
        self.pending, self.last = [], time.monotonic()
        self.done += n
        self.bar.update(n)
        if self.callback is not None:
            self.callback(self.done, self.total)


def _in_process(campaign: Campaign, missing: list[int], writer: _Writer, threads: int) -> None:
    queue = deque(missing)
    pool = ThreadPoolExecutor(max_workers=threads)
    running = set()
    try:
        while queue or running:
            while queue and len(running) < threads:
                running.add(pool.submit(_execute, campaign, [queue.popleft()], "local"))
            finished, running = wait(running, return_when=FIRST_COMPLETED)
            for f in finished:
                writer.add(f.result())
            writer.flush(force=not queue and not running)
    except BaseException:
        writer.flush()
        raise
    finally:
        pool.shutdown(wait=False, cancel_futures=True)


def _batch_size(batch: int | None, per_run_s: float | None, left: int, slots: int) -> int:
    if batch is not None:
        return batch
    if per_run_s is None:
        return 1
    return max(1, min(math.ceil(TASK_S / max(per_run_s, 1e-9)), math.ceil(left / slots)))


def _dask(campaign: Campaign, missing: list[int], writer: _Writer, client, batch: int | None) -> None:
    from distributed import as_completed

    slots = max(1, sum(client.nthreads().values()))
    queue = deque(missing)
    per_run: list[float] = []

    def send(size: int):
        ids = [queue.popleft() for _ in range(min(size, len(queue)))]
        return client.submit(_on_worker, campaign, ids, pure=False)

    futures = as_completed([send(1 if batch is None else batch) for _ in range(min(slots, len(queue)))], loop=client.loop)
    flying = futures.count()
    try:
        for fut in futures:
            flying -= 1
            results = fut.result()
            per_run.extend(e for *_, e in results)
            writer.add(results)
            writer.flush()
            size = _batch_size(batch, sum(per_run) / len(per_run), len(queue), slots)
            while queue and flying < IN_FLIGHT * slots:
                futures.add(send(size))
                flying += 1
    except BaseException:
        client.cancel(list(futures.futures))
        writer.flush()
        raise


def run(campaign: Campaign, folder, *, client=None, scheduler: str | None = None, batch: int | None = None,
        threads: int | None = None, progress: bool = True, callback=None) -> pd.DataFrame:
    """Run a campaign, writing every finished run to ``folder`` at once; resume it.

    Runs already on disk are not run again: calling ``run`` again with the same campaign
    and folder after an interruption (Ctrl-C, an error, a killed process or worker)
    computes only what is missing, and the table equals that of an uninterrupted run.

    Parameters
    ----------
    campaign : Campaign
        What to run.
    folder : str or path-like
        Output folder; the campaign's dataset is ``folder/<campaign.name>/``
        (:mod:`atomnav.campaign.store`).
    client : dask.distributed.Client, optional
        Run on this Dask cluster. A worker lost mid-campaign costs only its tasks in
        flight, which Dask runs again elsewhere.
    scheduler : str, optional
        Address of a Dask scheduler (``"tcp://host:8786"``) to connect to instead of
        ``client``.
    batch : int, optional
        Runs per Dask task; default: one run per task at first, then as many as take
        about :data:`TASK_S` s by the measured run time.
    threads : int, optional
        Threads in this process (without ``client`` or ``scheduler``); default the
        number of cores.
    progress : bool, default True
        Show a progress bar over runs.
    callback : callable, optional
        ``callback(done, total)`` after each write; an exception it raises stops the
        campaign (what is written stays).

    Returns
    -------
    pandas.DataFrame
        Every run, sorted by run id: ``run``, ``point``, ``replicate``, ``seed``, one
        column per parameter that varies or is fixed (lists as JSON text), then the
        scenario's columns (``time_s`` first). Run times are in :func:`timing`.

    Raises
    ------
    atomnav.InputError
        ``folder`` holds another campaign under this name, or ``seed`` is used by another
        campaign in ``folder``; ``batch``/``threads`` out of range.
    TypeError
        ``campaign`` not a :class:`Campaign`, both ``client`` and ``scheduler`` given.
    ConnectionError
        ``scheduler`` cannot be reached.
    """
    from tqdm.auto import tqdm

    instance(campaign, Campaign, "campaign")
    progress = flag(progress, "progress")
    batch = None if batch is None else integer(batch, "batch", 1, 1_000_000)
    threads = (os.cpu_count() or 1) if threads is None else integer(threads, "threads", 1, 1024)
    if callback is not None and not callable(callback):
        raise TypeError(f"callback: expected a callable callback(done, total), got {type(callback).__name__}")
    if client is not None and scheduler is not None:
        raise TypeError("client, scheduler: give one of them, not both")
    if client is not None and not callable(getattr(client, "submit", None)):
        raise TypeError(f"client: expected a dask.distributed Client or None, got {type(client).__name__}")
    if scheduler is not None:
        instance(scheduler, str, "scheduler")
    store = _Store(folder, campaign)
    done = store.dataset.done()
    missing = [r for r in range(campaign.n_runs) if r not in done]
    with tqdm(total=campaign.n_runs, initial=len(done), desc=campaign.name, disable=not progress, unit="run") as bar:
        writer = _Writer(store, bar, callback, campaign.n_runs, len(done))
        if missing and client is None and scheduler is None:
            _in_process(campaign, missing, writer, threads)
        elif missing:
            own = _connect(scheduler) if scheduler is not None else None
            try:
                _dask(campaign, missing, writer, client if own is None else own, batch)
            finally:
                if own is not None:
                    own.close()
    return store.dataset.table()


def _connect(address: str):
    from distributed import Client

    from .._validate import input_error

    try:
        return Client(address, timeout="10s")
    except (OSError, TimeoutError) as e:
        raise ConnectionError(f"scheduler: cannot connect to {address} ({e})") from None
    except ValueError as e:  # an address Dask cannot parse (no port, unknown protocol)
        raise input_error("scheduler", f"{address!r} is not a scheduler address such as tcp://host:8786 ({e})") from None


def load(folder, name: str) -> pd.DataFrame:
    """The table of the campaign ``name`` in ``folder`` (as :func:`run` returns it).

    Parameters
    ----------
    folder : str or path-like
        The output folder given to :func:`run`.
    name : str
        The campaign's name.

    Returns
    -------
    pandas.DataFrame
        The finished runs, sorted by run id.

    Raises
    ------
    atomnav.InputError
        No campaign ``name`` in ``folder`` (naming ``name``).
    """
    return _stored(folder, name).table()


def timing(folder, name: str) -> pd.DataFrame:
    """Run times of the campaign ``name`` in ``folder``: one row per run with ``run``,
    ``point``, ``worker`` (``"local"`` in this process, else the Dask worker's name) and
    ``elapsed_s`` (s, the scenario call alone).

    Parameters
    ----------
    folder : str or path-like
        The output folder given to :func:`run`.
    name : str
        The campaign's name.

    Returns
    -------
    pandas.DataFrame
        One row per finished run.

    Raises
    ------
    atomnav.InputError
        No campaign ``name`` in ``folder`` (naming ``name``).
    """
    return _stored(folder, name).timing()


def _stored(folder, name: str) -> _Dataset:
    from .._validate import input_error, path

    d = path(folder, "folder") / instance(name, str, "name")
    if not (d / "campaign.json").is_file():
        raise input_error("name", f"no campaign {name!r} in {folder}")
    return _Dataset(d)
