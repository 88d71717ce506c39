"""The recorded walk (tests/data/real_walk: a hand-held MEMS IMU turned in its housing, an
RTKLIB solution file) through the README's pipeline (examples/real_walk.py), with the
source's 15 s GNSS outage from 25 s after the first GNSS epoch, scored against the
withheld fixed-RTK positions. The bar is the source's published loosely coupled filter
(rtklibexplorer/GNSS_IMU, its SOURCE.md): 6.13 m forward, 0.56 m with its velocity
matching; and the scoring rule itself reproduces those two numbers from the source
filter's own output (benches/bench_walk.py --peer)."""

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
import real_walk  # noqa: E402


@pytest.fixture(scope="module")
def walk():
    run = real_walk.solve(real_walk.DATA)
    print("\n" + run.outages.table.to_string(index=False))
    return run.outages.table.set_index("solution")


def test_the_outage_holds_the_published_fixes(walk):
    assert walk.loc["forward", "fixes"] == 60  # 15 s of fixed-RTK epochs at 4 Hz withheld and scored


def test_smoothed_within_the_published_velocity_matching(walk):
    assert walk.loc["smoothed", "max_error_m"] <= real_walk.PUBLISHED["smoothed"]


def test_forward_within_the_published_forward_filter(walk):
    assert walk.loc["forward", "max_error_m"] <= real_walk.PUBLISHED["forward"]
