"""Command line: ``atomnav --version`` and ``atomnav reproduce [--out DIR] [--only NAME ...] [--quick] [--list]``."""

from __future__ import annotations

import argparse
import sys
import textwrap

DESCRIPTION = ("atomnav: hybrid quantum-classical inertial navigation (strapdown INS, cold-atom-interferometer "
               "aiding, GNSS and star-camera aiding, sensor-noise analysis).")
REPRODUCE = ("Reproduce the implemented papers' results side by side with the papers: a table on the terminal, "
             "and a Markdown report with PNG plots in the report folder. Each row's verdict is pass, FAIL, "
             "not reproduced (a claim atomnav does not reach; the note says why) or reported (a number without a "
             "claim to test). Exits with status 1 when any row is FAIL (the report is written either way).")


def version() -> str:
    """The installed distribution's version, or the package's own when not installed."""
    from importlib.metadata import PackageNotFoundError, version as installed

    try:
        return installed("atomnav")
    except PackageNotFoundError:
        from . import __version__

        return __version__


def parsers() -> tuple[argparse.ArgumentParser, argparse.ArgumentParser]:
    """The ``atomnav`` argument parser and its ``reproduce`` subcommand's."""
    top = argparse.ArgumentParser(prog="atomnav", description=DESCRIPTION)
    top.add_argument("--version", action="version", version=f"%(prog)s {version()}", help="print the version and exit")
    sub = top.add_subparsers(dest="command", required=True, metavar="COMMAND", help="the command to run")
    rep = sub.add_parser("reproduce", help="reproduce the source papers' results and write a report", description=REPRODUCE)
    rep.add_argument("--out", default="reproduce_report", metavar="DIR", help="report folder (default: %(default)s)")
    rep.add_argument("--only", nargs="+", metavar="SECTION", help="run only these sections (see --list)")
    rep.add_argument("--quick", action="store_true", help="reduced sizes, as the test suite runs them (minutes instead of tens of minutes)")
    rep.add_argument("--list", action="store_true", help="list the sections and exit")
    rep.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bars on stderr")
    return top, rep


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status (0, or 1 when a reproduced row is FAIL)."""
    top, rep = parsers()
    args = top.parse_args(argv)

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


if __name__ == "__main__":
    sys.exit(main())
