"""How goal episodes are collected: only feasible actions run, and an episode ends where none is drawn or the head
does not see the object (truncated, with its reason); the head searches the far part of the table too."""

import importlib
import json
from types import SimpleNamespace

import numpy as np
import pytest

from affordance_env.dataset import DatasetError, collect
from affordance_env.dataset.collect import PARAM_DRAWS, _goal_episode_rows, goal_step_actions
from affordance_env.dataset.format import chunk_metadata, chunk_name
from affordance_env.goal_env import TapAffordanceGoalEnv
from affordance_env.registry import BEHAVIOR_NAMES

SMALL = {"camera_width": 32, "camera_height": 24}
SETTINGS = {"seed": 5, "action": "random", "save_images": False}


class StubEnv:
    """Just enough of TapAffordanceGoal-v2 for ``_goal_episode_rows``: ``feasible`` as told, and a ``step`` that
    records its actions and returns an interaction with no failure (``interaction_row`` is replaced)."""

    def __init__(self, feasible, seen_after=lambda step: True, visible_at_reset=True):
        self.accepts, self.seen_after, self.visible_at_reset = feasible, seen_after, visible_at_reset
        self.asked, self.run = [], []

    def reset(self, seed):
        self.seen = self.visible_at_reset
        return {}, {"visible": self.visible_at_reset}

    def feasible(self, behavior, params):
        ok = self.accepts(behavior, params)
        self.asked.append(((behavior, tuple(params)), ok))
        return ok

    def step(self, action):
        self.run.append((action["behavior"], tuple(action["params"])))
        # the interaction starts from what the head saw before it
        self.last_result = SimpleNamespace(failure=None, initial=SimpleNamespace(visible=self.seen))
        self.seen = self.seen_after(len(self.run) - 1)
        info = {"failure": None, "visible": True, "observation_visible": self.seen, "distance": 0.1,
                "is_success": False}
        return {"desired_goal": np.zeros(2), "achieved_goal": np.ones(2)}, -1.0, False, False, info


@pytest.fixture
def rows_as_steps(monkeypatch):
    """``interaction_row`` gives each interaction's step and the visibility it started from."""
    monkeypatch.setattr(importlib.import_module("affordance_env.dataset.collect"), "interaction_row",
                        lambda episode, seed, result, images, goal: {
                            "step": goal.step, "visible_initial": result.initial.visible})


def test_a_goal_episode_runs_only_actions_that_feasible_accepts(rows_as_steps):
    env = StubEnv(lambda behavior, params: behavior == 3 and params[0] > 0)  # grasps with a positive first param
    rows, failure, truncation = _goal_episode_rows(env, SETTINGS, 0)
    assert len(env.run) == 5 and any(not ok for _, ok in env.asked)  # refused ones were drawn ...
    assert env.run == [action for action, ok in env.asked if ok]  # ... and never run: each accepted one is
    assert [row["step"] for row in rows] == [0, 1, 2, 3, 4] and failure is None and truncation is None


def test_a_goal_episode_without_a_feasible_action_ends_there_truncated(rows_as_steps):
    env = StubEnv(lambda behavior, params: len(env.run) < 2)  # the object out of reach after two interactions
    rows, failure, truncation = _goal_episode_rows(env, SETTINGS, 0)
    assert len(env.run) == 2 and len(rows) == 2 and failure is None
    assert truncation.startswith("infeasible:") and "step 2" in truncation
    assert len(env.asked) == 2 + PARAM_DRAWS * len(BEHAVIOR_NAMES)  # every behaviour tried, then the end


def test_a_goal_episode_ends_where_the_head_does_not_see_the_object(rows_as_steps):
    env = StubEnv(lambda behavior, params: True, seen_after=lambda step: step == 0)  # lost after the second
    rows, failure, truncation = _goal_episode_rows(env, SETTINGS, 0)
    assert len(env.run) == 2 and failure is None
    assert truncation.startswith("lost:") and "step 2" in truncation
    # each interaction starts from what the head saw before it, not from the last one's final snapshot
    assert [row["visible_initial"] for row in rows] == [True, True]
    unseen = StubEnv(lambda behavior, params: True, visible_at_reset=False)
    rows, failure, truncation = _goal_episode_rows(unseen, SETTINGS, 0)
    assert unseen.run == [] and rows == [] and truncation.startswith("lost:") and "step 0" in truncation


