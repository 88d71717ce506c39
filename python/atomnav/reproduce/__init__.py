"""``atomnav reproduce``: every paper reproduction, side by side with the paper.

A section is a module in this package that decorates one function with
:func:`section`. The function receives a :class:`Report` and adds rows (quantity,
paper value, atomnav value, verdict) and figures to it. Sections are discovered by
importing every module here, so adding a paper means adding one file.
"""

from __future__ import annotations

import importlib
import pkgutil
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import pandas as pd

_SECTIONS: dict[str, tuple[str, Callable]] = {}


def section(name: str, title: str):
    """Register ``fn(report)`` as the reproduction section ``name``."""

    def deco(fn):
        if name in _SECTIONS:
            raise RuntimeError(f"reproduce section {name!r} registered twice")
        _SECTIONS[name] = (title, fn)
        return fn

    return deco


@dataclass
class Report:
    """Collects the rows and figures of one section."""

    outdir: Path
    section: str
    quick: bool = False
    rows: list = field(default_factory=list)
    figures: list = field(default_factory=list)

    def row(self, quantity: str, paper, atomnav, verdict) -> None:
        """One table row. ``verdict`` is a bool (pass/fail), or a string such as a ratio."""
        if isinstance(verdict, bool):
            verdict = "pass" if verdict else "FAIL"
        self.rows.append({"section": self.section, "quantity": quantity, "paper": paper, "atomnav": atomnav, "verdict": verdict})

    def figure(self, fig, name: str, caption: str) -> Path:
        """Save a matplotlib figure as PNG in the report folder."""
        path = self.outdir / f"{self.section}_{name}.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        import matplotlib.pyplot as plt

        plt.close(fig)
        self.figures.append((path.name, caption))
        return path


def discover() -> dict[str, tuple[str, Callable]]:
    for mod in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{mod.name}")
    return dict(sorted(_SECTIONS.items()))


def _fmt(x) -> str:
    if isinstance(x, float):
        return f"{x:.6g}"
    return str(x)


def run(outdir: str | Path = "reproduce_report", only: list[str] | None = None, quick: bool = False) -> pd.DataFrame:
    """Run the sections (all, or those named in ``only``), print the table, and write
    ``outdir/report.md`` with the table and the PNG plots. Returns the table."""
    import matplotlib

    matplotlib.use("Agg")
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    sections = discover()
    if only:
        unknown = sorted(set(only) - set(sections))
        if unknown:
            raise ValueError(f"only: unknown section(s) {unknown}; known: {sorted(sections)}")
        sections = {k: v for k, v in sections.items() if k in only}
    reports = []
    for name, (title, fn) in sections.items():
        t0 = time.perf_counter()
        print(f"== {name}: {title}", flush=True)
        rep = Report(outdir=outdir, section=name, quick=quick)
        fn(rep)
        print(f"   ({time.perf_counter() - t0:.1f} s)", flush=True)
        reports.append((title, rep))
    table = pd.DataFrame([r for _, rep in reports for r in rep.rows], columns=["section", "quantity", "paper", "atomnav", "verdict"])
    shown = table.map(_fmt) if hasattr(table, "map") else table.applymap(_fmt)
    print()
    print(shown.to_string(index=False))
    lines = ["# atomnav reproduction report", ""]
    for title, rep in reports:
        lines += [f"## {rep.section}: {title}", "", "| quantity | paper | atomnav | ratio or pass |", "|---|---|---|---|"]
        lines += [f"| {r['quantity']} | {_fmt(r['paper'])} | {_fmt(r['atomnav'])} | {_fmt(r['verdict'])} |" for r in rep.rows]
        lines.append("")
        for fname, caption in rep.figures:
            lines += [f"![{caption}]({fname})", "", f"*{caption}*", ""]
    (outdir / "report.md").write_text("\n".join(lines))
    print(f"\nreport written to {outdir / 'report.md'}")
    return table
