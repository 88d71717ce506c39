"""The core's RINEX reader (the ``rinex`` crate) against the other candidate, georinex, on
the same real files (tests/data/rinex_stations): every code, second-frequency code and
Doppler atomnav takes, and every broadcast record, is the number georinex reads; no
satellite-epoch georinex sees is lost; a Hatanaka + gzip file keeps every epoch of the
expanded file (the ``hatanaka`` package, a third reader, expands it).
"""

from __future__ import annotations

import gzip
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from atomnav.gnss import rinex
from atomnav.gnss.observations import doppler_to_rate

georinex = pytest.importorskip("georinex")
D = Path(__file__).parent / "data" / "rinex_stations"
FILES = {"ESBC": ("ESBC00DNK_R_20201770000_01D_MN_cut12h.rnx.gz", "ESBC00DNK_R_20201770000_01D_30S_MO_cut.rnx.gz"),
         "WTZR": ("ESBC00DNK_R_20201770000_01D_MN_cut00h.rnx.gz", "WTZR00DEU_R_20201770000_01D_30S_MO_cut.rnx.gz"),
         "DELF": ("brdc0010_cut.21n.gz", "delf0010_cut.21o.gz"),
         "KMS3": ("KMS300DNK_R_20221591000_01H_MN.rnx.gz", "KMS300DNK_R_20221591000_01H_30S_MO.crx")}


def _georinex(path: Path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return georinex.load(str(path))


def _long(ds, types: list[str]) -> pd.DataFrame:
    """georinex's observations as rows (time, sat, type, value), finite and non-zero."""
    present = [c for c in types if c in ds.data_vars]
    if not present:
        return pd.DataFrame({"time": pd.Series(dtype="datetime64[ns]"), "sat": pd.Series(dtype=object),
                             "type": pd.Series(dtype=object), "value": pd.Series(dtype=float)})
    df = ds[present].to_dataframe().reset_index().melt(id_vars=["time", "sv"], var_name="type", value_name="value")
    return df[np.isfinite(df.value) & (df.value != 0.0)].rename(columns={"sv": "sat"})


@pytest.mark.parametrize("name", ["ESBC", "WTZR", "DELF", "KMS3"])
def test_observations_are_the_numbers_georinex_reads(name):
    nav, obs_file = FILES[name]
    eph = rinex.read_nav(D / nav)
    ours = rinex.read_obs(D / obs_file, eph)
    t = ours.table.assign(time=ours.week_start + pd.to_timedelta(ours.table.time_s, unit="s"))
    ds = _georinex(D / obs_file)
    chosen = {}
    for value, kind, preference in (("code_m", "code_type", rinex.CODE_PREFERENCE),
                                    ("code2_m", "code2_type", rinex.CODE2_PREFERENCE),
                                    ("rate_mps", "doppler_type", rinex.DOPPLER_PREFERENCE)):
        theirs = _long(ds, sorted({c for v in preference.values() for c in v}))
        # the first type of the preference order that georinex has, per satellite-epoch
        theirs["rank"] = [preference.get(s[0], []).index(c) if c in preference.get(s[0], []) else 99
                          for s, c in zip(theirs.sat, theirs.type)]
        chosen[value] = theirs[theirs["rank"] < 99].sort_values("rank").drop_duplicates(["time", "sat"])
    # a row per satellite-epoch with an L1 code or a Doppler, in both readers
    rows = pd.concat([chosen["code_m"], chosen["rate_mps"]])[["time", "sat"]].drop_duplicates()
    both = t.merge(rows, on=["time", "sat"], how="outer", indicator=True)
    assert (both["_merge"] == "both").all(), f"{name}: satellite-epochs read by one reader only:\n{both[both._merge != 'both']}"
    for value, kind in (("code_m", "code_type"), ("code2_m", "code2_type"), ("rate_mps", "doppler_type")):
        theirs = chosen[value].merge(rows, on=["time", "sat"])
        m = t[t[kind] != ""].merge(theirs, on=["time", "sat"], how="outer", indicator=True)
        assert (m["_merge"] == "both").all(), f"{name} {value}: read by one reader only:\n{m[m._merge != 'both']}"
        assert (m[kind] == m["type"]).all()
        expected = m["value"].to_numpy()
        if value == "rate_mps":
            expected = doppler_to_rate(expected, m.sat.to_numpy(), m.channel.to_numpy())
        np.testing.assert_allclose(m[value].to_numpy(), expected, rtol=0, atol=1e-9 * np.max(np.abs(expected), initial=0.0))
    assert len(t) > 200


@pytest.mark.parametrize("name", ["ESBC", "DELF"])
def test_broadcast_records_are_the_numbers_georinex_reads(name):
    nav = D / FILES[name][0]
    eph = rinex.read_nav(nav)
    gps, _ = eph.tables()
    ds = _georinex(nav)
    pairs = {"sqrt_a": "sqrtA", "e": "Eccentricity", "m0": "M0", "delta_n": "DeltaN", "omega0": "Omega0", "i0": "Io",
             "omega": "omega", "omega_dot": "OmegaDot", "idot": "IDOT", "cuc": "Cuc", "cus": "Cus", "crc": "Crc",
             "crs": "Crs", "cic": "Cic", "cis": "Cis", "af0": "SVclockBias", "af1": "SVclockDrift", "tgd": "TGD"}
    g = ds.sel(sv=[s for s in ds.sv.values if str(s).startswith("G")])[list(pairs.values()) + ["health"]]
    theirs = g.to_dataframe().dropna(how="all").reset_index().rename(columns={c: "georinex_" + c for c in pairs.values()})
    theirs = theirs[theirs.health == 0.0]
    theirs["prn"] = theirs.sv.str[1:].astype(int)
    theirs["toc"] = (theirs.time - eph.week_start).dt.total_seconds()
    m = gps.merge(theirs, on=["prn", "toc"], how="outer", indicator=True)
    assert (m["_merge"] == "both").all() and len(m) >= 40
    for ours, col in pairs.items():
        np.testing.assert_array_equal(m[ours].to_numpy(), m["georinex_" + col].to_numpy(), err_msg=ours)


def test_a_hatanaka_gzip_file_keeps_every_epoch(tmp_path):
    """The .crx compressed once more with gzip (.crx.gz, as stations publish): as many
    epochs as the ``hatanaka`` package's expansion of it, and the same rows as the .crx."""
    import hatanaka

    crx = D / FILES["KMS3"][1]
    expanded = hatanaka.decompress(crx.read_bytes())
    expanded = expanded.decode() if isinstance(expanded, bytes) else expanded
    epochs = sum(1 for line in expanded.splitlines() if line.startswith(">"))
    gz = tmp_path / (crx.name + ".gz")
    gz.write_bytes(gzip.compress(crx.read_bytes()))
    eph = rinex.read_nav(D / FILES["KMS3"][0])
    a, b = rinex.read_obs(crx, eph), rinex.read_obs(gz, eph)
    assert a.n_epochs == b.n_epochs == epochs == 19
    pd.testing.assert_frame_equal(a.table, b.table)
