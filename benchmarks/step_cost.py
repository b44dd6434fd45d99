"""What the Python around MuJoCo costs per physics step of canonical interactions, and taps per second.

    python benchmarks/step_cost.py [--episodes 40] [--rounds 3] [--behavior tap] [--cpu N] [--tree PATH]
    python benchmarks/step_cost.py --baseline PATH [--rounds 4] ...     # alternate with another checkout

A canonical interaction is ``reset(seed=i)`` and ``step`` at the action 0 (the paper's canonical tap, or with
``--behavior grasp`` the canonical grasp), i = 0 .. episodes - 1, in the newest ``TapAffordance`` version the tree
registers, at its default options. Each round runs in a fresh subprocess pinned to one core, which builds the env,
warms up on a few interactions and then times the episodes; ``mujoco.mj_step`` is wrapped before the project is
imported, so every physics step is timed however the project calls it (the wrapper's own cost, about 0.3 us per
call, counts as non-physics time, in every tree alike). Per round it prints

- ``mj_step`` per physics step [us] and wall time per physics step [us];
- the ratio of the non-physics time (everything but ``mj_step``) to the physics time, and the same ratio without
  perception (the range images, ``RangeCamera.capture``, and the 49 features), which no stepping loop spends;
- taps (interactions) per second.

With ``--baseline PATH`` (a checkout of another commit, e.g. ``git worktree add /tmp/base 0dcac75``) the rounds
alternate between this checkout and the baseline (ABBA order), each subprocess importing its tree's
``affordance_env`` through ``PYTHONPATH``, all on the same core in the same minutes, so that both share the
machine's varying load; the median taps per second of each and their ratio are printed at the end.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from types import ModuleType
from typing import Any

HERE = Path(__file__).resolve().parent
#: The checkout this script belongs to: the "current" tree.
CURRENT_TREE = HERE.parent
#: Interactions run before the timed ones in each subprocess (imports, caches, first-call costs) [episodes].
WARMUP_EPISODES = 3


# --- the worker: one round in one process -----------------------------------------------------------------------
def _worker(behavior: str, episodes: int) -> dict[str, Any]:
    """Time ``episodes`` canonical interactions of ``behavior`` in this process; returns seconds and counts."""
    import mujoco

    spent = {"mj_step": 0.0, "perception": 0.0}
    counts = {"steps": 0, "calls": 0}
    real_step = mujoco.mj_step
    perf_counter = time.perf_counter

    def timed_step(model: mujoco.MjModel, data: mujoco.MjData, nstep: int = 1) -> None:
        start = perf_counter()
        real_step(model, data, nstep)
        spent["mj_step"] += perf_counter() - start
        counts["steps"] += nstep
        counts["calls"] += 1

    # Before the project is imported: a module that binds mj_step at import time binds the wrapper.
    mujoco.mj_step = timed_step
    import gymnasium as gym
    import numpy as np

    import affordance_env  # noqa: F401 (registers the env)

    env = gym.make(_env_id(gym), behavior=behavior).unwrapped
    _time_perception(spent)
    action = np.zeros_like(env.action_space.sample(), dtype=np.float64)  # the canonical action: 0
    for i in range(WARMUP_EPISODES):
        env.reset(seed=10_000 + i)
        env.step(action)
    spent.update(mj_step=0.0, perception=0.0)
    counts.update(steps=0, calls=0)
    start = perf_counter()
    for i in range(episodes):
        env.reset(seed=i)
        env.step(action)
    wall = perf_counter() - start
    return {"wall": wall, **spent, **counts, "episodes": episodes}


def _env_id(gym: ModuleType) -> str:
    """The newest registered version of ``TapAffordance`` in this tree (``TapAffordance-v1``, ``-v2``, ...)."""
    versions = [name for name in gym.registry if re.fullmatch(r"TapAffordance-v\d+", name)]
    return max(versions, key=lambda name: int(name.rsplit("v", 1)[1]))


def _time_perception(spent: dict[str, float]) -> None:
    """Count the range images (``RangeCamera.capture``) and the features (``compute_features`` and
    ``object_features``, wherever a module of this tree calls them by name) into ``spent["perception"]`` [s]."""
    from affordance_env import features
    from affordance_env.camera import RangeCamera

    def timed(fn: Callable[..., Any]) -> Callable[..., Any]:
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            start = time.perf_counter()
            try:
                return fn(*args, **kwargs)
            finally:
                spent["perception"] += time.perf_counter() - start
        return wrapper

    RangeCamera.capture = timed(RangeCamera.capture)  # type: ignore[method-assign]
    # compute_features, and object_features where the tree has it (the features of the object's pixels alone)
    for name in ("compute_features", "object_features"):
        original = getattr(features, name, None)
        if original is None:
            continue
        for module in list(sys.modules.values()):  # the env is built: every module that calls it is loaded
            if getattr(module, "__name__", "").startswith("affordance_env.") and module is not features \
                    and getattr(module, name, None) is original:
                setattr(module, name, timed(original))  # any module of the tree


# --- the driver ---------------------------------------------------------------------------------------------------
def _pin(cpu: int | None) -> str:
    """Pin this process (and so its subprocesses) to one core; returns a description."""
    if not hasattr(os, "sched_setaffinity"):
        return "not pinned (no sched_setaffinity on this system)"
    allowed = sorted(os.sched_getaffinity(0))
    chosen = allowed[-1] if cpu is None else cpu
    os.sched_setaffinity(0, {chosen})
    return f"pinned to core {chosen}"


def _run_round(tree: Path, behavior: str, episodes: int) -> dict[str, Any]:
    """One round in a subprocess importing ``tree``'s ``affordance_env``."""
    path = os.pathsep.join(p for p in (str(tree), os.environ.get("PYTHONPATH", "")) if p)
    env = {**os.environ, "PYTHONPATH": path, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
           "MKL_NUM_THREADS": "1"}
    command = [sys.executable, str(Path(__file__).resolve()), "--worker", "--behavior", behavior,
               "--episodes", str(episodes)]
    # Run from outside both trees: the working directory must not shadow PYTHONPATH.
    done = subprocess.run(command, env=env, cwd=tree.parent, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"the round in {tree} failed:\n{done.stderr[-3000:]}")
    result = json.loads(done.stdout.strip().splitlines()[-1])
    _check_tree(result, tree)
    return result


