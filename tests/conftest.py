import numpy as np
import pytest

import railslosh as rs


@pytest.fixture(scope="session")
def tank_mesh():
    return rs.mesh.cylinder_tank(fill=0.5, n_length=6, n_width=4, n_height=2)


@pytest.fixture
def rng():
    return np.random.default_rng(12345)
