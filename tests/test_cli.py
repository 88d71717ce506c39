"""The ``atomnav`` command line, through a subprocess as a user runs it: version, argparse
errors, the section list, a real quick section (table width, summary line, exit status),
and the fixed verdict vocabulary of the report."""

from __future__ import annotations

import re
import subprocess
import sys
from importlib.metadata import version

import pytest

import atomnav
from atomnav import cli, reproduce


def _atomnav(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "atomnav.cli", *args], capture_output=True, text=True, timeout=600, cwd=cwd)


def test_version():
    run = _atomnav("--version")
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == f"atomnav {version('atomnav')}"


def test_unknown_section_is_a_usage_error_listing_the_sections():
    run = _atomnav("reproduce", "--only", "strapdown", "nosuch")
    assert run.returncode == 2
    assert "Traceback" not in run.stderr and run.stderr.startswith("usage: atomnav reproduce")
    assert "nosuch" in run.stderr
    for name in reproduce.discover():
        assert name in run.stderr


def test_list():
    run = _atomnav("reproduce", "--list")
    assert run.returncode == 0, run.stderr
    listed = [line.split()[0] for line in run.stdout.splitlines() if not line.startswith(" ")]
    assert listed == sorted(reproduce.discover())
    assert max(map(len, run.stdout.splitlines())) <= reproduce.WIDTH


def test_every_command_and_option_is_described():
    top, rep = cli.parsers()
    assert top.description and rep.description
    for parser in (top, rep):
        for action in parser._actions:
            assert action.help, (parser.prog, action.option_strings or action.dest)


def _markdown_verdicts(text: str) -> list[str]:
    """The verdict cells (fourth column) of the report's Markdown tables."""
    verdicts = []
    for line in text.splitlines():
        cells = [c.strip() for c in re.split(r"(?<!\\)\|", line)[1:-1]]
        if len(cells) == 5 and cells[0] not in ("quantity", "---"):
            verdicts.append(cells[3])
    return verdicts


def test_quick_section_fits_the_terminal_and_ends_with_the_summary(tmp_path):
    run = _atomnav("reproduce", "--quick", "--only", "cai_tennstedt2023", "--out", str(tmp_path / "report"))
    assert run.returncode == 0, run.stderr
    lines = run.stdout.splitlines()
    assert max(map(len, lines)) <= 120, max(lines, key=len)
    verdicts = _markdown_verdicts((tmp_path / "report" / "report.md").read_text())
    assert len(verdicts) >= 15 and set(verdicts) <= {"pass", "FAIL", "not reproduced", "reported"}
    counts = {v: verdicts.count(v) for v in ("pass", "FAIL", "not reproduced", "reported")}
    assert counts["not reproduced"] >= 1 and counts["reported"] >= 1  # the section exercises three of the words
    assert lines[-1] == (f"{counts['pass']} pass, {counts['FAIL']} FAIL, {counts['not reproduced']} not reproduced, "
                         f"{counts['reported']} reported")
    # the terminal wraps long cells; the Markdown keeps them whole
    long = "predictor − inertial oracle, 1 kHz, 0.05 rad/s, l = 0.3 m, vibration (cubic) [rad], Tennstedt et al. 2023"
    assert long in (tmp_path / "report" / "report.md").read_text() and long not in run.stdout


def _fake_section(*rows):
    def fn(report):
        for verdict in rows:
            report.row("a quantity", 1.0, 1.0, verdict)

    return {"fake": ("A fake section", fn)}


@pytest.mark.parametrize("rows,status,summary", [
    ((True, False), 1, "1 pass, 1 FAIL, 0 not reproduced, 0 reported"),
    ((True, "reported"), 0, "1 pass, 0 FAIL, 0 not reproduced, 1 reported"),
])
def test_exit_status_is_1_on_any_fail(monkeypatch, capsys, tmp_path, rows, status, summary):
    monkeypatch.setattr(reproduce, "discover", lambda: _fake_section(*rows))
    assert cli.main(["reproduce", "--only", "fake", "--out", str(tmp_path), "--no-progress"]) == status
    assert capsys.readouterr().out.splitlines()[-1] == summary


def test_verdicts_come_from_one_vocabulary(tmp_path):
    rep = reproduce.Report(outdir=tmp_path, section="fake")
    with pytest.raises(atomnav.InputError) as e:
        rep.row("a quantity", 1.0, 1.0, "ratio 1.00")
    assert e.value.parameter == "verdict"
    with pytest.raises(atomnav.InputError) as e:
        rep.row("a quantity", 1.0, 2.0, reproduce.NOT_REPRODUCED)
    assert e.value.parameter == "note"
    rep.row("a quantity", 1.0, 2.0, reproduce.NOT_REPRODUCED, "docs/departures.md")
    assert [r["verdict"] for r in rep.rows] == ["not reproduced"]



def test_run_names_an_unknown_section_for_python_callers(tmp_path):
    with pytest.raises(atomnav.InputError, match="nosuch") as e:
        reproduce.run(tmp_path, only=["strapdown", "nosuch"])
    assert e.value.parameter == "only" and "strapdown" in str(e.value)
