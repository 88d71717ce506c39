"""A station day through atomnav, georinex and RTKLIB side by side: reading a full-day
RINEX observation file (Hatanaka + gzip, ~2,880 epochs at 30 s) and its navigation file
with atomnav's reader (the ``rinex`` crate in the core) and with georinex (the other
candidate, ``--georinex``: about 9 minutes for a day), then single-point positioning of
every epoch (GPS, L1, 10° mask, broadcast Klobuchar and Saastamoinen) against RTKLIB's
``rnx2rtkp`` on the same files and options.

    python benches/bench_rinex.py --obs ESBC00DNK_R_20201770000_01D_30S_MO.crx.gz \\
        --nav ESBC00DNK_R_20201770000_01D_MN.rnx.gz [--truth 3582104.7678 532590.1779 5232755.1405] [--georinex]

The ESBC day of the measurements in docs/departures.md is in the public repository
rtk-rs/data (``CRNX/V3/`` and ``NAV/V3/``, MPL-2.0); the truth is ESBC's ITRF2014
marker (tests/data/rinex_stations/SOURCE.md; ΔH 0.216 m is added here). Prints the
read and solve times, RTKLIB's time and the ratio, and both 3-D errors when ``--truth``
is given.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

import atomnav as an
from atomnav.gnss import rinex

sys.path.insert(0, str(Path(__file__).resolve().parent))
from timing import record  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
CONF = ROOT / "tests" / "data" / "rinex_stations" / "rtklib_spp_gps.conf"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--obs", type=Path, required=True, help="RINEX observation file (.rnx, .crx, .gz)")
    ap.add_argument("--nav", type=Path, required=True, help="RINEX navigation file of the same day")
    ap.add_argument("--truth", type=float, nargs=3, help="marker ECEF x y z (m); the header's ΔH is added")
    ap.add_argument("--georinex", action="store_true", help="also time georinex reading the same files (minutes)")
    args = ap.parse_args()

    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        eph = rinex.read_nav(args.nav)
        t1 = time.perf_counter()
        obs = rinex.read_obs(args.obs, eph)
    t2 = time.perf_counter()
    gps = obs.table[obs.table["sat"].str[0] == "G"]
    result = an.gnss.solve(eph, gps, elevation_weight=True)
    t3 = time.perf_counter()
    n = len(result.epochs)
    print(f"atomnav: nav {t1 - t0:.2f} s, obs {t2 - t1:.2f} s ({obs.n_epochs} epochs), "
          f"SPP {t3 - t2:.3f} s ({1e3 * (t3 - t2) / max(n, 1):.3f} ms/epoch); total {t3 - t0:.2f} s")

    if args.georinex:
        import georinex

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s = time.perf_counter()
            georinex.load(str(args.nav))
            g1 = time.perf_counter()
            ds = georinex.load(str(args.obs))
            g2 = time.perf_counter()
        print(f"georinex: nav {g1 - s:.2f} s, obs {g2 - g1:.2f} s ({ds.time.size} epochs); "
              f"atomnav / georinex reading speed ratio {(g2 - s) / (t2 - t0):.0f}x")
        record(f"RINEX reading, {obs.n_epochs} epochs", "georinex", (g2 - s) / (t2 - t0))

    theirs, rt = None, None
    if shutil.which("rnx2rtkp"):
        with tempfile.TemporaryDirectory() as d:
            rnx = args.obs
            if ".crx" in args.obs.name:  # rnx2rtkp expands Hatanaka only through a crx2rnx on the PATH
                import hatanaka
                s = time.perf_counter()
                rnx = Path(d) / "obs.rnx"
                rnx.write_bytes(hatanaka.decompress(args.obs.read_bytes()))
                print(f"Hatanaka expansion for RTKLIB: {time.perf_counter() - s:.2f} s (not counted below)")
            out = Path(d) / "spp.pos"
            s = time.perf_counter()
            subprocess.run(["rnx2rtkp", "-k", str(CONF), "-o", str(out), str(rnx), str(args.nav)], check=True,
                           capture_output=True)
            rt = time.perf_counter() - s
            theirs = pd.read_csv(out, sep=r"\s+", comment="%", header=None).iloc[:, 2:5].to_numpy()
        print(f"RTKLIB rnx2rtkp (reads and solves): {rt:.2f} s for {len(theirs)} epochs; "
              f"atomnav / RTKLIB speed ratio {rt / (t3 - t0):.3f}x (SPP alone: {1e3 * (t3 - t2) / max(n, 1):.3f} "
              f"against {1e3 * rt / max(len(theirs), 1):.3f} ms/epoch with reading)")
    else:
        print("rnx2rtkp not installed (Debian: apt-get install rtklib): no side-by-side time")

    e = r = None
    if args.truth:
        marker = np.array(args.truth)
        lla = an.earth.ecef_to_lla(marker)
        arp = marker + an.earth.dcm_ned_to_ecef(lla[0], lla[1]) @ [0.0, 0.0, -obs.header["antenna_delta_hen_m"][0]]
        e = np.linalg.norm(result.epochs[["x_m", "y_m", "z_m"]].to_numpy() - arp, axis=1)
        print(f"atomnav 3-D error: mean {e.mean():.2f} m, worst {e.max():.2f} m over {n} epochs")
        if theirs is not None:
            r = np.linalg.norm(theirs - arp, axis=1)
            print(f"RTKLIB 3-D error:  mean {r.mean():.2f} m, worst {r.max():.2f} m over {len(r)} epochs")
    record(f"RINEX read + SPP, {n} epochs", None if rt is None else "RTKLIB rnx2rtkp", None if rt is None else rt / (t3 - t0),
           None if e is None else e.mean(), None if r is None else r.mean(), "m mean 3-D error")


if __name__ == "__main__":
    main()
