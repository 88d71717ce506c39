"""The walkthroughs of the README's "Your own data": every script under ``examples/`` runs
from a fresh working directory and exits 0 (each asserts its own result against the
simulated truth), and every code block of that README section is the code of the example
it names."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted(p.name for p in (ROOT / "examples").glob("*.py") if not p.name.startswith("_"))


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_runs(name, tmp_path):
    """The example writes its files into tmp_path, works on them and checks its result."""
    run = subprocess.run([sys.executable, str(ROOT / "examples" / name), str(tmp_path)], capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]


def readme_blocks():
    """(example file, code) of every python block in the README's "Your own data" section;
    the file is the last ``examples/*.py`` named before the block."""
    text = (ROOT / "README.md").read_text()
    section = text.split("\n## Your own data\n", 1)[1].split("\n## ", 1)[0]
    blocks, pos = [], 0
    for m in re.finditer(r"```python\n(.*?)```", section, re.S):
        named = re.findall(r"examples/(\w+\.py)", section[pos:m.start()])
        blocks.append((named[-1] if named else None, m.group(1)))
        pos = m.end()
    return blocks


def test_readme_section_names_every_example():
    assert sorted({name for name, _ in readme_blocks()}) == EXAMPLES


@pytest.mark.parametrize("name, code", readme_blocks())
def test_readme_code_is_the_example(name, code):
    """Each README block appears verbatim in its example, so the README runs as shown."""
    assert name is not None, code
    assert code in (ROOT / "examples" / name).read_text(), name
