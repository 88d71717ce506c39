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
