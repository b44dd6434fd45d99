"""Location of the shipped ``assets/`` folder, in a source checkout and in an installed wheel alike."""

from __future__ import annotations

from importlib import resources
from pathlib import Path


def assets_dir() -> Path:
    """Directory holding ``scene.xml``: ``affordance_env/assets`` when installed, ``<repo>/assets`` in a checkout."""
    try:
        packaged = Path(str(resources.files("affordance_env.assets")))
        if (packaged / "scene.xml").is_file():
            return packaged
    except ModuleNotFoundError:
        pass
    checkout = Path(__file__).resolve().parent.parent / "assets"
    if (checkout / "scene.xml").is_file():
        return checkout
    raise FileNotFoundError(
        f"TapAffordance assets not found (looked in the installed package and in {checkout}); reinstall the package."
    )
