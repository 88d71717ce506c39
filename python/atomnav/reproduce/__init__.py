"""``atomnav reproduce``: every paper reproduction, side by side with the paper.

A section is a module in this package that decorates one function with
:func:`section`. The function receives a :class:`Report` and adds rows (quantity,
paper value, atomnav value, verdict, note) and figures to it. Sections are discovered by
importing every module here, so adding a paper means adding one file.

Every row's verdict is one of four words:

``pass`` / ``FAIL``
    a claim of the paper (or an exact reference) tested against atomnav's number;
``not reproduced``
    a claim of the paper atomnav does not reach, the row's note saying why (a link
    to ``docs/departures.md``);
``reported``
    a number without a claim to test: the paper gives it without a criterion, or
    atomnav reports it without a paper value.
"""

from __future__ import annotations

import importlib
import pkgutil
import sys
import textwrap
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from .._validate import input_error

PASS, FAIL, NOT_REPRODUCED, REPORTED = "pass", "FAIL", "not reproduced", "reported"
#: The verdicts, in the order of the summary line.
VERDICTS = (PASS, FAIL, NOT_REPRODUCED, REPORTED)
#: Columns of the table :func:`run` returns.
COLUMNS = ["section", "quantity", "paper", "atomnav", "verdict", "note"]
#: Width of the terminal table (characters) and of its cells; the Markdown report keeps every cell whole.
WIDTH = 120
_CELLS = {"quantity": 46, "paper": 24, "atomnav": 24, "verdict": len(NOT_REPRODUCED)}
_GAP = "  "

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
    """Collects the rows and figures of one section. A section runs at reduced size when
    ``quick``, and passes ``progress`` to the ``progress=`` of its long runs (tqdm bars on
    stderr)."""

    outdir: Path
    section: str
    quick: bool = False
    progress: bool = False
    rows: list = field(default_factory=list)
    figures: list = field(default_factory=list)

    def row(self, quantity: str, paper, atomnav, verdict, note: str = "") -> None:
        """One table row.

        Parameters
        ----------
        quantity : str
            What is compared, with its unit and the paper's equation, table or figure.
        paper, atomnav
            The paper's value (or claim) and atomnav's value.
        verdict : bool or str
            A bool is ``pass`` (True) or ``FAIL`` (False); otherwise one of
            :data:`VERDICTS`.
        note : str
            Anything else the reader needs (a ratio, a reference, why a claim is not
            reproduced); required for ``not reproduced``.
        """
        if isinstance(verdict, (bool, np.bool_)):
            verdict = PASS if verdict else FAIL
        elif verdict not in VERDICTS:
            raise input_error("verdict", f"must be a bool or one of {list(VERDICTS)}, got {verdict!r}")
        if verdict == NOT_REPRODUCED and not note:
            raise input_error("note", "a 'not reproduced' row says why (a link to docs/departures.md)")
        self.rows.append({"section": self.section, "quantity": quantity, "paper": paper, "atomnav": atomnav,
                          "verdict": verdict, "note": note})

    def figure(self, fig, name: str, caption: str) -> Path:
        """Save a matplotlib figure as PNG in the report folder."""
        path = self.outdir / f"{self.section}_{name}.png"
        fig.savefig(path, dpi=110, bbox_inches="tight")
        import matplotlib.pyplot as plt

        plt.close(fig)
        self.figures.append((path.name, caption))
        return path


def discover() -> dict[str, tuple[str, Callable]]:
    """Every registered section, by name: (title, function), sorted by name."""
    for mod in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{mod.name}")
    return dict(sorted(_SECTIONS.items()))


def _fmt(x) -> str:
    if isinstance(x, (float, np.floating)):
        return f"{x:.6g}"
    return str(x)


def summary(table: pd.DataFrame) -> str:
    """``N pass, N FAIL, N not reproduced, N reported`` of a table :func:`run` returned."""
    return ", ".join(f"{int((table['verdict'] == v).sum())} {v}" for v in VERDICTS)


