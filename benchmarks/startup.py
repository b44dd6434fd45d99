"""What a new process pays before its first interaction: imports and building the env, with and without the cache
of compiled models (``affordance_env.model_cache``).

    python benchmarks/startup.py [--repeats 5] [--behavior tap]

Each round starts fresh Python processes that import ``affordance_env.tap_env`` and build the env, as a
collection worker does: one with the cache off (the baseline: MuJoCo compiles the scene) and one with it on,
taking turns so that both see the same load. Prints the median of each and their ratio. The cache directory is
a temporary one, filled by a first, unmeasured build.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

_CHILD = """
import json, time
start = time.perf_counter()
from affordance_env.tap_env import TapAffordanceEnv
imported = time.perf_counter()
TapAffordanceEnv(behavior={behavior!r})
print(json.dumps({{"import": imported - start, "build": time.perf_counter() - imported}}))
"""


def _run(behavior: str, cache: str) -> dict[str, float]:
    env = {**os.environ, "TAP_AFFORDANCE_CACHE": cache}
    out = subprocess.run([sys.executable, "-c", _CHILD.format(behavior=behavior)], env=env, check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--behavior", default="tap")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as cache:
        _run(args.behavior, cache)  # fills the cache
        runs: dict[str, list[dict[str, float]]] = {"off": [], "on": []}
        for _ in range(args.repeats):
            runs["off"].append(_run(args.behavior, "off"))
            runs["on"].append(_run(args.behavior, cache))
    medians = {k: {part: statistics.median(r[part] for r in v) for part in ("import", "build")}
               for k, v in runs.items()}
    print(f"A new process, {args.behavior} env, median of {args.repeats} (taking turns):")
    for k, label in (("off", "compiled (cache off)"), ("on", "from the cache")):
        m = medians[k]
        print(f"  {label:<22}: import {m['import']:.3f} s, build {m['build']:.3f} s, "
              f"total {m['import'] + m['build']:.3f} s")
    off, on = medians["off"], medians["on"]
    print(f"  build: {on['build'] / off['build']:.2f} x the baseline; import + build: "
          f"{(on['import'] + on['build']) / (off['import'] + off['build']):.2f} x")


if __name__ == "__main__":
    main()
