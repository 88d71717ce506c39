"""Every option the core publishes in ``_core.OPTIONS`` is rejected by name when misspelt,
through the public Python API, with an ``InputError`` naming the caller's parameter.

Most options have their bad-value case next to the rest of their module's boundary tests
(listed in ``ELSEWHERE``); the ones without such a module test are here. A new option in
the core fails ``test_every_option_has_a_bad_value_case`` until a case is added."""

import numpy as np
import pandas as pd
import pytest

import atomnav as an
from atomnav import _core, astro, gnss
from atomnav import filter as fl
from atomnav.gnss.ephemeris import GLONASS_COLUMNS, GPS_COLUMNS, Ephemerides

HERE = {
    "Helmert": ("datum", lambda: Ephemerides(pd.DataFrame(columns=GPS_COLUMNS), pd.DataFrame(columns=GLONASS_COLUMNS), 18.0,
                                             datum="nope")),
    "Formulation": ("formulation", lambda: gnss.GnssOptions(formulation="nope")),
    "LoopMode": ("mode", lambda: fl.KalmanFilter(np.eye(2), mode="nope")),
    "Discretization": ("method", lambda: fl.Scenario(np.zeros((1, 2, 2)), np.zeros((1, 2, 2)), [0.1], np.eye(2), np.eye(2),
                                                     np.eye(2), [True, True], method="nope").sigmas()),
    "DiffForm": ("p_diff", lambda: astro.Vasilyuk2024().run(1, p_diff="nope")),
    "MountCovariance": ("covariance", lambda: astro.calibrate(np.tile(np.eye(3), (3, 1, 1)), np.tile(np.eye(3), (3, 1, 1)),
                                                              covariance="nope")),
}

#: option → the test file holding its bad-value case (None: the option is an output only)
ELSEWHERE = {
    "Adaptive": "test_noise_boundary.py", "AllanKind": "test_noise_boundary.py", "DataType": "test_noise_boundary.py",
    "NoiseForm": "test_noise_boundary.py", "NoiseType": "test_noise_boundary.py", "TauGrid": "test_noise_boundary.py",
    "X0": "test_noise_boundary.py",
    "CalibrationInit": "test_astro_boundary.py", "CalibrationSolver": "test_astro_boundary.py",
    "ResidualForm": "test_astro_boundary.py", "GyroErrorMode": "test_astro_boundary.py",
    "TaylorVariant": "test_astro_boundary.py",
    "ClosedForm": "test_cai_options.py", "ForceMode": "test_cai_options.py", "Gravity": "test_cai_options.py",
    "Interpolation": "test_cai_options.py", "MlMethod": "test_cai_options.py", "OmegaDot": "test_cai_options.py",
    "PhaseSource": "test_cai_options.py", "CaiData": "test_cai_options.py", "IncompleteShots": "test_cai_own_data.py",
    "Ellipsoid": "test_bad_input.py", "ImuKind": "test_bad_input.py", "Vertical": "test_bad_input.py",
    "BiasKind": "test_filter_aided_config.py", "UpdateForm": "test_filter_engine.py",
    "Verdict": None,
}


def test_every_option_has_a_bad_value_case():
    assert set(HERE) | set(ELSEWHERE) == set(_core.OPTIONS)
    assert not set(HERE) & set(ELSEWHERE)


@pytest.mark.parametrize("option", sorted(HERE))
def test_a_misspelt_option_names_its_parameter(option):
    parameter, call = HERE[option]
    with pytest.raises(an.InputError, match=f"{parameter}: unknown option \"nope\"") as e:
        call()
    assert e.value.parameter == parameter