def _clip(text: str, width: int = WIDTH) -> str:
    return text if len(text) <= width else text[: width - 1] + "…"


def _terminal(table: pd.DataFrame) -> str:
    """The table in at most :data:`WIDTH` columns: long cells wrap, notes go on their own
    indented lines, each section under its name."""
    cols = list(_CELLS)

    def line(cells) -> str:
        return _GAP.join(c.ljust(_CELLS[k]) for k, c in zip(cols, cells)).rstrip()

    out = [line(cols), line("-" * w for w in _CELLS.values())]
    for name, rows in table.groupby("section", sort=False):
        out.append(f"[{name}]")
        for _, r in rows.iterrows():
            wrapped = [textwrap.wrap(_fmt(r[k]), _CELLS[k], break_on_hyphens=False) or [""] for k in cols]
            out += [line(w[i] if i < len(w) else "" for w in wrapped) for i in range(max(map(len, wrapped)))]
            if r["note"]:
                out += textwrap.wrap(str(r["note"]), WIDTH, initial_indent="    note: ", subsequent_indent="          ",
                                     break_on_hyphens=False)
    return "\n".join(out)


def _cell(x) -> str:
    return _fmt(x).replace("|", "\\|")


def _markdown(reports, table: pd.DataFrame) -> str:
    lines = ["# atomnav reproduction report", ""]
    for title, rep in reports:
        lines += [f"## {rep.section}: {title}", "", "| quantity | paper | atomnav | verdict | note |", "|---|---|---|---|---|"]
        lines += ["| " + " | ".join(_cell(r[k]) for k in COLUMNS[1:]) + " |" for r in rep.rows]
        lines.append("")
        for fname, caption in rep.figures:
            lines += [f"![{caption}]({fname})", "", f"*{caption}*", ""]
    lines += [f"**{summary(table)}**", ""]
    return "\n".join(lines)


def run(outdir: str | Path = "reproduce_report", only: list[str] | None = None, quick: bool = False,
        progress: bool = False) -> pd.DataFrame:
    """Run the sections (all, or those named in ``only``), print the table and the
    summary line, and write ``outdir/report.md`` with the table and the PNG plots.

    Parameters
    ----------
    outdir : str or Path
        Report folder (created if missing).
    only : list of str, optional
        Section names (see :func:`discover`); an unknown name is an ``InputError``.
    quick : bool
        Reduced sizes, as the test suite runs them.
    progress : bool
        tqdm progress bars (on stderr) over the sections and inside the long ones.

    Returns
    -------
    pandas.DataFrame
        One row per compared quantity, columns :data:`COLUMNS`.
    """
    from tqdm.auto import tqdm
    import matplotlib

    matplotlib.use("Agg")
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    sections = discover()
    if only:
        unknown = sorted(set(only) - set(sections))
        if unknown:
            raise input_error("only", f"unknown section(s) {unknown}; known: {sorted(sections)}")
        sections = {k: v for k, v in sections.items() if k in only}
    reports = []
    with tqdm(total=len(sections), desc="reproduce", unit="section", disable=not progress) as bar:
        for name, (title, fn) in sections.items():
            t0 = time.perf_counter()
            bar.set_postfix_str(name)
            tqdm.write(_clip(f"== {name}: {title}"), file=sys.stdout)
            rep = Report(outdir=outdir, section=name, quick=quick, progress=progress)
            fn(rep)
            tqdm.write(f"   ({time.perf_counter() - t0:.1f} s)", file=sys.stdout)
            reports.append((title, rep))
            bar.update()
    table = pd.DataFrame([r for _, rep in reports for r in rep.rows], columns=COLUMNS)
    print()
    print(_terminal(table))
    (outdir / "report.md").write_text(_markdown(reports, table))
    print(_clip(f"\nreport written to {outdir / 'report.md'}"))
    print(summary(table), flush=True)
    return table
