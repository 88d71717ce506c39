"""Your own data (f): a recorded walk — a hand-held MEMS IMU turned in its housing and an
RTK solution file from RTKLIB — through a 15 s GNSS outage.

    python examples/real_walk.py [workdir]

The files are a real record (tests/data/real_walk, from rtklibexplorer/GNSS_IMU, BSD
3-Clause; see its SOURCE.md): an ADIS16465-class IMU at about 166 Hz without a header
(time in GPS seconds since 1970, specific force in g, angular rate in rad/s) and the
receiver's RTKLIB ``.pos`` solution at 4 Hz with fixed and float stretches. Only the facts
of SOURCE.md go in: the IMU's mount (roll 180°, pitch 0°, yaw −90° in its housing), its
noise densities, bias walks and initial bias σ, and the rule "heading from the GNSS track
once faster than 1 m/s". The example copies the files into ``workdir``, levels the IMU
(and reads its gyro bias) while the walker stands, takes the heading from the GNSS
velocity, runs the aided INS and the Rauch–Tung–Striebel smoother with the GNSS withheld from 25 to 40 s after its first epoch,
and scores both against the withheld fixed-RTK positions, next to the source's published
loosely coupled filter (6.13 m forward, 0.56 m with its velocity matching).
"""

from __future__ import annotations

import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np

import atomnav as an

DATA = Path(__file__).resolve().parents[1] / "tests" / "data" / "real_walk"
PUBLISHED = {"forward": 6.13, "smoothed": 0.56}  # the source's filter: largest 3-D error in the outage (m)


@dataclass
class WalkRun:
    samples: int  # IMU samples processed
    outages: an.filter.OutageResult
    reference: an.filter.PositionFixes  # the fixed-RTK positions scored against


def solve(folder: Path) -> WalkRun:
    deg, g = np.pi / 180.0, 9.80665
    log = an.io.read_imu(folder / "imu_1730_sf.csv.gz", kind="rates", header=None,
                         names=["t", "fx", "fy", "fz", "wx", "wy", "wz", "u1", "u2", "u3", "u4"],
                         columns={"time": "t", "accel_x": "fx", "accel_y": "fy", "accel_z": "fz",
                                  "gyro_x": "wx", "gyro_y": "wy", "gyro_z": "wz"},
                         units={"accel": "g", "gyro": "rad/s"})
    gnss = an.gnss.read_pos(folder / "gnss_1730_sf.pos.gz")      # time_s: GPS s since 1970, as the IMU
    fixes, velocities = gnss.position_fixes(), gnss.velocity_fixes()  # σ × 2 for float epochs
    errors = an.imu.ImuErrors(                                    # SOURCE.md: densities, bias walks, initial σ
        accel=an.imu.TriadErrors(white=70e-6 * g, bias_rw=7e-6 * g, bias_sigma=0.2),
        gyro=an.imu.TriadErrors(white=0.0038 * deg, bias_rw=3.8e-5 * deg, bias_sigma=0.2 * deg))
    imu = log.data
    rest = imu[imu["time_s"] < imu["time_s"].iloc[0] + 9.0]        # still until 9.4 s (then |ω| > 2 °/s)
    site = fixes.value[0]
    level = an.alignment.level(rest, site, errors=errors)          # roll, pitch, gyro bias (IMU axes); no heading
    start = an.alignment.in_motion(imu, fixes, velocities, level, mount=np.radians([180.0, 0.0, -90.0]),
                                   speed=1.0, slip_sigma=10 * deg, predict_s=0.01)
    windows = an.filter.outage_windows(gnss.data["time_s"].to_numpy(), length=15.0, first=25.0)
    reference = gnss.position_fixes({"fix": 1.0})                  # score against fixed-RTK epochs only
    out = an.filter.outage_analysis(start.setup, start.later(fixes), start.after(imu), windows,
                                    withhold=[start.later(velocities)], reference=reference, progress=False)
    return WalkRun(len(imu), out, reference)


if __name__ == "__main__":
    from _workdir import enter

    workdir = enter()
    for name in ("imu_1730_sf.csv.gz", "gnss_1730_sf.pos.gz"):
        shutil.copy(DATA / name, workdir / name)
    run = solve(workdir)
    table = run.outages.table.assign(published_m=run.outages.table["solution"].map(PUBLISHED))
    print(table[["solution", "fixes", "max_error_m", "end_error_m", "end_sigma_m", "published_m"]].to_string(index=False))
    worst = table.set_index("solution")["max_error_m"]
    assert worst["forward"] <= PUBLISHED["forward"] and worst["smoothed"] <= PUBLISHED["smoothed"], worst
