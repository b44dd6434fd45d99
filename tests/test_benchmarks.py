"""The benchmark scripts that reach into the environment's modules (to time its parts in place) still run: a
rename inside the package would otherwise break them silently, since nothing else calls them."""

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.slow
@pytest.mark.parametrize("argv", [
    ["benchmarks/env.py", "--episodes", "2", "--repeats", "1", "--width", "40", "--height", "30"],
    ["benchmarks/step_cost.py", "--episodes", "2", "--rounds", "1"],
    ["benchmarks/draw.py", "--episodes", "2"],
    ["benchmarks/feasible.py", "--draws", "3"],  # patches MotionExecutor.ik to time the IK's whole budget
    ["benchmarks/put_down_offset.py", "--draws", "4"],  # wraps MotionExecutor.line and grasp.plan_grasp
    ["benchmarks/render_frames.py", "--episodes", "2"],  # replaces World.picture
    ["benchmarks/reach_clearance.py", "--episodes", "2"],  # plans the reach with the strokes' functions
    ["benchmarks/reach_lag.py", "--draws", "6"],  # plans the reach with the strokes' functions, watches the steps
    ["benchmarks/planner.py", "--objects", "2", "--goals", "1", "--spread", "0"],  # sets planner.SPREAD_WEIGHT
])
def test_benchmark_runs(argv):
    done = subprocess.run([sys.executable, *argv], cwd=ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip()
