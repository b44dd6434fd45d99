"""Location of the shipped ``assets/`` folder, in a source checkout and in an installed wheel alike.

The wheel ships the top-level ``assets/`` as ``affordance_env/assets`` (see ``pyproject.toml``).
"""

from __future__ import annotations

from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def assets_dir() -> Path:
    """Directory holding ``scene.xml``: ``affordance_env/assets`` when installed, ``<repo>/assets`` in a checkout."""
    candidates = (_PACKAGE / "assets", _PACKAGE.parent / "assets")
    for path in candidates:
        if (path / "scene.xml").is_file():
            return path
    raise FileNotFoundError(
        f"TapAffordance assets (scene.xml) not found in {[str(p) for p in candidates]}; reinstall the package."
    )