def _check_tree(result: dict[str, Any], tree: Path) -> None:
    """The subprocess imported ``tree``'s package, not another one (an editable install could shadow it)."""
    imported = Path(result["package"]).resolve()
    if tree.resolve() not in imported.parents:
        raise RuntimeError(f"the round for {tree} imported affordance_env from {imported}.")


def _describe(label: str, r: dict[str, float]) -> str:
    """One line of a round: taps per second, per physics step [us], and the ratios."""
    steps, physics = r["steps"], r["mj_step"]
    other = r["wall"] - physics
    return (f"{label:9s} {r['episodes'] / r['wall']:6.1f} taps/s | per physics step: mj_step "
            f"{1e6 * physics / steps:5.1f} us, wall {1e6 * r['wall'] / steps:5.1f} us | non-physics/physics "
            f"{other / physics:5.3f}, without perception {(other - r['perception']) / physics:5.3f} | "
            f"{steps / r['episodes']:.0f} steps in {r['calls'] / r['episodes']:.0f} mj_step calls per tap")


def _summary(label: str, rounds: list[dict[str, float]]) -> dict[str, float]:
    """Print the medians of a tree's rounds; returns its median and best taps per second."""
    rates = [r["episodes"] / r["wall"] for r in rounds]
    ratios = [(r["wall"] - r["mj_step"]) / r["mj_step"] for r in rounds]
    bare = [(r["wall"] - r["mj_step"] - r["perception"]) / r["mj_step"] for r in rounds]
    print(f"{label}: taps/s median {statistics.median(rates):.1f} (best {max(rates):.1f}); non-physics/physics "
          f"median {statistics.median(ratios):.3f}, without perception {statistics.median(bare):.3f}")
    return {"rate": statistics.median(rates), "best": max(rates)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--episodes", type=int, default=40, help="timed interactions per round")
    parser.add_argument("--rounds", type=int, default=3, help="rounds per tree (each a fresh subprocess)")
    parser.add_argument("--behavior", default="tap", help="the behaviour (tap, tap_back, push, grasp)")
    parser.add_argument("--baseline", type=Path, default=None, help="checkout of another commit to alternate with")
    parser.add_argument("--tree", type=Path, default=CURRENT_TREE, help="the checkout measured as current")
    parser.add_argument("--cpu", type=int, default=None, help="core to pin to (default: the last one allowed)")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        result = _worker(args.behavior, args.episodes)
        import affordance_env

        result["package"] = str(Path(affordance_env.__file__).resolve().parent)
        print(json.dumps(result))
        return
    print(f"{args.behavior}, {args.episodes} canonical interactions per round, {args.rounds} rounds per tree, "
          f"{_pin(args.cpu)}")
    trees = {"current": args.tree.resolve()}
    if args.baseline is not None:
        if not (args.baseline / "affordance_env").is_dir():
            parser.error(f"--baseline {args.baseline} is not a checkout of the project (no affordance_env/).")
        trees["baseline"] = args.baseline.resolve()
    rounds: dict[str, list[dict[str, float]]] = {label: [] for label in trees}
    order = list(trees)
    for k in range(args.rounds):
        for label in order if k % 2 == 0 else order[::-1]:  # ABBA: neither tree always runs first
            result = _run_round(trees[label], args.behavior, args.episodes)
            rounds[label].append(result)
            print(f"round {k + 1}: " + _describe(label, result), flush=True)
    summaries = {label: _summary(label, rounds[label]) for label in trees}
    if "baseline" in summaries:
        ratio = summaries["current"]["rate"] / summaries["baseline"]["rate"]
        print(f"current / baseline taps per second: {ratio:.3f} (medians; best rounds "
              f"{summaries['current']['best'] / summaries['baseline']['best']:.3f})")


if __name__ == "__main__":
    main()
