"""The `atomnav reproduce` section of seed 003 / seed 000 §3 runs (quick mode) with every
checked row passing."""

from atomnav import reproduce


def test_cai_section_quick(tmp_path):
    table = reproduce.run(tmp_path, only=["cai_tennstedt2023"], quick=True)
    assert len(table) >= 15
    assert not (table["verdict"] == "FAIL").any(), table[table["verdict"] == "FAIL"]
    assert len(list(tmp_path.glob("cai_tennstedt2023_*.png"))) == 4
