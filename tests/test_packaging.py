"""The wheel carries the assets, so an installed (non-editable) package finds its scene."""

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.slow
def test_wheel_ships_assets(tmp_path):
    subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path),
         str(ROOT)],
        check=True,
        capture_output=True,
    )
    (wheel,) = tmp_path.glob("*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    assert "affordance_env/assets/scene.xml" in names
    assert "affordance_env/assets/README.md" in names
    assert "affordance_env/tap_env.py" in names and "affordance_learning/__init__.py" in names
    # every module of every package in the source tree (a subpackage left out of pyproject.toml is caught here)
    sources = {str(p.relative_to(ROOT)) for package in ("affordance_env", "affordance_learning")
               for p in (ROOT / package).rglob("*.py")}
    assert not sources - names, sorted(sources - names)
    assert "affordance_learning/data/tap_model.joblib" in names
    assert "affordance_learning/data/grasp_model.joblib" in names
    entry_points = next(n for n in names if n.endswith("entry_points.txt"))
    assert "affordance = affordance_learning.cli:main" in zipfile.ZipFile(wheel).read(entry_points).decode()


def test_assets_dir_holds_the_scene():
    from affordance_env.assets_path import assets_dir

    assert (assets_dir() / "scene.xml").is_file()
