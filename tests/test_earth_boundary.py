"""Positions whose geodetic coordinates are undefined raise, they do not return NaN."""

from __future__ import annotations

import numpy as np
import pytest

import atomnav
from atomnav import earth


def test_centre_of_the_earth_is_an_input_error():
    with pytest.raises(atomnav.InputError) as e:
        earth.ecef_to_lla([0.0, 0.0, 0.0])
    assert (e.value.parameter, e.value.index) == ("ecef", 0)
    good = earth.lla_to_ecef([0.9, 0.1, 50.0])
    with pytest.raises(atomnav.InputError) as e:
        earth.ecef_to_lla(np.vstack([good, [0.0, 0.0, 0.0]]))
    assert e.value.index == 1
    np.testing.assert_allclose(earth.ecef_to_lla(good), [0.9, 0.1, 50.0], atol=1e-8)


def test_bad_latitude_row_is_named():
    with pytest.raises(atomnav.InputError) as e:
        earth.lla_to_ecef([[0.1, 0.0, 0.0], [2.0, 0.0, 0.0]])
    assert (e.value.parameter, e.value.index) == ("lla", 1)


def test_scalar_wrappers_name_their_own_parameters():
    # gravity/radii/schuler_period stack lat and h into an lla array: the core's errors
    # about it named "lla", not a parameter of the called function
    for fn in (lambda: earth.gravity(float("-inf")), lambda: earth.radii([0.1, 3.0]),
               lambda: earth.schuler_period(-float("inf")), lambda: earth.gravity(3.0, 0.0)):
        with pytest.raises(atomnav.InputError) as e:
            fn()
        assert e.value.parameter == "lat", str(e.value)
    with pytest.raises(atomnav.InputError) as e:
        earth.gravity([0.1, 0.2], [1.0, 2.0, 3.0])
    assert e.value.parameter == "h"
    with pytest.raises(TypeError, match="^lat: "):
        earth.gravity(None)
    with pytest.raises(atomnav.InputError) as e:
        earth.ellipsoid("WGS-84")
    assert e.value.parameter == "name"


def test_navigation_rates_rows_must_match():
    # fuzz seed 20261202: 5 positions and 3 velocities reached numpy's concatenate
    with pytest.raises(atomnav.InputError) as e:
        earth.navigation_rates(np.zeros((5, 3)), np.ones((3, 3)))
    assert e.value.parameter == "vel_ned" and "5 rows" in str(e.value)
