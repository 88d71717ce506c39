"""Tightly coupled GNSS/INS: atomnav (Rust engine + gnss aiding, one call) vs a pure-numpy
implementation of the same loop, in one run.

Loop: 100 Hz strapdown on increments (quaternion attitude, velocity with gravity and
Coriolis, geodetic position), 16-state error filter (15 INS + c·τ_GPS) predicted every
1 s with Φ = I + FΔT + (FΔT)²/2, first differences of code and pseudorange rate for the
~10 GPS satellites above the horizon at 1 Hz (Keplerian orbits, light time, Sagnac), Cholesky
decorrelation, sequential scalar Joseph updates, closed-loop feedback.

    python benches/bench_gnss.py [--minutes 10] [--repeat 1]

The numpy loop is timed over ``--minutes`` of data (default 10; the full 1-h case is
``--minutes 60``); the ratio is per second of data.
"""

from __future__ import annotations

import argparse

import numpy as np

import atomnav as an
from atomnav.gnss import scenarios as S
from atomnav.gnss import simulate, tight_ins
from timing import best_of, record

MU, OMEGA, C, A_WGS, E2 = 3.986005e14, 7.2921151467e-5, 299792458.0, 6378137.0, 6.69437999014e-3


def skew(v):
    return np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def qrot(v):
    a = np.linalg.norm(v)
    return np.r_[1.0, 0.5 * v] if a < 1e-12 else np.r_[np.cos(a / 2), np.sin(a / 2) * v / a]


def dcm(q):
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def ecef(lat, lon, h):
    n = A_WGS / np.sqrt(1 - E2 * np.sin(lat) ** 2)
    return np.array([(n + h) * np.cos(lat) * np.cos(lon), (n + h) * np.cos(lat) * np.sin(lon), (n * (1 - E2) + h) * np.sin(lat)])


def cne(lat, lon):
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    return np.array([[-sl * co, -so, -cl * co], [-sl * so, co, -cl * so], [cl, 0, -sl]])


def kepler(g, t):
    """Positions and velocities of circular broadcast orbits (e = 0), vectorised."""
    a = g.sqrt_a.to_numpy() ** 2
    n = np.sqrt(MU / a ** 3)
    tk = t - g.toe.to_numpy()
    u = g.m0.to_numpy() + n * tk
    om = g.omega0.to_numpy() - OMEGA * t
    i = g.i0.to_numpy()
    xp, yp = a * np.cos(u), a * np.sin(u)
    pos = np.stack([xp * np.cos(om) - yp * np.cos(i) * np.sin(om), xp * np.sin(om) + yp * np.cos(i) * np.cos(om), yp * np.sin(i)], 1)
    xd, yd = -a * n * np.sin(u), a * n * np.cos(u)
    vel = np.stack([xd * np.cos(om) - yd * np.cos(i) * np.sin(om) + OMEGA * pos[:, 1],
                    xd * np.sin(om) + yd * np.cos(i) * np.cos(om) - OMEGA * pos[:, 0], yd * np.sin(i)], 1)
    return pos, vel


