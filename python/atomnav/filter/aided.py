"""Position-aided strapdown INS with the 15-state error-state filter (Rust core,
``rust/filter/aided.rs``): batch over a whole IMU record, closed or open loop."""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import _core
from .._validate import rows, vector
from .engine import BiasModel, Layout
from .riccati import _mat


def position_aided_ins(t0: float, lla0, vel0, q0, kind: str, time, gyro, accel, fix_time, fix_lla, fix_cov,
                       p0, accel_psd: float, gyro_psd: float, accel_bias: BiasModel = BiasModel(),
                       gyro_bias: BiasModel = BiasModel(), ba0=(0, 0, 0), bg0=(0, 0, 0), predict_every: int = 1,
                       method: str = "van_loan", mode: str = "closed", sequential: bool = False,
                       gate: float | None = None, ellipsoid: str = "WGS84"):
    """Run the aided INS.

    Initial state t0 (s), lla0 (rad, rad, m), vel0 NED (m/s), q0 = q_nb; IMU ``time`` (N,),
    ``gyro``/``accel`` (N, 3) as rates (rad/s, m/s²) or increments (rad, m/s) per ``kind``;
    fixes at ``fix_time`` (M,) with ``fix_lla`` (M, 3) and NED covariance ``fix_cov``
    (M, 3, 3) m² (applied at the first IMU epoch at or after their time; a fix outside
    the IMU span is a ValueError); p0 (15, 15) in the order of :data:`INS15`; white-noise
    PSDs accel_psd ((m/s²)²/Hz), gyro_psd (rad²/s). Predicts every ``predict_every`` IMU
    steps. Returns (table, fixes): the solution, bias estimates and σ of the 15 states at
    every prediction epoch, and per fix its NIS and whether the gate rejected it.
    """
    out = _core.position_aided(
        float(t0), vector(lla0, 3, "lla0"), vector(vel0, 3, "vel0"), vector(q0, 4, "q0"), kind,
        np.ascontiguousarray(np.asarray(time, float)), rows(gyro, 3, "gyro"), rows(accel, 3, "accel"),
        vector(ba0, 3, "ba0"), vector(bg0, 3, "bg0"), _mat(p0, "p0"),
        np.ascontiguousarray(np.asarray(fix_time, float).ravel()), rows(fix_lla, 3, "fix_lla"),
        np.ascontiguousarray(np.asarray(fix_cov, float).reshape(-1, 3, 3)),
        float(accel_psd), float(gyro_psd), accel_bias._parts(), gyro_bias._parts(), int(predict_every),
        method, mode, bool(sequential), None if gate is None else float(gate), ellipsoid)
    t, lla, vel, q, ba, bg, sigma, nis, rejected = out
    cols = {"time_s": t, "lat_rad": lla[:, 0], "lon_rad": lla[:, 1], "h_m": lla[:, 2],
            "v_n_mps": vel[:, 0], "v_e_mps": vel[:, 1], "v_d_mps": vel[:, 2],
            "q_w": q[:, 0], "q_x": q[:, 1], "q_y": q[:, 2], "q_z": q[:, 3]}
    for i, a in enumerate("xyz"):
        cols[f"accel_bias_{a}_mps2"] = ba[:, i]
    for i, a in enumerate("xyz"):
        cols[f"gyro_bias_{a}_rad_s"] = bg[:, i]
    for i, lab in enumerate(Layout().labels):
        cols[f"sigma_{lab}"] = sigma[:, i]
    return pd.DataFrame(cols), pd.DataFrame({"fix_time_s": np.asarray(fix_time, float).ravel(), "nis": nis, "rejected": rejected})
