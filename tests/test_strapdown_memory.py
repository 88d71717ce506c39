"""Streaming memory: a whole day of IMU data at 200 Hz (17.28 million samples) goes
through :class:`atomnav.strapdown.Strapdown` chunk by chunk within 256 MB peak resident
memory, and the peak does not grow with the record's length.

Each record runs in a fresh subprocess that generates its samples chunk by chunk (a
stationary IMU: the same Earth-rate and gravity increments every 5 ms) and reports its
own peak resident set size (``VmHWM`` of ``/proc/self/status``), so what is measured is
the interpreter with atomnav imported plus what streaming holds, not the generator or the
test runner."""

import json
import subprocess
import sys

import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads VmHWM from /proc/self/status")

RATE_HZ = 200.0
CHUNK = 100_000  # rows per Strapdown.run call: 500 s at 200 Hz

CHILD = r"""
import json, sys
import numpy as np
from atomnav import trajectory
from atomnav.strapdown import Strapdown

def peak_mb():
    with open("/proc/self/status") as f:
        return next(int(l.split()[1]) for l in f if l.startswith("VmHWM:")) / 1024

hours, rate, chunk = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
n = round(hours * 3600 * rate)
short = trajectory.stationary(1.0, rate)
init = short.initial_state()
row = short.ideal_imu("increments").to_numpy()[0]  # time, dtheta (rad), dv (m/s) of one 1/rate interval
dt = row[0] - init["t0"]
sd = Strapdown(**init, kind="increments", vertical="damped")
block = np.empty((chunk, 7))
block[:, 1:] = row[1:]
h_ref = np.full(chunk, init["lla"][2])
imported = peak_mb()
for s in range(0, n, chunk):
    m = min(chunk, n - s)
    block[:m, 0] = init["t0"] + np.arange(s + 1, s + m + 1) * dt
    nav = sd.run(block[:m], h_ref=h_ref[:m])
last = nav.iloc[-1]
print(json.dumps({"peak_mb": peak_mb(), "imported_mb": imported, "rows": n, "last_index": int(nav.index[-1]),
                  "last_time_s": float(last["time_s"]), "expected_time_s": float(init["t0"] + n * dt),
                  "dlat_rad": float(last["lat_rad"] - init["lla"][0]), "dh_m": float(last["h_m"] - init["lla"][2])}))
"""


def _stream(hours: float) -> dict:
    """Stream ``hours`` of 200 Hz samples in a fresh interpreter; its report."""
    out = subprocess.run([sys.executable, "-c", CHILD, str(hours), str(RATE_HZ), str(CHUNK)],
                         capture_output=True, text=True, timeout=600, check=False)
    assert out.returncode == 0, out.stderr[-3000:]
    return json.loads(out.stdout.splitlines()[-1])


def _streamed_whole_record(r: dict, hours: float):
    """Every sample ran (record-wide row numbers, last time stamp) and the stationary
    solution stayed where it started (damped vertical channel on the true height)."""
    assert r["rows"] == round(hours * 3600 * RATE_HZ) and r["last_index"] == r["rows"] - 1
    assert r["last_time_s"] == pytest.approx(r["expected_time_s"], abs=1e-6)
    assert abs(r["dlat_rad"]) < 1e-9 and abs(r["dh_m"]) < 1e-3


def test_a_day_at_200_hz_streams_within_256_mb():
    r = _stream(24.0)
    _streamed_whole_record(r, 24.0)
    assert r["rows"] == 17_280_000
    assert r["peak_mb"] <= 256.0, f"peak RSS {r['peak_mb']:.1f} MB (after import {r['imported_mb']:.1f} MB)"


def test_peak_memory_does_not_grow_with_the_record():
    """Three times the record, same peak: streaming holds one chunk, not the record (an
    hour at 200 Hz is 720,000 rows, 80 MB of solution, so a leak of rows would show)."""
    one, three = _stream(1.0), _stream(3.0)
    _streamed_whole_record(three, 3.0)
    assert three["peak_mb"] - one["peak_mb"] < 8.0, (one, three)
