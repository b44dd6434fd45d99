"""Datasets: the fixed schema, the same data whatever the workers or scheduler, resumable, clear errors."""

import argparse
import contextlib
import dataclasses
import hashlib
import json
import os
import signal
import subprocess
import sys
import time
import warnings

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
import pytest

from affordance_env import FEATURE_GROUPS, FEATURE_NAMES, load_dataset
from affordance_env.dataset import (
    GROUND_TRUTH_COLUMNS,
    POSE_COLUMNS,
    DatasetError,
    FailureShareError,
    collect,
    images,
    interaction_action,
    interaction_seed,
    learning_data,
    read_manifest,
    show_progress,
)
from affordance_env.tap_env import TapAffordanceEnv

SMALL = {"camera_width": 32, "camera_height": 32}
RUN = {"seed": 5, "env_options": SMALL, "chunk_size": 8, "progress": False}  # the reference settings


def assert_same_dataset(path, reference: pd.DataFrame) -> None:
    """Bit for bit: the rows, and what the manifest says."""
    frame = load_dataset(path)
    pd.testing.assert_frame_equal(frame, reference, check_exact=True)
    assert frame.attrs == reference.attrs
    assert not list(path.glob(".*.tmp"))


@pytest.fixture(scope="module")
def reference_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("data") / "reference"
    collect(out, 24, workers=1, **RUN)
    return out


@pytest.fixture(scope="module")
def reference(reference_dir):
    return load_dataset(reference_dir)


def test_schema_columns_and_metadata(reference, tmp_path):
    assert len(reference) + len(reference.attrs["failures"]) == 24
    pose = [f"true_{stage}_{f}" for stage in ("initial", "final") for f in ("x", "y", "z", "qw", "qx", "qy", "qz")]
    required = ["action_0", "action_1", "action_2", "type", "size", *pose, "displacement", "rolled", "success",
                "rolling_distance", "tilt", "toppled", "outcome", "outcome_time", "contact", "visible_initial",
                "visible_final", "ik_success", "behavior", "episode", "seed"]
    required += [f"{stage}_{name}" for stage in ("initial", "final", "effect") for name in FEATURE_NAMES]
    assert set(required) <= set(reference.columns)
    assert reference["episode"].is_monotonic_increasing and reference["episode"].is_unique
    assert [interaction_seed(5, i) for i in reference.episode] == reference.seed.tolist()
    assert reference.select_dtypes("number").apply(np.isfinite).all().all()
    assert not reference.isna().any().any()
    assert reference.rolled.dtype == bool and set(reference.behavior) == {"tap"}
    assert reference.success.dtype == bool and (reference.success == reference.rolled).all()  # tap: success = rolled
    manifest = reference.attrs["manifest"]
    assert manifest["feature_names"] == list(FEATURE_NAMES) and manifest["feature_groups"] == FEATURE_GROUPS
    assert manifest["schema_version"] == 5 and manifest["complete"] and manifest["rows"] == len(reference)
    assert manifest["settings"]["env_options"]["camera_width"] == 32
    assert manifest["settings"]["env_options"]["settle_timeout"] == 3.0  # defaults are recorded too


def test_each_namespace_holds_only_its_own_columns(reference, tmp_path):
    collect(tmp_path / "img", 2, seed=2, env_options=SMALL, chunk_size=2, progress=False, save_images=True)
    for frame in (reference, load_dataset(tmp_path / "img", with_images=True)):
        for prefix in ("initial_", "final_", "effect_"):
            assert [c for c in frame if c.startswith(prefix)] == [f"{prefix}{n}" for n in FEATURE_NAMES]
        assert [c for c in frame if c.startswith("true_")] == list(POSE_COLUMNS)
        assert [c for c in frame if c.startswith("action_")] == ["action_0", "action_1", "action_2"]
        assert set(GROUND_TRUTH_COLUMNS) <= set(frame.columns)
    assert [c for c in frame if c.startswith("image_")] == ["image_initial_range", "image_initial_mask",
                                                            "image_final_range", "image_final_mask"]


