"""Broadcast orbits: GPS against an independent numpy evaluation of the IS-GPS-200
equations, GLONASS RK4 against a tight scipy integration of the ICD equations of motion."""

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

import atomnav.gnss as g

MU, OMEGA_E = 3.986005e14, 7.2921151467e-5

GPS_SET = dict(prn=5, toe=352800.0, sqrt_a=5153.65531, e=0.0103, m0=1.2, delta_n=4.6e-9, omega0=-2.1, i0=0.96,
               omega=0.65, omega_dot=-8.1e-9, idot=3.2e-10, cuc=2.1e-6, cus=8.4e-6, crc=210.0, crs=45.0, cic=1.2e-7,
               cis=-9.0e-8, toc=352800.0, af0=1.5e-4, af1=2.0e-12, af2=1e-19, tgd=-1.1e-8)


def icd_position(p, t):
    """IS-GPS-200 Table 20-IV, written out independently of the Rust code."""
    a = p["sqrt_a"] ** 2
    n = np.sqrt(MU / a ** 3) + p["delta_n"]
    tk = t - p["toe"]
    tk = tk - 604800 * (tk > 302400) + 604800 * (tk < -302400)
    m = p["m0"] + n * tk
    e = m
    for _ in range(30):
        e = m + p["e"] * np.sin(e)
    nu = np.arctan2(np.sqrt(1 - p["e"] ** 2) * np.sin(e), np.cos(e) - p["e"])
    phi = nu + p["omega"]
    du = p["cus"] * np.sin(2 * phi) + p["cuc"] * np.cos(2 * phi)
    dr = p["crs"] * np.sin(2 * phi) + p["crc"] * np.cos(2 * phi)
    di = p["cis"] * np.sin(2 * phi) + p["cic"] * np.cos(2 * phi)
    u, r = phi + du, a * (1 - p["e"] * np.cos(e)) + dr
    i = p["i0"] + di + p["idot"] * tk
    xp, yp = r * np.cos(u), r * np.sin(u)
    om = p["omega0"] + (p["omega_dot"] - OMEGA_E) * tk - OMEGA_E * p["toe"]
    clock = p["af0"] + p["af1"] * (t - p["toc"]) + p["af2"] * (t - p["toc"]) ** 2 \
        - 4.442807633e-10 * p["e"] * p["sqrt_a"] * np.sin(e) - p["tgd"]
    return np.array([xp * np.cos(om) - yp * np.cos(i) * np.sin(om), xp * np.sin(om) + yp * np.cos(i) * np.cos(om),
                     yp * np.sin(i)]), clock


def test_gps_position_matches_independent_icd_evaluation_within_1mm():
    eph = g.Ephemerides(gps=pd.DataFrame([GPS_SET]))
    t = GPS_SET["toe"] + np.array([-7000.0, -1800.0, 0.0, 900.0, 7100.0])
    s = eph.state("G05", t)
    for k, tk in enumerate(t):
        pos, clock = icd_position(GPS_SET, tk)
        assert np.linalg.norm(s[["x_m", "y_m", "z_m"]].to_numpy()[k] - pos) < 1e-3
        assert abs(s["clock_s"][k] - clock) < 1e-15
    # velocity: analytic derivative vs central difference of the independent positions, < 1 mm/s
    for k, tk in enumerate(t):
        fd = (icd_position(GPS_SET, tk + 0.01)[0] - icd_position(GPS_SET, tk - 0.01)[0]) / 0.02
        assert np.linalg.norm(s[["vx_mps", "vy_mps", "vz_mps"]].to_numpy()[k] - fd) < 1e-3


def _glonass_rhs(_, y, j2):
    mu, ae, w = 3.986004418e14, 6378136.0, 7.292115e-5
    r = np.linalg.norm(y[:3])
    x, yy, z = y[:3] / r
    mub, rho2 = mu / r ** 2, (ae / r) ** 2
    k = 1.5 * j2 * mub * rho2
    return [y[3], y[4], y[5],
            -mub * x - k * x * (1 - 5 * z * z) + w * w * y[0] + 2 * w * y[4],
            -mub * yy - k * yy * (1 - 5 * z * z) + w * w * y[1] - 2 * w * y[3],
            -mub * z - k * z * (3 - 5 * z * z)]


