"""``atomnav campaign FILE``, through a subprocess as a user runs it: a TOML campaign and
the same campaign in YAML write the table an in-process :func:`atomnav.campaign.run`
gives, each run's rows equal to a direct call of the scenario with the seed
``SeedSequence(seed, spawn_key=(r,))`` (NumPy's parallel-streams recipe); running the file
again computes nothing, and after losing a point's file computes only that point; a bad
file is a usage error (status 2) naming its key; an unreachable scheduler ends the command
with status 1 and a message, no traceback.

The scenario is ``campaign_toy:random_walk`` (tests/campaign_toy.py), imported through
``PYTHONPATH`` as a user's own module would be."""

from __future__ import annotations

import itertools
import os
import pickle
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import campaign_toy
from atomnav import campaign, cli
from atomnav.campaign.config_file import CampaignFile, Executor, load

TESTS = Path(__file__).resolve().parent
SEED, SEEDS = 5, 3
GRID = {"steps": [10, 20], "sigma_m": [[1.0, 1.0, 1.0], [0.5, 0.5, 2.0]]}
FIXED = {"dt_s": 0.5}

TOML = f"""\
scenario = "campaign_toy:random_walk"
name = "walk"
seeds = {SEEDS}
seed = {SEED}
output = "out"

[grid]
steps = [10, 20]
sigma_m = [[1.0, 1.0, 1.0], [0.5, 0.5, 2.0]]

[fixed]
dt_s = 0.5
"""

YAML = f"""\
scenario: campaign_toy:random_walk
name: walk
seeds: {SEEDS}
seed: {SEED}
output: out
grid:
  steps: [10, 20]
  sigma_m:
    - [1.0, 1.0, 1.0]
    - [0.5, 0.5, 2.0]
fixed:
  dt_s: 0.5
"""


def _atomnav(*args: str, timeout: float = 300, tests_on_path: bool = True) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(TESTS) if tests_on_path else "",
                                                                     os.environ.get("PYTHONPATH")]))}
    return subprocess.run([sys.executable, "-m", "atomnav.cli", "campaign", *args], capture_output=True, text=True,
                          timeout=timeout, env=env)


def _write(folder: Path, name: str, text: str) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text(text)
    return folder / name


@pytest.fixture(scope="module")
def in_process(tmp_path_factory):
    """The same campaign, built and run in this process."""
    study = campaign.Campaign(campaign_toy.random_walk, GRID, seeds=SEEDS, seed=SEED, fixed=FIXED, name="walk")
    return campaign.run(study, tmp_path_factory.mktemp("in_process"), progress=False)


def _run_seed(r: int) -> int:
    words = np.random.SeedSequence(SEED, spawn_key=(r,)).generate_state(2, np.uint32)
    return int(words[0]) | (int(words[1]) << 32)


