"""The ``gnss`` reproduction section at reduced size (35 s: marked slow)."""

import pytest

from atomnav import reproduce


@pytest.mark.slow
def test_gnss_section_quick(tmp_path):
    table = reproduce.run(tmp_path, only=["gnss"], quick=True)
    assert len(table) >= 18
    assert not (table["verdict"] == "FAIL").any(), table[table["verdict"] == "FAIL"]
    assert len(list(tmp_path.glob("gnss_*.png"))) == 2
