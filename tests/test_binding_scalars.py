"""Scalar float arguments of the extension read numbers only: text in any form (str,
bytes, a numpy string scalar or 0-d string array, whose float() would parse it) is a
TypeError naming the argument, never a number and never a bare ValueError."""

import numpy as np
import pytest

from atomnav import _core

# (function, its float arguments by name, a valid value each); the oracle for the valid
# call is its documented closed form (white-noise sigma = density / sqrt(dt) for rates)
DENSITY, DT = 2e-3, 0.01


@pytest.mark.parametrize("text", ["0.01", b"0.01", np.str_("0.01"), np.array("0.01"), np.array("1e+"), np.array(b"0.01")])
def test_text_is_a_type_error_naming_the_argument(text):
    with pytest.raises(TypeError, match="dt"):
        _core.imu_white_sigma(DENSITY, text, "rates")


@pytest.mark.parametrize("number", [DT, np.float64(DT), np.array(DT), np.float32(DT), np.array([DT])[0]])
def test_numbers_in_any_numeric_form_are_read(number):
    assert _core.imu_white_sigma(DENSITY, number, "rates") == pytest.approx(DENSITY / np.sqrt(DT), rel=1e-6)


def test_optional_float_none_and_text():
    # an optional float (the baro loop's zeta) keeps None as "not given" and refuses text
    args = dict(t0=0.0, lla=np.array([0.9, 0.6, 100.0]), vel_ned=np.zeros(3), q_nb=np.array([1.0, 0.0, 0.0, 0.0]), kind="rates",
                ellipsoid="WGS84", vertical="free")
    _core.Strapdown(**args, zeta=None)
    with pytest.raises(TypeError, match="zeta"):
        _core.Strapdown(**args, zeta=np.array("0.7"))


@pytest.mark.parametrize("call, name", [
    (lambda x: _core.zero_velocity(np.array([1.0, 2.0]), x), "sigma"),
    (lambda x: _core.zero_rate(np.array([1.0, 2.0]), x, 0.0), "gyro_psd"),
    (lambda x: _core.zero_rate(np.array([1.0, 2.0]), 1e-12, x), "sigma"),
])
def test_alignment_sources_refuse_text(call, name):
    call(0.01)  # a number is read
    with pytest.raises(TypeError, match=name):
        call(np.str_("0.01"))
