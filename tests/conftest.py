import pytest

from affordance_env.physics import TapPhysics
from affordance_env.scene import build_model


@pytest.fixture(scope="session")
def model():
    """One compiled scene for read-only tests (compiling takes about 1 s)."""
    return build_model()


@pytest.fixture
def physics():
    """A fresh scene whose model a test may modify."""
    physics = TapPhysics(build_model())
    physics.reset_home()
    return physics
