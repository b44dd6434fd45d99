import os

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


@pytest.fixture(scope="session", autouse=True)
def scratch_working_directory(tmp_path_factory):
    """Run the tests in a scratch directory: MuJoCo writes its warnings to MUJOCO_LOG.TXT in the working
    directory, and the commands write their default outputs (./reproduction, ./default-taps) there."""
    previous = os.getcwd()
    os.chdir(tmp_path_factory.mktemp("cwd"))
    yield
    os.chdir(previous)


@pytest.fixture(scope="session", autouse=True)
def scratch_user_data(tmp_path_factory):
    """Default models that tests rebuild go to a scratch data directory, not the user's."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("TAP_AFFORDANCE_DATA", str(tmp_path_factory.mktemp("user-data")))
        yield
