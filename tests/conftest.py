import numpy as np
import pandas as pd
import pytest


def with_initial(traj, nav: pd.DataFrame) -> pd.DataFrame:
    """Prepend the trajectory's first sample to an increments-driven solution so the
    solution and the truth share time stamps."""
    return pd.concat([traj.df.iloc[:1], nav], ignore_index=True)


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)