@pytest.mark.parametrize("sat", ["R01", "R10", "R20"])
@pytest.mark.parametrize("dt", [900.0, -900.0])
def test_glonass_rk4_agrees_with_tight_reference_within_1m(sat, dt):
    eph = g.Ephemerides.nominal(0.0, 3600.0, gps=False, clocks=False)
    s0 = eph.state(sat, [1800.0]).to_numpy()[0, :6]
    y = g.glonass_propagate(s0[:3], s0[3:], [0, 0, 0], dt, step=30.0)
    ref = solve_ivp(_glonass_rhs, (0, dt), s0, args=(1082625.75e-9,), method="DOP853", rtol=1e-13, atol=1e-6).y[:, -1]
    assert np.linalg.norm(y[:3] - ref[:3]) < 1.0
    assert np.linalg.norm(y[3:] - ref[3:]) < 1e-3
    # J₂ matters: dropping it moves the satellite by tens of metres
    no_j2 = solve_ivp(_glonass_rhs, (0, dt), s0, args=(0.0,), method="DOP853", rtol=1e-13, atol=1e-6).y[:3, -1]
    assert np.linalg.norm(no_j2 - ref[:3]) > 10.0


def test_nominal_constellation_geometry_and_channels():
    eph = g.Ephemerides.nominal(0.0, 7200.0)
    assert len(eph.satellites) == 48
    s = eph.state("G01", [0.0])
    a_gps = (MU * (43082.0 / (2 * np.pi)) ** 2) ** (1 / 3)
    assert abs(np.linalg.norm(s[["x_m", "y_m", "z_m"]].to_numpy()) - a_gps) < 1.0
    r = np.linalg.norm(eph.state("R05", [3000.0])[["x_m", "y_m", "z_m"]].to_numpy())
    assert abs(r - 25508e3) < 30e3          # J₂ keeps it near the nominal radius
    assert [eph.channel(f"R{k:02d}") for k in (1, 5, 10, 24)] == [1, 1, -7, 2]
    assert {eph.channel(f"R{k:02d}") for k in range(1, 25)} <= set(range(-7, 7))


def test_doppler_conversion_uses_the_channel_wavelength():
    # k = +6 converted with its own wavelength vs the k = 0 one: 0.21 % (spec Eq. 16)
    r6 = g.doppler_to_rate([-4000.0], ["R01"], [6])[0]
    r0 = g.doppler_to_rate([-4000.0], ["R01"], [0])[0]
    assert abs(r0 / r6 - 1 - 0.5625 * 6 / 1602) < 1e-12
    assert abs(g.doppler_to_rate([1.0], ["G01"], [0])[0] + 299792458.0 / 1575.42e6) < 1e-12


def test_unknown_glonass_channel_is_rejected():
    with pytest.raises(ValueError, match="unknown GLONASS frequency channel 9 at index 0"):
        g.doppler_to_rate([1.0], ["R01"], [9])
    row = dict(slot=3, channel=-8, tb=0.0, x=2.5e7, y=0.0, z=0.0, vx=0.0, vy=3900.0, vz=0.0, ax=0, ay=0, az=0,
               tau_n=0.0, gamma_n=0.0)
    with pytest.raises(ValueError, match="channel -8 at index 0"):
        g.Ephemerides(glonass=pd.DataFrame([row]))


def test_stale_ephemeris_is_rejected():
    eph = g.Ephemerides(gps=pd.DataFrame([GPS_SET]))
    with pytest.raises(ValueError, match="G05 at t = 362000 s: nearest set is 9200 s away"):
        eph.state("G05", [362000.0])
    eph = g.Ephemerides.nominal(0.0, 3600.0, gps=False)
    with pytest.raises(ValueError, match="R01.*validity"):
        eph.state("R01", [20000.0])


def test_datum_pz90_02_shifts_glonass_positions():
    eph = g.Ephemerides.nominal(0.0, 3600.0, gps=False, clocks=False)
    glo = pd.DataFrame(np.asarray(_table_from(eph)), columns=g.GLONASS_COLUMNS)
    shifted = g.Ephemerides(glonass=glo, datum="pz90_02_to_wgs84")
    d = shifted.state("R07", [600.0]).to_numpy()[0, :3] - eph.state("R07", [600.0]).to_numpy()[0, :3]
    assert np.allclose(d, [-0.36, 0.08, 0.18], atol=1e-9)


def _table_from(eph):
    """GLONASS sets re-built from states at their nodes (t_b every 30 min in GLONASS time)."""
    rows = []
    for k in range(1, 25):
        sat = f"R{k:02d}"
        for tb in (10800.0, 12600.0):
            t_gps = tb - 10782.0
            s = eph.state(sat, [t_gps]).to_numpy()[0]
            rows.append([k, eph.channel(sat), tb, *s[:6], 0, 0, 0, -s[6], s[7]])
    return rows
