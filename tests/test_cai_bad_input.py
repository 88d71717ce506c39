"""Bad input → ValueError naming the field (and the shot where one is involved)."""

import numpy as np
import pytest

from atomnav import cai

N = 201
T_IMU = np.arange(N) * 1e-3
F = np.tile([0.0, 0.0, -9.8], (N, 1))
W = np.zeros((N, 3))
CH = cai.Channels.cyclic()


def predict(**kw):
    args = dict(t=T_IMU, specific_force=F, angular_rate=W, shots=[0.01, 0.07], T=0.025, channels=CH)
    args.update(kw)
    return cai.predict_phase(args.pop("t"), args.pop("specific_force"), args.pop("angular_rate"), args.pop("shots"),
                             args.pop("T"), args.pop("channels"), **args)


@pytest.mark.parametrize("T", [0.0, -0.01])
def test_nonpositive_T(T):
    with pytest.raises(ValueError, match="T: must be finite and > 0"):
        predict(T=T)


def test_pulse_times_outside_record():
    with pytest.raises(ValueError, match=r"shots: shot 1: pulse times .* outside the IMU record"):
        predict(shots=[0.01, 0.16])


def test_zero_k():
    k = CH.k.copy()
    k[3] = 0
    with pytest.raises(ValueError, match=r"channels\[3\]\.k: zero wave vector"):
        predict(channels=cai.Channels(k, CH.lever, CH.c_sb, CH.v0))


@pytest.mark.parametrize("c", [0.0, 1.2, -0.5])
def test_contrast_outside_unit_interval(c):
    with pytest.raises(ValueError, match="contrast: must be in"):
        cai.readout(0.3, contrast=c)


def test_overlapping_shots():
    with pytest.raises(ValueError, match="shots: shot 2 starts at .* before shot 1 ends"):
        predict(shots=[0.01, 0.06, 0.1])


def test_nan_in_imu_stream_names_shot_and_field():
    w = W.copy()
    w[85, 1] = np.nan
    with pytest.raises(ValueError, match=r"angular_rate: non-finite value .* at index 85 .*used by shot 1"):
        predict(angular_rate=w)
    f = F.copy()
    f[20, 0] = np.inf
    with pytest.raises(ValueError, match=r"specific_force: non-finite value .* at index 20 .*used by shot 0"):
        predict(specific_force=f)


def test_unidentifiable_noise_triple_is_reported():
    p, psi = cai.simulate_fringe(300, seed=3)
    with pytest.raises(ValueError, match="jointly unidentifiable"):
        cai.identify_noise(p - 0.5, psi, np.full(300, 0.15), free=("p0", "phi", "A"))
