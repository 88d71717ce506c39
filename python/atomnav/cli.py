"""Command line: ``atomnav reproduce [--out DIR] [--only NAME ...] [--quick] [--list]``."""

from __future__ import annotations

import argparse
import sys


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="atomnav", description="Hybrid quantum-classical inertial navigation.")
    sub = parser.add_subparsers(dest="command", required=True)
    rep = sub.add_parser("reproduce", help="reproduce the source papers' results and write a report")
    rep.add_argument("--out", default="reproduce_report", help="report folder (default: %(default)s)")
    rep.add_argument("--only", nargs="+", metavar="SECTION", help="run only these sections")
    rep.add_argument("--quick", action="store_true", help="reduced sizes (as the test suite runs them)")
    rep.add_argument("--list", action="store_true", help="list the sections and exit")
    args = parser.parse_args(argv)

    from . import reproduce

    if args.list:
        for name, (title, _) in reproduce.discover().items():
            print(f"{name:24s} {title}")
        return 0
    table = reproduce.run(args.out, only=args.only, quick=args.quick)
    return 1 if (table["verdict"] == "FAIL").any() else 0


if __name__ == "__main__":
    sys.exit(main())