def numpy_loop(setup):
    a, m, obs = setup["args"], setup["imu"], setup["obs"]
    gtab = setup["eph"].tables()[0]
    t = m["time_s"].to_numpy()
    dth = m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy()
    dvb = m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy()
    lat, lon, h = a["lla0"]
    v, q = np.array(a["vel0"], float), np.array(a["q0"], float)
    ba, bg = np.zeros(3), np.zeros(3)
    p = np.zeros((16, 16))
    p[:15, :15] = a["p0_ins"]
    p[15, 15] = (C * 1e-6) ** 2
    qc = np.diag(np.r_[[0] * 3, [a["accel_psd"]] * 3, [a["gyro_psd"]] * 3, [a["accel_bias"].psd] * 3, [a["gyro_bias"].psd] * 3, 0.0])
    epochs = {tt: ep for tt, ep in obs.groupby("time_s")}
    t_prev, f_n = a["t0"], np.zeros(3)
    for k in range(len(t)):
        dt = t[k] - t_prev
        t_prev = t[k]
        w, f = dth[k] - bg * dt, dvb[k] - ba * dt
        sl, cl = np.sin(lat), np.cos(lat)
        rn = A_WGS / np.sqrt(1 - E2 * sl * sl)
        rm = rn * (1 - E2) / (1 - E2 * sl * sl)
        wie = OMEGA * np.array([cl, 0, -sl])
        wen = np.array([v[1] / (rn + h), -v[0] / (rm + h), -v[1] * sl / cl / (rn + h)])
        cnb = dcm(q)
        f_n = cnb @ (f + 0.5 * np.cross(w, f)) / dt
        g = 9.780327 * (1 + 0.0053024 * sl * sl) - 3.086e-6 * h
        v_new = v + (f_n + np.array([0, 0, g]) - np.cross(2 * wie + wen, v)) * dt
        lat += 0.5 * (v[0] + v_new[0]) / (rm + h) * dt
        lon += 0.5 * (v[1] + v_new[1]) / ((rn + h) * cl) * dt
        h -= 0.5 * (v[2] + v_new[2]) * dt
        v = v_new
        q = qmul(qrot(-(wie + wen) * dt), qmul(q, qrot(w)))
        q /= np.linalg.norm(q)
        if k % 100 != 99 and t[k] not in epochs:
            continue
        # predict P over ΔT = 1 s
        fm = np.zeros((16, 16))
        fm[0:3, 3:6] = np.eye(3)
        fm[3:6, 6:9] = skew(f_n)
        fm[3:6, 9:12] = -cnb
        fm[6:9, 6:9] = -skew(wie + wen)
        fm[6:9, 12:15] = cnb
        fm[5, 2] = 2 * g / 6.37e6
        ph = np.eye(16) + fm + fm @ fm / 2
        p = ph @ p @ ph.T + qc
        ep = epochs.get(t[k])
        if ep is None or len(ep) < 2:
            continue
        idx = gtab.groupby("prn").apply(lambda d: (d.toe - t[k]).abs().idxmin(), include_groups=False)
        sel = gtab.loc[idx.loc[[int(s[1:]) for s in ep.sat]].to_numpy()]
        r = ecef(lat, lon, h)
        cen = cne(lat, lon)
        pos, vel = kepler(sel, t[k])
        rho = np.linalg.norm(pos - r, axis=1)
        pos, vel = kepler(sel, t[k] - rho / C)
        th = OMEGA * rho / C
        pos = np.stack([np.cos(th) * pos[:, 0] + np.sin(th) * pos[:, 1], -np.sin(th) * pos[:, 0] + np.cos(th) * pos[:, 1], pos[:, 2]], 1)
        rho = np.linalg.norm(pos - r, axis=1)
        u = (pos - r) / rho[:, None]
        ve = cen @ v
        rate = np.einsum("ij,ij->i", u, vel - ve)
        un = u @ cen
        z = np.r_[rho - ep.code_m.to_numpy(), rate - ep.rate_mps.to_numpy()]
        dvs = vel - ve
        gi = -(dvs - u * np.einsum("ij,ij->i", u, dvs)[:, None]) @ cen / rho[:, None]
        hm = np.zeros((2 * len(ep), 16))
        hm[:len(ep), 0:3] = -un
        hm[len(ep):, 0:3] = gi
        hm[len(ep):, 3:6] = -un
        ref = int(np.argmax(-un[:, 2]))
        keep = [i for i in range(len(ep)) if i != ref]
        zd = np.r_[z[keep] - z[ref], z[len(ep) + np.array(keep)] - z[len(ep) + ref]]
        hd = np.vstack([hm[keep] - hm[ref], hm[len(ep) + np.array(keep)] - hm[len(ep) + ref]])
        nk = len(keep)
        rd = np.zeros((2 * nk, 2 * nk))
        rd[:nk, :nk] = 9.0 * (np.ones((nk, nk)) + np.eye(nk))
        rd[nk:, nk:] = 0.0025 * (np.ones((nk, nk)) + np.eye(nk))
        lch = np.linalg.cholesky(rd)
        zb, hb = np.linalg.solve(lch, zd), np.linalg.solve(lch, hd)
        x = np.zeros(16)
        for i in range(len(zb)):
            hi = hb[i]
            ph_ = p @ hi
            s = hi @ ph_ + 1.0
            y = zb[i] - hi @ x
            if y * y / s > 10.83:
                continue
            kk = ph_ / s
            x += kk * y
            ia = np.eye(16) - np.outer(kk, hi)
            p = ia @ p @ ia.T + np.outer(kk, kk)
        # closed-loop feedback
        lat -= x[0] / (rm + h)
        lon -= x[1] / ((rn + h) * cl)
        h += x[2]
        v -= x[3:6]
        q = qmul(qrot(x[6:9]), q)
        ba -= x[9:12]
        bg -= x[12:15]
    return np.array([lat, lon, h])


