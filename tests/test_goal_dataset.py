"""Collections of TapAffordanceGoal-v2 episodes: a row per interaction with its episode and step, and the goal."""

import json

import numpy as np
import pytest

from affordance_env import load_dataset
from affordance_env.dataset import collect, read_manifest
from affordance_env.dataset.format import GOAL_COLUMNS, chunk_metadata, collect_command
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_env.workspace import in_any_workspace

SMALL = {"camera_width": 32, "camera_height": 24}
RUN = {"seed": 3, "action": "random", "chunk_size": 3, "progress": False, "max_failure_share": 1.0,
       "env_id": "TapAffordanceGoal-v2"}


@pytest.fixture(scope="module")
def goal_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("goal") / "episodes"
    return collect(out, 6, env_options={**SMALL, "position_range": "workspace"}, **RUN)


def test_goal_episodes_are_rows_of_interactions_with_episode_step_and_goal(goal_dir):
    frame = load_dataset(goal_dir)
    manifest = read_manifest(goal_dir)
    assert manifest["settings"]["env_id"] == "TapAffordanceGoal-v2"
    assert "behavior" not in manifest["settings"]["env_options"]  # the env chooses it at every step
    assert manifest["rows"] == len(frame) > 6  # several interactions per episode
    command = collect_command(goal_dir, manifest)  # what an error message tells a user to run
    assert "--env TapAffordanceGoal-v2" in command and "--position-range workspace" in command
    assert {"step", *GOAL_COLUMNS} <= set(frame.columns)
    assert set(frame["behavior"]) <= set(BEHAVIOR_NAMES) and frame["behavior"].nunique() >= 3
    truncated = {k: v for chunk in sorted(goal_dir.glob("chunk-*.parquet"))
                 for k, v in chunk_metadata(chunk)[0]["chunk"]["truncated"].items()}
    assert all(reason.startswith(("infeasible:", "lost:")) for reason in truncated.values())
    assert not set(truncated) & {str(e) for e in frame.attrs["failures"]}  # cut short is not failed
    for episode, rows in frame.groupby("episode"):
        steps = rows["step"].to_numpy()
        np.testing.assert_array_equal(steps, np.arange(len(steps)))  # from 0, none missing
        assert rows[["goal_x", "goal_y"]].nunique().max() == 1  # one goal per episode
        # the object stays: each interaction starts where the one before it left the object, at rest (the head
        # turning to it again moves it by less than 0.1 mm: the contacts of an object at rest still creep by
        # micrometres)
        for axis in ("x", "y"):
            np.testing.assert_allclose(rows[f"true_initial_{axis}"].to_numpy()[1:],
                                       rows[f"true_final_{axis}"].to_numpy()[:-1], atol=1e-4)
        ended = rows.iloc[-1]
        failed = episode in frame.attrs["failures"]
        cut_short = str(episode) in truncated  # no feasible action drawn, or the object not seen
        assert failed or cut_short or len(rows) == 5 or ended["goal_reached"] or ended["outcome"] == "off_table"
        assert rows["visible_initial"].all()  # an interaction starts only from an observation that sees the object
    first = frame[frame["step"] == 0]
    assert np.all(in_any_workspace(first[["true_initial_x", "true_initial_y"]].to_numpy()))
    np.testing.assert_allclose(frame["goal_distance"], np.hypot(frame["achieved_x"] - frame["goal_x"],
                                                                 frame["achieved_y"] - frame["goal_y"]))


def test_goal_episodes_resume_to_the_same_rows(goal_dir, tmp_path):
    out = collect(tmp_path / "part", 3, env_options={**SMALL, "position_range": "workspace"}, **RUN)
    collect(out, 6, env_options={**SMALL, "position_range": "workspace"}, **RUN)
    a, b = load_dataset(out), load_dataset(goal_dir)
    assert a.equals(b)
    assert a.attrs["failures"] == b.attrs["failures"]


def test_the_goal_env_takes_no_behavior_option(tmp_path):
    with pytest.raises(ValueError, match="chooses among all the behaviours"):
        collect(tmp_path / "x", 2, env_options={"behavior": "tap"}, **RUN)


def test_datasets_made_before_env_id_and_position_range_resume(tmp_path):
    run = {"seed": 1, "env_options": SMALL, "chunk_size": 2, "progress": False}
    out = collect(tmp_path / "old", 2, **run)
    manifest = json.loads((out / "manifest.json").read_text())
    del manifest["settings"]["env_id"], manifest["settings"]["env_options"]["position_range"]
    (out / "manifest.json").write_text(json.dumps(manifest))
    collect(out, 4, **run)  # the settings they lack count at the values they had
    assert len(load_dataset(out)) + len(load_dataset(out).attrs["failures"]) == 4
    with pytest.raises(ValueError, match="position_range"):
        collect(out, 4, **{**run, "env_options": {**SMALL, "position_range": "workspace"}})


def test_the_minari_export_refuses_goal_episodes_with_a_reason(goal_dir):
    pytest.importorskip("minari")
    from affordance_env.dataset.minari_export import export_minari

    with pytest.raises(ValueError, match="holds TapAffordanceGoal-v2 episodes"):
        export_minari(goal_dir, "tap-affordance/goal-v0")
