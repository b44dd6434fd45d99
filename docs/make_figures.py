"""Draw every picture under docs/ again from the code, with one command.

    MUJOCO_GL=egl python docs/make_figures.py [--only tap_strip grasp_strip hand_mount]

Run from anywhere; it writes into the docs/ folder beside this script:

- ``tap_strip.png``: one canonical tap of a ball (``python examples/tap_strip.py --behavior tap --object sphere
  --seed 4``), six rendered frames with the range images, masks and effect of its two snapshots;
- ``grasp_strip.png``: one canonical grasp of a ball (``python examples/tap_strip.py --behavior grasp --object
  sphere --seed 0``), the same layout;
- ``hand_mount.png``: the fingered hand over the V2.5 hand mesh it replaces (``python examples/hand_mount.py``).

The strips render every frame of the interaction with OpenGL (``MUJOCO_GL``: EGL or OSMesa, chosen automatically
when unset), 30 per simulated second: the tap's 82, the grasp's 341, so without a GPU the grasp's strip takes
several times the tap's (85 s and 793 s on a busy 2-core machine without a GPU). The reference reproductions under
``docs/reproduction/`` have figures of their own, which ``affordance reproduce`` draws (their README gives the
commands); this script leaves them as they are.
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent

#: Picture name under docs/ -> the example script and its arguments that draw it (without --out).
FIGURES = {
    "tap_strip": ["examples/tap_strip.py", "--behavior", "tap", "--object", "sphere", "--seed", "4"],
    "grasp_strip": ["examples/tap_strip.py", "--behavior", "grasp", "--object", "sphere", "--seed", "0"],
    "hand_mount": ["examples/hand_mount.py"],
}


def draw(name: str, scratch: Path) -> Path:
    """Run the script that draws ``name`` with its output in ``scratch``; move the picture into docs/."""
    script, *arguments = FIGURES[name]
    out = scratch / name
    # tap_strip.py appends ".png" to --out (and writes a video beside it); hand_mount.py takes the file name.
    out_argument = f"{out}.png" if script.endswith("hand_mount.py") else str(out)
    subprocess.run([sys.executable, str(ROOT / script), *arguments, "--out", out_argument], check=True, cwd=scratch)
    target = DOCS / f"{name}.png"
    shutil.move(f"{out}.png", target)
    return target


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", nargs="+", choices=sorted(FIGURES), default=list(FIGURES),
                        help="draw only these pictures (default: all)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as scratch:
        for name in args.only:
            start = time.perf_counter()
            target = draw(name, Path(scratch))
            print(f"{target.relative_to(ROOT)}: {time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main()