def workload(minutes: float) -> tuple[dict, tuple, float]:
    """The 'precise' scenario over ``minutes`` with a free vertical channel and observations
    without atmosphere above 0° (as the numpy loop models them): (setup, IMU columns,
    mean satellites per epoch)."""
    dur = 60.0 * minutes
    sc = S.Scenario("precise", duration_s=dur, rate_hz=100.0, vertical="free")
    setup = S.build(sc)
    t_gnss = np.arange(1.0, dur + 1e-9, 1.0)
    idx = np.rint(t_gnss * 100.0).astype(int)
    tr = setup["trajectory"]
    setup["obs"] = simulate(setup["eph"], t_gnss, tr.lla[idx], tr.vel_ned[idx], iono=False, tropo=False, mask_deg=0.0, seed=1)
    m = setup["imu"]
    imu = (m["time_s"].to_numpy(), m[["dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad"]].to_numpy(), m[["dv_x_mps", "dv_y_mps", "dv_z_mps"]].to_numpy())
    return setup, imu, setup["obs"].groupby("time_s").size().mean()


def run_atomnav(setup: dict, imu: tuple):
    """One tightly coupled run of atomnav on the inputs of :func:`workload`."""
    return tight_ins(setup["eph"], setup["obs"], iono=False, tropo=False, **setup["args"]).run(*imu, progress=False)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--minutes", type=float, default=10.0)
    ap.add_argument("--repeat", type=int, default=1)
    args = ap.parse_args()
    setup, imu, nsat = workload(args.minutes)
    t_an, res = best_of(lambda: run_atomnav(setup, imu), args.repeat)
    t_np, end = best_of(lambda: numpy_loop(setup), args.repeat)
    truth_end = setup["trajectory"].lla[-1]
    print(f"tightly coupled GNSS/INS, {args.minutes:g} min of 100 Hz IMU, 1 Hz GNSS, {nsat:.1f} satellites")
    print(f"  atomnav : {t_an:8.3f} s  ({t_an * 60 / args.minutes:.2f} s per hour of data)")
    print(f"  numpy   : {t_np:8.3f} s  ({t_np * 60 / args.minutes:.2f} s per hour of data)")
    print(f"  ratio numpy/atomnav = {t_np / t_an:.1f}x (target >= 30x)")
    e_np = an.earth.lla_to_ned(end, truth_end)
    e_an = an.earth.lla_to_ned(res.nav[["lat_rad", "lon_rad", "h_m"]].to_numpy()[-1], truth_end)
    print(f"  final position error: atomnav {np.linalg.norm(e_an):.2f} m, numpy {np.linalg.norm(e_np):.2f} m")
    record(f"tightly coupled GNSS/INS, {args.minutes:g} min", "numpy loop (own)", t_np / t_an, np.linalg.norm(e_an),
           np.linalg.norm(e_np), "m final position error")


if __name__ == "__main__":
    main()
