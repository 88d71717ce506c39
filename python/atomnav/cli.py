"""Command line: ``atomnav --version``, ``atomnav reproduce [--out DIR] [--only NAME ...] [--quick] [--list]`` and
``atomnav campaign FILE [--scheduler ADDRESS | --workers N] [--no-progress]``."""

from __future__ import annotations

import argparse
import contextlib
import importlib.util
import sys
import textwrap
import time
from pathlib import Path

DESCRIPTION = ("atomnav: hybrid quantum-classical inertial navigation (strapdown INS, cold-atom-interferometer "
               "aiding, GNSS and star-camera aiding, sensor-noise analysis).")
REPRODUCE = ("Reproduce the implemented papers' results side by side with the papers: a table on the terminal, "
             "and a Markdown report with PNG plots in the report folder. Each row's verdict is pass, FAIL, "
             "not reproduced (a claim atomnav does not reach; the note says why) or reported (a number without a "
             "claim to test). Exits with status 1 when any row is FAIL (the report is written either way).")
CAMPAIGN = ("Run a design study described by a campaign file (TOML or YAML: the scenario, its parameter grid or points, "
            "seeds, output folder and executor; the format is in atomnav.campaign.config_file). Every finished run is "
            "written at once to OUTPUT/NAME/ (Parquet files and campaign.json); running the same file again resumes it, "
            "computing only the runs missing there. A scenario 'module:function' is imported with the file's folder on "
            "the module path. Exits with status 0 when every run is done, 2 for a bad file or option, 1 when the runs "
            "cannot execute (an unreachable scheduler), 130 when interrupted (Ctrl-C).")


def version() -> str:
    """The installed distribution's version, or the package's own when not installed."""
    from importlib.metadata import PackageNotFoundError, version as installed

    try:
        return installed("atomnav")
    except PackageNotFoundError:
        from . import __version__

        return __version__


def parsers() -> tuple[argparse.ArgumentParser, argparse.ArgumentParser]:
    """The ``atomnav`` argument parser and its ``reproduce`` subcommand's (each subcommand's
    parser is also its arguments' ``parser``)."""
    top = argparse.ArgumentParser(prog="atomnav", description=DESCRIPTION)
    top.add_argument("--version", action="version", version=f"%(prog)s {version()}", help="print the version and exit")
    sub = top.add_subparsers(dest="command", required=True, metavar="COMMAND", help="the command to run")
    rep = sub.add_parser("reproduce", help="reproduce the source papers' results and write a report", description=REPRODUCE)
    rep.add_argument("--out", default="reproduce_report", metavar="DIR", help="report folder (default: %(default)s)")
    rep.add_argument("--only", nargs="+", metavar="SECTION", help="run only these sections (see --list)")
    rep.add_argument("--quick", action="store_true", help="reduced sizes, as the test suite runs them (minutes instead of tens of minutes)")
    rep.add_argument("--list", action="store_true", help="list the sections and exit")
    rep.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bars on stderr")
    rep.set_defaults(parser=rep)
    camp = sub.add_parser("campaign", help="run or resume a design study described by a TOML or YAML file",
                          description=CAMPAIGN)
    camp.add_argument("file", metavar="FILE", help="the campaign file (.toml, .yaml or .yml)")
    where = camp.add_mutually_exclusive_group()
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="run on the dask.distributed cluster of this scheduler (tcp://host:port) instead of the "
                            "file's [executor]")
    where.add_argument("--workers", type=int, metavar="N",
                       help="run on a local cluster of N single-threaded worker processes instead of the file's [executor]")
    camp.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar on stderr")
    camp.set_defaults(parser=camp)
    return top, rep


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (0, or 1 when a reproduced row is FAIL)."""
    top, rep = parsers()
    args = top.parse_args(argv)
    if args.command == "campaign":
        return _campaign(args)

    from . import reproduce

    sections = reproduce.discover()
    if args.list:
        for name, (title, _) in sections.items():
            print(textwrap.fill(title, reproduce.WIDTH, initial_indent=f"{name:24s} ", subsequent_indent=" " * 25))
        return 0
    unknown = sorted(set(args.only or ()) - set(sections))
    if unknown:
        rep.error(
            f"--only: unknown section(s) {', '.join(unknown)}; known sections: {', '.join(sections)}")
    table = reproduce.run(args.out, only=args.only, quick=args.quick, progress=args.progress)
    return 1 if (table["verdict"] == reproduce.FAIL).any() else 0


def _campaign(args: argparse.Namespace) -> int:
    """Run or resume the campaign file ``args.file``, print a summary; returns the exit status."""
    from ._core import InputError
    from ._validate import renamed
    from .campaign import config_file, run, timing

    parser = args.parser
    if args.workers is not None and args.workers < 1:
        parser.error(f"--workers: must be ≥ 1, got {args.workers}")
    try:
        study_file = config_file.load(args.file)
        sys.path.insert(0, str(Path(args.file).resolve().parent))
        study = study_file.campaign()
    except (InputError, TypeError) as e:
        parser.error(f"{args.file}: {str(e).removeprefix('path: ') if getattr(e, 'parameter', None) == 'path' else e}")
    except (OSError, ImportError) as e:
        parser.error(f"{args.file}: {getattr(e, 'strerror', None) or e}")
    where = study_file.executor if args.workers is None and args.scheduler is None else config_file.Executor(args.scheduler, args.workers)
    if (where.workers or where.scheduler) and importlib.util.find_spec("distributed") is None:
        parser.error("a cluster (--workers, --scheduler or [executor]) needs dask.distributed: "
                     "pip install 'atomnav[dask]'")
    try:
        before = len(timing(study_file.output, study.name))
    except InputError:  # no campaign of this name in the folder yet
        before = 0
    t0 = time.perf_counter()
    try:
        with renamed(folder="output"), _local_cluster(where.workers if before < study.n_runs else None) as client:
            table = run(study, study_file.output, client=client, scheduler=where.scheduler, progress=args.progress)
    except InputError as e:  # another campaign in the folder, a parameter value the scenario rejects
        parser.error(f"{args.file}: {e}")
    except ConnectionError as e:
        print(f"{parser.prog}: error: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print(f"{parser.prog}: interrupted with {len(timing(study_file.output, study.name))} of {study.n_runs} runs in "
              f"{study_file.output / study.name}; run the same command again to resume", file=sys.stderr)
        return 130
    done = table["run"].nunique() if len(table) else 0
    print(f"{study.name}: {done - before} new runs, {before} resumed, {done} of {study.n_runs} done, in "
          f"{study_file.output / study.name} ({time.perf_counter() - t0:.1f} s)")
    return 0


@contextlib.contextmanager
def _local_cluster(workers: int | None):
    """A client of a LocalCluster of ``workers`` single-threaded processes (None: no client)."""
    if workers is None:
        yield None
        return
    import logging

    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=":0",
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        yield client


if __name__ == "__main__":
    sys.exit(main())