def test_learning_data_gives_features_effects_and_labels_of_one_behaviour(reference):
    X, E, labels = learning_data(reference, "tap")
    assert list(X.columns) == list(E.columns) == list(FEATURE_NAMES)
    np.testing.assert_array_equal(X.to_numpy(), reference[[f"initial_{n}" for n in FEATURE_NAMES]].to_numpy())
    np.testing.assert_array_equal(E.to_numpy(), reference[[f"effect_{n}" for n in FEATURE_NAMES]].to_numpy())
    assert {"type", "size", "success", "true_initial_x"} <= set(labels.columns)
    assert not set(labels.columns) & {f"initial_{n}" for n in FEATURE_NAMES}
    assert (labels.index == X.index).all() and (labels["success"] == reference["success"]).all()
    mixed = pd.concat([reference, reference.assign(behavior="push")], ignore_index=True)
    assert len(learning_data(mixed, "push")[0]) == len(reference)
    with pytest.raises(ValueError, match=r"mixes the behaviours \['push', 'tap'\]; pass behavior="):
        learning_data(mixed)
    with pytest.raises(ValueError, match="holds no 'grasp' interactions"):
        learning_data(reference, "grasp")
    with pytest.raises(ValueError, match="lacks 1 feature column"):
        learning_data(reference.drop(columns=f"effect_{FEATURE_NAMES[3]}"))


def test_a_changed_byte_in_a_chunk_is_an_error_naming_it_and_the_command(reference, tmp_path):
    out = tmp_path / "d"
    collect(out, 16, workers=1, **RUN)
    chunk = out / "chunk-00001.parquet"
    good = chunk.read_bytes()
    assert read_manifest(out)["chunk_sha256"]["chunk-00001.parquet"] == hashlib.sha256(good).hexdigest()
    # a byte of a value inside a data page (snappy keeps random doubles as literals): pyarrow still reads the
    # file, with that value changed
    value = reference.loc[reference.episode >= 8, "true_initial_x"].iloc[0]
    at = good.index(np.float64(value).tobytes())
    data = bytearray(good)
    data[at] ^= 0x01
    chunk.write_bytes(bytes(data))
    changed = pq.read_table(chunk).to_pandas()["true_initial_x"]
    assert value not in changed.to_numpy() and (changed.to_numpy() != 0).all()
    with pytest.raises(DatasetError) as error:
        load_dataset(out)
    message = str(error.value)
    assert "chunk-00001.parquet has changed since it was written" in message
    assert f"affordance collect --out {out} --episodes 16 --seed 5 --chunk-size 8 --camera-width 32" in message
    with pytest.warns(UserWarning, match="collecting chunk-00001.parquet again: .* has changed"):
        collect(out, 16, workers=1, **RUN)  # the command the message gives redoes it
    assert chunk.read_bytes() == good
    assert_same_dataset_prefix(out, reference, 16)