def test_truncated_episodes_are_recorded_and_a_dataset_of_other_rules_is_not_resumed(tmp_path, monkeypatch):
    monkeypatch.setattr(TapAffordanceGoalEnv, "feasible", lambda self, behavior, params: False)
    run = {"seed": 2, "action": "random", "chunk_size": 2, "progress": False, "env_id": "TapAffordanceGoal-v2",
           "env_options": SMALL}
    out = collect(tmp_path / "goal", 2, **run)
    meta, rows = chunk_metadata(out / chunk_name(0))
    assert rows == 0 and meta["chunk"]["failures"] == {}  # nothing was run: nothing failed
    assert set(meta["chunk"]["truncated"]) == {"0", "1"}
    assert all(reason.startswith("infeasible:") for reason in meta["chunk"]["truncated"].values())
    manifest = json.loads((out / "manifest.json").read_text())
    assert "feasible actions only" in manifest["settings"]["goal_episodes"]
    del manifest["settings"]["goal_episodes"]  # as collected before the rule: its episodes ran refused actions
    (out / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(DatasetError, match="goal_episodes"):
        collect(out, 4, **run)


def test_the_goal_env_says_whether_its_observation_sees_the_object():
    env = TapAffordanceGoalEnv(**SMALL)
    env.reset(seed=0, options={"position": (-0.30, 0.03), "object_type": "sphere", "size": 0.06})
    *_, info = env.step({"behavior": "tap", "params": np.zeros(3, np.float32)})
    assert info["observation_visible"] is True and info["attention"]["visible"]


def test_the_head_finds_an_object_on_the_far_part_of_the_table():
    """Looking down at an object near the robot, the head finds it again once it lies near the table's far edge:
    only a gaze that looks up sees it there."""
    env = TapAffordanceGoalEnv(**SMALL)
    for start in ((-0.20, -0.15), (-0.20, 0.0)):
        env.reset(seed=0, options={"position": start, "object_type": "sphere", "size": 0.06})
        physics = env.world.physics
        pose = physics.object_pose()
        pose[:2] = (-0.715, -0.154)
        physics.set_object_pose(pose)
        seen = env.world.observe(env.np_random)
        assert seen.visible and seen.attention.success, start


def test_every_behaviour_is_tried_at_each_step_each_first_as_often():
    firsts = []
    for episode in range(200):
        actions = list(goal_step_actions(0, episode, 0, "random"))
        behaviors = [a["behavior"] for a in actions]
        assert sorted(set(behaviors)) == list(range(len(BEHAVIOR_NAMES)))  # all of them, the draw's too
        assert all(behaviors.count(b) == PARAM_DRAWS for b in set(behaviors))
        firsts.append(behaviors[0])
    counts = np.bincount(firsts, minlength=len(BEHAVIOR_NAMES))
    assert counts.min() > 200 / len(BEHAVIOR_NAMES) / 2  # none neglected
    same = [a["params"] for a in goal_step_actions(0, 7, 2, "random")]
    np.testing.assert_array_equal(same, [a["params"] for a in goal_step_actions(0, 7, 2, "random")])


def test_the_episode_rule_says_the_reach_clearance_feasible_keeps():
    # A goal dataset is resumed only under the same rule: a clearance changed without its rule would resume data
    # whose actions another feasible() chose.
    from affordance_env.behaviors.stroke import REACH_CLEARANCE
    from affordance_env.dataset.collect import GOAL_EPISODE_RULE

    assert f"a reach kept {1000 * REACH_CLEARANCE:g} mm from the object" in GOAL_EPISODE_RULE
