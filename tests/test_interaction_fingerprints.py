"""Every behaviour's interactions at random actions stay the same bit for bit, unless the physics is meant to change.

The fingerprints in ``tests/data/interactions/<behavior>.json`` pin down 12 interactions per behaviour (seed 0,
random actions, a small range image): the action, the ground truth, the initial and final features and the
effect of each, as SHA-256 digests (:mod:`affordance_env.dataset.fingerprint`). A change that only reorganises the
code must leave them as they are: bit for bit where the fingerprints were made with the same versions on the same
kind of CPU, and by what holds across machines elsewhere (the same interactions drawn, their outcome labels). A
change meant to alter what the robot does (its physics, motion or perception) rewrites them::

    TAP_AFFORDANCE_REWRITE_FINGERPRINTS=1 python -m pytest tests/test_interaction_fingerprints.py
"""

import json
import os
from pathlib import Path

import pytest

from affordance_env import load_dataset
from affordance_env.dataset import collect
from affordance_env.dataset.fingerprint import compare_fingerprints, fingerprint

HERE = Path(__file__).resolve().parent / "data" / "interactions"
EPISODES = 12
OPTIONS = {"camera_width": 40, "camera_height": 30}


@pytest.mark.slow
@pytest.mark.parametrize("behavior", ["tap", "tap_back", "push", "grasp", "draw"])
def test_interactions_at_random_actions_stay_the_same(behavior, tmp_path):
    out = collect(tmp_path / behavior, episodes=EPISODES, seed=0, workers=1, action="random",
                  env_options={"behavior": behavior, **OPTIONS}, chunk_size=EPISODES, progress=False)
    found = fingerprint(load_dataset(out), EPISODES)
    path = HERE / f"{behavior}.json"
    if os.environ.get("TAP_AFFORDANCE_REWRITE_FINGERPRINTS"):
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(found, indent=1, sort_keys=True) + "\n")
    expected = json.loads(path.read_text())
    check = compare_fingerprints(expected, found)
    assert check.ok, f"{check.summary()}: {check.problems}"