def test_a_chunk_the_manifest_does_not_record_is_unfinished(reference, tmp_path):
    # a run stopped between writing a chunk and recording it: the chunk is not read, and resuming records it
    out = tmp_path / "d"
    collect(out, 16, workers=1, **RUN)
    manifest = json.loads((out / "manifest.json").read_text())
    del manifest["chunk_sha256"]["chunk-00001.parquet"]
    (out / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(DatasetError, match="1 chunk\\(s\\) missing or unfinished \\(chunk-00001.parquet\\)"):
        load_dataset(out)
    assert set(load_dataset(out, allow_incomplete=True).episode) <= set(range(8))
    before = (out / "chunk-00001.parquet").stat().st_mtime_ns
    collect(out, 16, workers=1, **RUN)
    assert (out / "chunk-00001.parquet").stat().st_mtime_ns == before  # checked and kept, not collected again
    assert_same_dataset_prefix(out, reference, 16)


def test_chunk_files(tmp_path, reference):
    collect(tmp_path / "d", 8, workers=1, **RUN)
    chunk = tmp_path / "d" / "chunk-00000.parquet"
    meta = json.loads(pq.read_schema(chunk).metadata[b"tap_affordance"])
    assert meta["schema_version"] == 5 and meta["feature_names"] == list(FEATURE_NAMES)
    assert meta["package_version"] and meta["settings"]["env_options"]["camera_height"] == 32
    assert (meta["chunk"]["start"], meta["chunk"]["stop"]) == (0, 8)
    plain = pd.read_parquet(chunk)
    pd.testing.assert_frame_equal(plain, reference[reference.episode < 8], check_exact=True)


def test_same_dataset_with_two_workers(reference, tmp_path):
    collect(tmp_path / "two", 24, workers=2, **RUN)
    assert_same_dataset(tmp_path / "two", reference)


def test_random_actions_depend_only_on_seed_and_episode(tmp_path):
    np.testing.assert_array_equal(interaction_action(3, 7, "random"), interaction_action(3, 7, "random"))
    assert not np.array_equal(interaction_action(3, 7, "random"), interaction_action(3, 8, "random"))
    assert interaction_action(3, 7, "random").dtype == np.float32
    collect(tmp_path / "r", 3, seed=3, action="random", env_options=SMALL, chunk_size=3, progress=False)
    frame = load_dataset(tmp_path / "r")
    for _, row in frame.iterrows():
        actions = row[["action_0", "action_1", "action_2"]].to_numpy(np.float32)
        np.testing.assert_array_equal(actions, interaction_action(3, row.episode, "random"))


def test_extending_equals_collecting_at_once(reference, tmp_path):
    out = tmp_path / "grown"
    collect(out, 20, workers=1, **RUN)  # its last chunk, 16..19, is redone as 16..23
    assert len(load_dataset(out)) + len(load_dataset(out).attrs["failures"]) == 20
    whole = {name: (out / name).stat().st_mtime_ns for name in ("chunk-00000.parquet", "chunk-00001.parquet")}
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # redoing the short last chunk is expected: no warning
        collect(out, 24, workers=1, **RUN)
    assert {name: (out / name).stat().st_mtime_ns for name in whole} == whole  # only the last chunk was redone
    assert_same_dataset(out, reference)
    with pytest.raises(DatasetError, match="not shortened"):
        collect(out, 16, workers=1, **RUN)


def test_a_dataset_labelled_before_is_not_extended_with_rows_labelled_otherwise(tmp_path):
    out = tmp_path / "d"
    collect(out, 4, seed=1, env_options=SMALL, chunk_size=4, progress=False)
    manifest = json.loads((out / "manifest.json").read_text())
    del manifest["labels_version"]  # as written before the labels' version was recorded: version 1
    (out / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(DatasetError, match="other settings.*labels_version: dataset has 1, asked for 2"):
        collect(out, 8, seed=1, env_options=SMALL, chunk_size=4, progress=False)


def test_other_settings_are_refused_naming_them(tmp_path):
    out = tmp_path / "d"
    collect(out, 4, seed=1, env_options=SMALL, chunk_size=4, progress=False)
    with pytest.raises(DatasetError, match="other settings.*seed: dataset has 1, asked for 2"):
        collect(out, 4, seed=2, env_options=SMALL, chunk_size=4, progress=False)
    with pytest.raises(DatasetError, match="camera_width: dataset has 32, asked for 160"):
        collect(out, 4, seed=1, env_options={}, chunk_size=4, progress=False)
    with pytest.raises(DatasetError, match="action: dataset has 'canonical', asked for 'random'.*chunk_size"):
        collect(out, 4, seed=1, action="random", env_options=SMALL, chunk_size=2, progress=False)
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "notes.txt").write_text("mine")
    with pytest.raises(DatasetError, match="not a TapAffordance dataset"):
        collect(tmp_path / "other", 4, env_options=SMALL, progress=False)


def test_bad_arguments_are_clear_errors(tmp_path):
    with pytest.raises(ValueError, match="episodes must be an integer >= 1"):
        collect(tmp_path / "d", 0)
    with pytest.raises(ValueError, match="unknown or unsupported env options \\['colour'\\]"):
        collect(tmp_path / "d", 2, env_options={"colour": "red"})
    with pytest.raises(ValueError, match="scheduler must be one of"):
        collect(tmp_path / "d", 2, scheduler="ray")
    with pytest.raises(ValueError, match="Unknown object type"):
        collect(tmp_path / "d", 2, env_options={**SMALL, "object_types": ["cube"]})
    with pytest.raises(ValueError, match="camera resolution"):  # checked here, before any worker starts
        collect(tmp_path / "d", 2, workers=2, env_options={**SMALL, "camera_width": 1})
    assert not (tmp_path / "d").exists()


def test_load_errors_name_the_problem(tmp_path):
    with pytest.raises(FileNotFoundError, match="No dataset"):
        load_dataset(tmp_path / "missing")
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(DatasetError, match="not a TapAffordance dataset"):
        load_dataset(tmp_path / "notes.txt")
    pd.DataFrame({"a": [1, 2]}).to_parquet(tmp_path / "foreign.parquet")
    with pytest.raises(DatasetError, match="Parquet file but not a TapAffordance dataset chunk"):
        load_dataset(tmp_path / "foreign.parquet")
    (tmp_path / "text.parquet").write_text("not parquet")
    with pytest.raises(DatasetError, match="not a Parquet file"):
        load_dataset(tmp_path / "text.parquet")
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    with pytest.raises(DatasetError, match="a directory with manifest.json"):
        load_dataset(foreign)
    (foreign / "manifest.json").write_text(json.dumps({"format": "something else"}))
    with pytest.raises(DatasetError, match="not a TapAffordance dataset"):
        load_dataset(foreign)
    (foreign / "manifest.json").write_text("{not json")
    with pytest.raises(DatasetError, match="manifest"):
        load_dataset(foreign)


def test_newer_schema_corrupt_and_half_written_chunks(reference, tmp_path):
    out = tmp_path / "d"
    collect(out, 16, workers=1, **RUN)
    chunk = out / "chunk-00001.parquet"
    good = chunk.read_bytes()
    (out / ".chunk-00002.parquet.0a1b.tmp").write_bytes(good[: len(good) // 2])  # a killed writer's leftover
    with pytest.raises(DatasetError, match="chunk-00000.parquet"):
        load_dataset(out / "chunk-00000.parquet")  # a chunk alone: load the directory
    chunk.write_bytes(good[: len(good) // 2])  # truncated under its final name (disk damage, not our writer)
    with pytest.raises(DatasetError, match="chunk-00001.parquet (is corrupt|has changed).*affordance collect"):
        load_dataset(out)
    with pytest.warns(UserWarning, match="collecting chunk-00001.parquet again"):
        collect(out, 16, workers=1, **RUN)  # redoes the damaged chunk, removes the leftover
    assert_same_dataset_prefix(out, reference, 16)
    manifest = json.loads((out / "manifest.json").read_text())
    manifest["schema_version"] = 99
    (out / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(DatasetError, match="schema version 99.*upgrade"):
        load_dataset(out)


def test_a_damaged_manifest_or_chunk_metadata_is_a_dataset_error_naming_it(tmp_path):
    out = tmp_path / "d"
    collect(out, 4, seed=1, env_options=SMALL, chunk_size=4, progress=False)
    good = (out / "manifest.json").read_text()
    for episodes in (-3, 0, True, 10**12):  # a count of nothing, or more than a chunk list can be made for
        manifest = json.loads(good)
        manifest["episodes"] = episodes
        (out / "manifest.json").write_text(json.dumps(manifest))
        with pytest.raises(DatasetError, match=rf"manifest.json is damaged: episodes {episodes!r}"):
            load_dataset(out)
    manifest = json.loads(good)
    manifest["settings"]["env_options"] = "tap"
    (out / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(DatasetError, match="manifest.json is damaged: its settings, with the env's options"):
        load_dataset(out)
    # a chunk whose metadata names a failure of no episode (its checksum recorded anew: not a changed file)
    (out / "manifest.json").write_text(good)
    chunk = out / "chunk-00000.parquet"
    table = pq.read_table(chunk)
    meta = json.loads(table.schema.metadata[b"tap_affordance"])
    meta["chunk"]["failures"] = {"abc": "ik: out of reach"}
    pq.write_table(table.replace_schema_metadata({**table.schema.metadata,
                                                  b"tap_affordance": json.dumps(meta).encode()}), chunk)
    manifest = json.loads(good)
    manifest["chunk_sha256"][chunk.name] = hashlib.sha256(chunk.read_bytes()).hexdigest()
    (out / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(DatasetError, match=r"chunk-00000.parquet is corrupt: a failure 'abc': 'ik: out of reach' is "
                                           r"not an episode of 0..3"):
        load_dataset(out)
    with pytest.raises(ValueError, match="episodes must be at most 100,000,000"):
        collect(tmp_path / "huge", 10**12, env_options=SMALL, progress=False)


def assert_same_dataset_prefix(path, reference, episodes):
    frame = load_dataset(path)
    pd.testing.assert_frame_equal(frame, reference[reference.episode < episodes], check_exact=True)
    assert not list(path.glob(".*.tmp"))


def _patch_env(monkeypatch, change):
    """Make TapAffordanceEnv.step replace the fields of its result that ``change(episode_seed)`` returns (a dict;
    it may raise)."""
    reset, step = TapAffordanceEnv.reset, TapAffordanceEnv.step

    def patched_step(self, action):
        returned = step(self, action)
        self._last = dataclasses.replace(self._last, **change(self._test_seed))
        return returned

    def remembering_reset(self, *, seed=None, options=None):
        self._test_seed = seed
        return reset(self, seed=seed, options=options)

    monkeypatch.setattr(TapAffordanceEnv, "step", patched_step)
    monkeypatch.setattr(TapAffordanceEnv, "reset", remembering_reset)


def test_interactions_the_env_marks_failed_are_reported_never_written(reference, tmp_path, monkeypatch):
    failing = {interaction_seed(5, 1), interaction_seed(5, 4)}

    def fail(seed):
        return {"failure": "tap: the hand never touched the object"} if seed in failing else {}

    _patch_env(monkeypatch, fail)
    out = tmp_path / "failing"
    collect(out, 8, workers=1, max_failure_share=0.5, **RUN)  # workers=1 runs in this process, patched
    frame = load_dataset(out)
    assert 1 not in set(frame.episode) and 4 not in set(frame.episode)
    assert frame.attrs["failures"][1] == frame.attrs["failures"][4] == "tap: the hand never touched the object"
    kept = reference[(reference.episode < 8) & ~reference.episode.isin([1, 4])].reset_index(drop=True)
    pd.testing.assert_frame_equal(frame, kept, check_exact=True)  # the other interactions are unharmed
    failures = read_manifest(out)["failures"]
    assert failures["count"] == 2 + sum(e < 8 for e in reference.attrs["failures"])
    assert failures["by_kind"]["tap"] >= 2


def test_a_bug_stops_the_collection_with_its_traceback_and_keeps_what_was_written(reference, tmp_path,
                                                                                   monkeypatch):
    def blow_up(seed):
        if seed == interaction_seed(5, 5):
            raise RuntimeError("the simulation blew up")
        return {}

    _patch_env(monkeypatch, blow_up)
    out = tmp_path / "bug"
    settings = {**RUN, "chunk_size": 2}
    with pytest.raises(RuntimeError, match="the simulation blew up"):
        collect(out, 8, workers=1, **settings)
    manifest = read_manifest(out)
    assert manifest["chunks_done"] == 2 and not manifest["complete"]  # episodes 0-3, written before the bug
    partial = load_dataset(out, allow_incomplete=True)
    assert set(partial.episode) == {0, 1, 2, 3}
    monkeypatch.undo()  # the bug is fixed: the same command finishes the dataset
    collect(out, 8, workers=1, **settings)
    pd.testing.assert_frame_equal(load_dataset(out), reference[reference.episode < 8].reset_index(drop=True),
                                  check_exact=True)


def test_non_finite_numbers_in_an_interaction_not_marked_failed_are_a_bug(tmp_path, monkeypatch):
    def poison(seed):
        return {"effect": np.full(49, np.nan, np.float32)} if seed == interaction_seed(5, 2) else {}

    _patch_env(monkeypatch, poison)
    with pytest.raises(RuntimeError, match="interaction 2 .* non-finite value"):
        collect(tmp_path / "nan", 4, workers=1, **RUN)


def test_collection_stops_above_the_failure_share_and_lists_the_reasons(tmp_path, monkeypatch):
    def fail_most(seed):
        if seed != interaction_seed(5, 0):
            return {"failure": "reach: the arm moved the object by 4.0 mm before the stroke"}
        return {}

    _patch_env(monkeypatch, fail_most)
    out = tmp_path / "unreachable"
    settings = {**RUN, "chunk_size": 2}
    with pytest.raises(FailureShareError, match=r"1 of the 2 interactions .* \(50 %\).* reach 1 \(e.g. episode 1: "
                                                 r"reach: the arm moved"):
        collect(out, 8, workers=1, **settings)
    assert (out / "chunk-00000.parquet").exists()  # what was collected is kept
    collect(out, 8, workers=1, max_failure_share=1.0, **settings)  # accepting them, the collection goes on
    assert len(load_dataset(out)) == 1
    with pytest.raises(ValueError, match="max_failure_share"):
        collect(out, 8, workers=1, max_failure_share=1.5, **settings)


def test_a_second_collection_into_the_same_directory_is_refused(tmp_path):
    fcntl = pytest.importorskip("fcntl")
    out = tmp_path / "d"
    collect(out, 2, env_options=SMALL, chunk_size=2, progress=False)
    with open(out / ".lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(DatasetError, match="another collection is writing"):
            collect(out, 4, env_options=SMALL, chunk_size=2, progress=False)


def test_saved_images_decode_to_the_observations(tmp_path):
    collect(tmp_path / "img", 3, seed=2, env_options=SMALL, chunk_size=3, progress=False, save_images=True)
    assert "image_initial_range" not in load_dataset(tmp_path / "img").columns  # images only when asked for
    frame = load_dataset(tmp_path / "img", with_images=True)
    ranges, masks = images(frame, "image_initial_range"), images(frame, "image_final_mask")
    assert ranges.shape == (len(frame), 32, 32) and masks.dtype == bool
    obs, _ = TapAffordanceEnv(**SMALL).reset(seed=interaction_seed(2, int(frame.episode[0])))
    np.testing.assert_array_equal(images(frame, "image_initial_mask")[0], obs["mask"].astype(bool))
    np.testing.assert_allclose(ranges[0], obs["range"], rtol=1e-3)  # float16 on disk
    with pytest.raises(ValueError, match="save_images"):
        images(frame.drop(columns="image_final_mask"), "image_final_mask")


def _old_column_names(version: int) -> dict[str, str]:
    """Current column name -> the name a dataset of schema ``version`` (< 5) gave it."""
    pose = {c: (f"object_{c.removeprefix('true_')}" if version == 1 else c.removeprefix("true_"))
            for c in POSE_COLUMNS}
    return {**pose, **{f"image_{s}_{k}": f"{s}_{k}" for s in ("initial", "final") for k in ("range", "mask")}}


def test_schema_version_1_datasets_are_read(reference, tmp_path):
    out = tmp_path / "v1"
    out.mkdir()
    old = reference[reference.episode < 8].rename(columns=_old_column_names(1))
    old.to_parquet(out / "chunk-00000.parquet")
    manifest = {**reference.attrs["manifest"], "schema_version": 1, "episodes": 8}
    del manifest["chunk_sha256"]
    (out / "manifest.json").write_text(json.dumps(manifest))
    frame = load_dataset(out)
    assert "object_initial_x" in old.columns and "true_initial_x" in frame.columns
    pd.testing.assert_frame_equal(frame, reference[reference.episode < 8], check_exact=True)
    with pytest.raises(DatasetError, match="schema_version: dataset has 1"):
        collect(out, 8, workers=1, **RUN)


def _as_old_version(source, out, version: int, dropped: list[str]) -> None:
    """Rewrite the dataset ``source`` into ``out`` as the writer of schema ``version`` (2 to 4) wrote it: its
    column names, no checksums, and without the columns ``dropped``."""
    out.mkdir()
    manifest = {**json.loads((source / "manifest.json").read_text()), "schema_version": version}
    del manifest["chunk_sha256"]
    names = _old_column_names(version)
    for chunk_file in sorted(source.glob("chunk-*.parquet")):
        chunk = pq.read_table(chunk_file)
        meta = json.loads(chunk.schema.metadata[b"tap_affordance"])
        meta["schema_version"] = version
        chunk = chunk.drop_columns(dropped)
        chunk = chunk.rename_columns([names.get(c, c) for c in chunk.column_names])
        chunk = chunk.replace_schema_metadata({b"tap_affordance": json.dumps(meta)})
        pq.write_table(chunk, out / chunk_file.name)
    (out / "manifest.json").write_text(json.dumps(manifest))


def test_schema_version_2_datasets_are_read(reference, reference_dir, tmp_path):
    # Version 2 had no rolling_distance, tilt, toppled, outcome_time or success columns; success is derived.
    added = ["rolling_distance", "tilt", "toppled", "outcome_time"]
    _as_old_version(reference_dir, tmp_path / "v2", 2, [*added, "success"])
    assert "initial_x" in pq.read_schema(tmp_path / "v2" / "chunk-00000.parquet").names
    frame = load_dataset(tmp_path / "v2")
    assert len(frame) == len(reference) and not set(added) & set(frame.columns)
    pd.testing.assert_frame_equal(frame, reference.drop(columns=added), check_exact=True)


def test_schema_version_3_datasets_get_the_success_label_derived(tmp_path):
    # Version 3 stored no success column: it is derived by the env's rule, here push's (displacement beyond
    # roll_threshold), and equals what a current dataset stores. Extending such a dataset is refused.
    run = {**RUN, "env_options": {**SMALL, "behavior": "push"}}
    collect(tmp_path / "v5", 8, workers=1, **run)
    stored = load_dataset(tmp_path / "v5")
    assert stored.success.dtype == bool and stored.success.any() and not stored.success.all()
    assert (stored.success == (stored.displacement > 0.03)).all()
    _as_old_version(tmp_path / "v5", tmp_path / "v3", 3, ["success"])
    derived = load_dataset(tmp_path / "v3")
    assert derived.attrs["manifest"]["schema_version"] == 3
    pd.testing.assert_frame_equal(derived, stored, check_exact=True)
    with pytest.raises(DatasetError, match="schema_version: dataset has 3"):
        collect(tmp_path / "v3", 8, workers=1, **run)


def test_schema_version_4_datasets_load_with_the_new_names_images_too(tmp_path):
    collect(tmp_path / "v5", 3, seed=2, env_options=SMALL, chunk_size=3, progress=False, save_images=True)
    _as_old_version(tmp_path / "v5", tmp_path / "v4", 4, [])
    assert {"initial_x", "initial_range"} <= set(pq.read_schema(tmp_path / "v4" / "chunk-00000.parquet").names)
    old, new = (load_dataset(tmp_path / v, with_images=True) for v in ("v4", "v5"))
    pd.testing.assert_frame_equal(old, new, check_exact=True)
    np.testing.assert_array_equal(images(old, "image_final_mask"), images(new, "image_final_mask"))
    assert "image_initial_range" not in load_dataset(tmp_path / "v4").columns
    with pytest.raises(ValueError, match="'initial_range' is named 'image_initial_range' now"):
        images(old, "initial_range")


def test_progress_bar_only_on_a_terminal_and_not_in_ci(monkeypatch):
    monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
    monkeypatch.delenv("CI", raising=False)
    assert show_progress(None)
    monkeypatch.setenv("CI", "true")
    assert not show_progress(None) and show_progress(True)
    monkeypatch.setattr(sys.stderr, "isatty", lambda: False)
    monkeypatch.delenv("CI")
    assert not show_progress(None)


def test_collect_command(reference, tmp_path, capsys):
    from affordance_env.collect_cli import add_collect_parser

    parser = argparse.ArgumentParser(prog="affordance")
    add_collect_parser(parser.add_subparsers(dest="command", required=True))
    out = tmp_path / "cli"
    argv = ["collect", "--episodes", "8", "--out", str(out), "--seed", "5", "--chunk-size", "8",
            "--camera-width", "32", "--camera-height", "32"]
    args = parser.parse_args(argv)
    assert args.func(args) == 0
    assert f"{len(reference[reference.episode < 8])} interactions written" in capsys.readouterr().out
    assert_same_dataset_prefix(out, reference, 8)
    args = parser.parse_args([*argv, "--behavior", "push", "--camera-fovy", "40"])
    with pytest.raises(DatasetError, match="behavior: dataset has 'tap', asked for 'push'; camera_fovy"):
        args.func(args)
    args = parser.parse_args([*argv, "--scheduler", "joblib", "--dask-address", "tcp://x:1"])
    with pytest.raises(ValueError, match="--dask-address"):
        args.func(args)


def descendants(pid: int) -> list[int]:
    """Processes started by ``pid``, and by those, ... (Linux /proc)."""
    children: dict[int, list[int]] = {}
    for entry in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{entry}/stat") as stat:
                ppid = int(stat.read().rsplit(")", 1)[1].split()[1])
        except (OSError, ValueError, IndexError):
            continue
        children.setdefault(ppid, []).append(int(entry))
    found, stack = [], list(children.get(pid, []))
    while stack:
        found.append(stack.pop())
        stack.extend(children.get(found[-1], []))
    return found


@pytest.mark.slow
def test_kill_minus_nine_then_resume_equals_uninterrupted(reference, tmp_path):
    out = tmp_path / "killed"
    code = (
        "from affordance_env.dataset import collect\n"
        f"collect({str(out)!r}, 24, workers=2, chunk_size=2, seed=5, env_options={SMALL!r}, progress=False)\n"
    )
    process = subprocess.Popen([sys.executable, "-c", code])
    def recorded() -> int:  # chunks the manifest records as finished (a chunk file lands just before that)
        try:
            return len(json.loads((out / "manifest.json").read_text()).get("chunk_sha256", {}))
        except (OSError, ValueError):
            return 0

    deadline = time.time() + 60
    while time.time() < deadline and recorded() < 1:
        time.sleep(0.02)
    workers = descendants(process.pid)
    os.kill(process.pid, signal.SIGKILL)  # the coordinator: its workers go on with the chunks they hold ...
    process.wait()
    time.sleep(0.3)
    for pid in workers:  # ... until they die too, perhaps in the middle of writing one
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, signal.SIGKILL)
    written = len(list(out.glob("chunk-*.parquet")))
    assert 1 <= written < 12, "kill -9 should land in the middle of the collection"
    with pytest.raises(DatasetError, match="incomplete"):
        load_dataset(out)
    assert 0 < len(load_dataset(out, allow_incomplete=True)) < 24
    collect(out, 24, workers=1, chunk_size=2, seed=5, env_options=SMALL, progress=False)
    pd.testing.assert_frame_equal(load_dataset(out), reference, check_exact=True)
    assert not list(out.glob(".*.tmp"))


@pytest.mark.slow
def test_a_local_dask_cluster_collects_the_same_dataset(reference, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        collect(tmp_path / "dask", 24, dask_address=cluster.scheduler_address, **RUN)
    assert_same_dataset(tmp_path / "dask", reference)
    collect(tmp_path / "local-dask", 24, scheduler="dask", workers=2, **RUN)  # a cluster of its own
    assert_same_dataset(tmp_path / "local-dask", reference)


def test_without_a_terminal_progress_is_a_plain_line_every_10_s(tmp_path, monkeypatch, capsys):
    import affordance_env.progress as progress

    monkeypatch.setattr(sys.stderr, "isatty", lambda: False)
    monkeypatch.setattr(progress, "LOG_INTERVAL", 0.0)  # every update, to see the lines
    collect(tmp_path / "d", 4, **{**RUN, "chunk_size": 2, "progress": None})
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) >= 3 and "\r" not in "".join(lines)  # the start, each chunk, the end
    assert lines[-1].startswith("d: 100%") and "4/4" in lines[-1]
    collect(tmp_path / "e", 2, **{**RUN, "chunk_size": 2, "progress": False})
    assert capsys.readouterr().err == ""


def test_worker_processes_are_at_most_the_chunks_and_the_cores(tmp_path, monkeypatch, capsys):
    # --workers 1000 for one chunk once started 850 processes: now one per chunk to collect at most, and one per
    # core unless asked for more (oversubscribe), the cap said in one line on stderr.
    import importlib

    module = importlib.import_module("affordance_env.dataset.collect")
    started = []
    monkeypatch.setattr(module, "_run", lambda tasks, scheduler, workers, client: started.append(
        (scheduler, workers)) or iter(()))
    monkeypatch.setattr(module, "_dask_client", lambda scheduler, address: contextlib.nullcontext())  # no cluster
    monkeypatch.setattr(module.os, "cpu_count", lambda: 4)
    collect(tmp_path / "one", 4, workers=1000, progress=False)  # one chunk
    assert started.pop() == ("joblib", 1) and capsys.readouterr().err == ""
    collect(tmp_path / "three", 6, workers=3, chunk_size=2, progress=False)  # within the cores: as asked
    assert started.pop() == ("joblib", 3) and capsys.readouterr().err == ""
    collect(tmp_path / "many", 40, workers=1000, chunk_size=2, progress=False)  # 20 chunks, 4 cores
    assert started.pop() == ("joblib", 4)
    note = capsys.readouterr().err
    assert note.count("\n") == 1 and "4 cores" in note and "oversubscribe" in note
    collect(tmp_path / "over", 40, workers=1000, chunk_size=2, progress=False, oversubscribe=True)
    assert started.pop() == ("joblib", 20) and capsys.readouterr().err == ""
    collect(tmp_path / "dask", 40, workers=1000, chunk_size=2, progress=False, scheduler="dask")  # local cluster
    assert started.pop() == ("dask", 4)
    collect(tmp_path / "remote", 40, workers=1000, chunk_size=2, progress=False, dask_address="tcp://h:8786")
    assert started.pop() == ("dask", 1000)  # another machine's cluster: its workers are its own


@pytest.mark.parametrize("address", ["127.0.0.1", "notanaddress", "tcp://host", "http://host:8786", 8786])
def test_a_malformed_dask_address_is_refused_before_anything_is_written(address, tmp_path):
    with pytest.raises(ValueError, match="PROTOCOL://HOST:PORT"):
        collect(tmp_path / "d", 2, dask_address=address, progress=False)
    assert not (tmp_path / "d").exists()
