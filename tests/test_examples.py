"""The walkthroughs of the README's "Your own data" and "Design studies at scale": every
script under ``examples/`` runs from a fresh working directory and exits 0 (each asserts
its own result against the simulated truth or a closed form), and every python block of
those README sections is the code of the example it names."""

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


#: The README sections whose python blocks are examples' code.
SECTIONS = ("Your own data", "Design studies at scale")


def readme_blocks(section):
    """(example file, code) of every python block in the README's ``section``; the file is
    the last ``examples/*.py`` named in the section before the block."""
    text = (ROOT / "README.md").read_text()
    body = text.split(f"\n## {section}\n", 1)[1].split("\n## ", 1)[0]
    blocks, pos, name = [], 0, None
    for m in re.finditer(r"```python\n(.*?)```", body, re.S):
        name = ([name] + re.findall(r"examples/(\w+\.py)", body[pos:m.start()]))[-1]
        blocks.append((name, m.group(1)))
        pos = m.end()
    return blocks


BLOCKS = [(section, name, code) for section in SECTIONS for name, code in readme_blocks(section)]


@pytest.mark.parametrize("section", SECTIONS)
def test_readme_section_has_example_code(section):
    """A section that lost its blocks or its example's name would pass the checks below
    vacuously."""
    blocks = readme_blocks(section)
    assert blocks and all(name is not None for name, _ in blocks), section


def test_readme_section_names_every_example():
    assert sorted({name for _, name, _ in BLOCKS}) == EXAMPLES


@pytest.mark.parametrize("section, name, code", BLOCKS)
def test_readme_code_is_the_example(section, name, code):
    """Each README block appears verbatim in its example, so the README runs as shown."""
    assert name is not None, (section, code)
    assert code in (ROOT / "examples" / name).read_text(), (section, name)