@pytest.mark.parametrize("name,text", [("campaign.toml", TOML), ("campaign.yaml", YAML)])
def test_file_writes_the_in_process_table_and_resumes(tmp_path, in_process, name, text):
    path = _write(tmp_path, name, text)
    first = _atomnav(str(path), "--no-progress")
    assert first.returncode == 0, first.stderr
    assert "Traceback" not in first.stderr
    n = len(GRID["steps"]) * len(GRID["sigma_m"]) * SEEDS
    assert first.stdout.startswith(f"walk: {n} new runs, 0 resumed, {n} of {n} done, in {tmp_path / 'out' / 'walk'} (")
    table = campaign.load(tmp_path / "out", "walk")
    pd.testing.assert_frame_equal(table, in_process)

    # each run's rows against a direct call: the grid in order (last key fastest), the run seed of the recipe
    points = [dict(zip(GRID, combo)) for combo in itertools.product(*GRID.values())]
    for r in range(n):
        rows = table[table["run"] == r].reset_index(drop=True)
        direct = campaign_toy.random_walk(seed=_run_seed(r), **FIXED, **points[r // SEEDS])
        assert (rows["seed"] == _run_seed(r)).all()
        np.testing.assert_array_equal(rows["time_s"], direct["time_s"])
        np.testing.assert_array_equal(rows["pos_error_m"], direct["pos_error_m"])

    again = _atomnav(str(path), "--no-progress")
    assert again.returncode == 0, again.stderr
    assert again.stdout.startswith(f"walk: 0 new runs, {n} resumed, {n} of {n} done")

    lost = sorted((tmp_path / "out" / "walk" / "runs" / "point=2").glob("*.parquet"))
    for f in lost:
        f.unlink()
    partial = _atomnav(str(path), "--no-progress")
    assert partial.returncode == 0, partial.stderr
    assert partial.stdout.startswith(f"walk: {SEEDS} new runs, {n - SEEDS} resumed, {n} of {n} done")
    pd.testing.assert_frame_equal(campaign.load(tmp_path / "out", "walk"), in_process)


def test_local_cluster_writes_the_in_process_table(tmp_path, in_process, monkeypatch):
    """Also: a scenario module beside the file is found, by the command and by its workers."""
    (tmp_path / "walk_of_mine.py").write_text((TESTS / "campaign_toy.py").read_text())
    path = _write(tmp_path, "campaign.toml", TOML.replace("campaign_toy:", "walk_of_mine:") + "\n[executor]\nworkers = 1\n")
    run = _atomnav(str(path), "--no-progress", "--workers", "2", tests_on_path=False)
    assert run.returncode == 0, run.stderr
    monkeypatch.setattr(sys, "path", [str(tmp_path), *sys.path])  # load() imports the scenario named in campaign.json
    pd.testing.assert_frame_equal(campaign.load(tmp_path / "out", "walk"), in_process)
    assert set(campaign.timing(tmp_path / "out", "walk")["worker"]) != {"local"}


def test_interrupt_keeps_whole_runs_and_says_how_to_resume(tmp_path):
    """Ctrl-C (SIGINT) mid-campaign: status 130, a one-line message, no traceback, and every
    run on disk whole and equal to a direct call of the scenario."""
    seeds = 2000  # ≈ 10 ms each: far longer than the wait for the first written run
    text = TOML.replace("seeds = 3", f"seeds = {seeds}").replace("steps = [10, 20]", "steps = [100000]")
    text = text.replace("sigma_m = [[1.0, 1.0, 1.0], [0.5, 0.5, 2.0]]", "sigma_m = [[1.0, 1.0, 1.0]]")
    path = _write(tmp_path, "campaign.toml", text)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(filter(None, [str(TESTS), os.environ.get("PYTHONPATH")]))}
    proc = subprocess.Popen([sys.executable, "-m", "atomnav.cli", "campaign", str(path), "--no-progress"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    runs = tmp_path / "out" / "walk" / "runs"
    deadline = time.monotonic() + 120
    while not list(runs.glob("point=*/part-*.parquet")) and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, err
    assert "Traceback" not in err and out == ""
    table = campaign.load(tmp_path / "out", "walk")
    done = sorted(set(table["run"]))
    assert 0 < len(done) < seeds
    assert err.strip() == (f"atomnav campaign: interrupted with {len(done)} of {seeds} runs in {tmp_path / 'out' / 'walk'}; "
                           "run the same command again to resume")
    for r in done[:3] + done[-3:]:
        direct = campaign_toy.random_walk(seed=_run_seed(r), steps=100000, sigma_m=[1.0, 1.0, 1.0], **FIXED)
        np.testing.assert_array_equal(table.loc[table["run"] == r, "pos_error_m"], direct["pos_error_m"])


BAD = [
    ("seeds = 0", "seeds: must be ≥ 1, got 0"),
    ("seeds = 1.5", "seeds: expected an integer"),
    ("sedes = 2", "sedes: unknown key"),
    ("seed = -1", "seed: must be an integer in [0, 18446744073709551615]"),
    ("[executor]\nworkers = 0", "executor.workers: must be ≥ 1"),
    ("[executor]\nthreads = 2", "executor.threads: unknown key"),
    ('[executor]\nworkers = 2\nscheduler = "tcp://127.0.0.1:8786"', "executor.workers: give scheduler"),
]


@pytest.mark.parametrize("extra,message", BAD)
def test_a_bad_key_is_a_usage_error_naming_it(tmp_path, capsys, monkeypatch, extra, message):
    monkeypatch.setattr(sys, "path", [str(TESTS), *sys.path])  # the command puts the file's folder first
    if extra.startswith("["):  # a table: at the end
        text = TOML + "\n" + extra + "\n"
    else:  # a top-level key: first, instead of the file's own
        key = extra.split("=")[0].strip()
        text = extra + "\n" + "".join(line + "\n" for line in TOML.splitlines() if line.split("=")[0].strip() != key)
    path = _write(tmp_path, "campaign.toml", text)
    with pytest.raises(SystemExit) as e:
        cli.main(["campaign", str(path), "--no-progress"])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("usage: atomnav campaign")
    assert f"atomnav campaign: error: {path}: {message}" in err, err
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("text,message", [
    (TOML.replace("campaign_toy:random_walk", "nosuch"), "scenario: unknown built-in scenario 'nosuch'; the built-ins are "),
    (TOML.replace("campaign_toy:random_walk", "campaign_toy:nosuch"), "scenario: cannot import 'campaign_toy:nosuch'"),
    (TOML.replace("campaign_toy:random_walk", "no_such_module:walk"), "No module named 'no_such_module'"),
    (TOML.replace("steps = [10, 20]", "steps = []"), "grid.steps: empty list of values"),
    (TOML.replace("steps = [10, 20]", "bogus = [1, 2]"), "grid: 'bogus' is not a parameter of random_walk"),
    (TOML.replace("[grid]", "[points]").replace("steps = [10, 20]", "steps = [10]"),
     "points: the lists must have equal lengths (point i takes the i-th value of each), got steps: 1, sigma_m: 2"),
    (TOML.replace("[grid]", "[points]") + "[grid]\ndt_s = [1.0]\n", "points: give the parameter points"),
    (TOML.split("[grid]")[0], "points: missing"),
    (TOML.replace('scenario = "campaign_toy:random_walk"', ""), "scenario: missing"),
    (TOML.split("[grid]")[0] + "grid = 3\n", "grid: expected a table of parameter names and values, got int"),
    ("- a\n- list\n", "not valid TOML"),
    (TOML.replace("seeds = 3", "seeds = "), "not valid TOML"),
    (TOML.replace("dt_s = 0.5", "bogus = 1.0"), "fixed: 'bogus' is not a parameter of random_walk"),
    (TOML.replace("dt_s = 0.5", "dt_s = nan"), "fixed.dt_s: must be finite"),
    (TOML.replace("dt_s = 0.5", "dt_s = [1.0, 'a']"), "fixed.dt_s[1]: a vector holds numbers, got str 'a'"),
])
def test_a_bad_file_is_a_usage_error_naming_the_key(tmp_path, capsys, monkeypatch, text, message):
    monkeypatch.setattr(sys, "path", [str(TESTS), *sys.path])
    path = _write(tmp_path, "campaign.toml", text)
    with pytest.raises(SystemExit) as e:
        cli.main(["campaign", str(path), "--no-progress"])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert f"atomnav campaign: error: {path}: " in err and message in err, err


def test_unknown_builtin_lists_the_builtins_and_a_missing_file_is_named(tmp_path):
    run = _atomnav(str(_write(tmp_path, "c.toml", TOML.replace("campaign_toy:random_walk", "nosuch"))))
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert "'nosuch'" in run.stderr and "cai_car" in run.stderr
    run = _atomnav(str(tmp_path / "missing.yaml"))
    assert run.returncode == 2 and "Traceback" not in run.stderr
    assert f"{tmp_path / 'missing.yaml'}: No such file or directory" in run.stderr
    run = _atomnav(str(_write(tmp_path, "c.json", "{}")))
    assert run.returncode == 2 and "expected a .toml, .yaml or .yml file, got 'c.json'" in run.stderr
    (tmp_path / "latin1.yaml").write_bytes("scenario: caf\xe9".encode("latin-1"))
    run = _atomnav(str(tmp_path / "latin1.yaml"))
    assert run.returncode == 2 and "Traceback" not in run.stderr and "latin1.yaml: not UTF-8 text" in run.stderr
    run = _atomnav(str(_write(tmp_path, "list.yaml", "- a\n- list\n")))
    assert run.returncode == 2 and "list.yaml: expected a table of keys at the top of the file, got list" in run.stderr


def test_yaml_without_pyyaml_says_what_to_install(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "yaml", None)  # import yaml raises ImportError
    path = _write(tmp_path, "campaign.yaml", YAML)
    with pytest.raises(SystemExit) as e:
        cli.main(["campaign", str(path)])
    assert e.value.code == 2
    assert "needs PyYAML: pip install pyyaml" in capsys.readouterr().err


def test_unreachable_scheduler_fails_cleanly(tmp_path):
    path = _write(tmp_path, "campaign.toml", TOML)
    run = _atomnav(str(path), "--no-progress", "--scheduler", "tcp://127.0.0.1:9", timeout=120)
    assert run.returncode == 1
    assert "Traceback" not in run.stderr
    assert "atomnav campaign: error: scheduler: cannot connect to tcp://127.0.0.1:9" in run.stderr
    assert run.stdout == ""


def test_toml_and_yaml_read_alike_and_points_have_two_spellings(tmp_path):
    toml, yaml = load(_write(tmp_path, "a.toml", TOML)), load(_write(tmp_path, "a.yaml", YAML))
    assert toml == yaml == CampaignFile("campaign_toy:random_walk", grid=GRID, seeds=SEEDS, seed=SEED, fixed=FIXED,
                                        name="walk", output=tmp_path / "out")
    assert pickle.loads(pickle.dumps(toml)) == toml and hash(toml) == hash(yaml)
    executor = Executor(scheduler="tcp://10.0.0.5:8786")
    assert pickle.loads(pickle.dumps(executor)) == executor
    zipped = load(_write(tmp_path, "z.toml", 'scenario = "x"\n[points]\nsteps = [10, 20]\ndt_s = [1.0, 2.0]\n'))
    tables = load(_write(tmp_path, "t.toml", 'scenario = "x"\n[[points]]\nsteps = 10\ndt_s = 1.0\n'
                         '[[points]]\nsteps = 20\ndt_s = 2.0\n'))
    assert zipped.points == tables.points == ((("steps", 10), ("dt_s", 1.0)), (("steps", 20), ("dt_s", 2.0)))
    assert zipped.output == tmp_path.resolve()


def test_executor_flags_and_help():
    top, _ = cli.parsers()
    args = top.parse_args(["campaign", "c.toml", "--workers", "2"])
    parser = args.parser
    assert parser.description
    for action in parser._actions:
        assert action.help, action.option_strings or action.dest
    with pytest.raises(SystemExit):
        top.parse_args(["campaign", "c.toml", "--workers", "2", "--scheduler", "tcp://h:1"])
    assert Executor(workers=2) == Executor(None, 2)
