"""Datasets: deterministic whatever the workers, resumable after kill -9, and clear errors."""

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest

from affordance_env import load_dataset
from affordance_env.dataset import DatasetError, collect

SMALL = {"camera_width": 32, "camera_height": 32}


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("data") / "reference"
    collect(out, 24, seed=5, workers=1, env_options=SMALL, chunk_size=8, progress=False)
    return load_dataset(out)


def test_schema(reference):
    from affordance_env import FEATURE_NAMES

    assert len(reference) + len(reference.attrs["failures"]) == 24
    for column in ("episode", "seed", "action_0", "type", "size", "displacement", "rolled", "outcome", "contact",
                   "object_initial_x", "object_final_qz", "behavior"):
        assert column in reference.columns
    for name in FEATURE_NAMES:
        assert {f"initial_{name}", f"final_{name}", f"effect_{name}"} <= set(reference.columns)
    manifest = reference.attrs["manifest"]
    assert manifest["feature_names"] == list(FEATURE_NAMES) and manifest["schema_version"] == 1
    assert manifest["settings"]["env_options"]["camera_width"] == 32
    assert reference["episode"].is_monotonic_increasing
    assert not reference.drop(columns=["type", "outcome", "behavior"]).isna().any().any()


def test_same_dataset_with_two_workers(reference, tmp_path):
    collect(tmp_path / "two", 24, seed=5, workers=2, env_options=SMALL, chunk_size=8, progress=False)
    pd.testing.assert_frame_equal(load_dataset(tmp_path / "two"), reference)


def test_parquet_opens_with_plain_pandas(reference, tmp_path):
    collect(tmp_path / "d", 8, seed=5, workers=1, env_options=SMALL, chunk_size=8, progress=False)
    frame = pd.read_parquet(tmp_path / "d" / "chunk-00000.parquet")
    assert len(frame) == len(reference[reference.episode < 8])


def test_other_settings_are_refused(tmp_path):
    collect(tmp_path / "d", 4, seed=1, workers=1, env_options=SMALL, chunk_size=4, progress=False)
    with pytest.raises(DatasetError, match="seed: dataset has 1, asked for 2"):
        collect(tmp_path / "d", 4, seed=2, workers=1, env_options=SMALL, chunk_size=4, progress=False)
    with pytest.raises(DatasetError, match="camera_width"):
        collect(tmp_path / "d", 4, seed=1, workers=1, env_options={"camera_width": 40}, chunk_size=4,
                progress=False)


def test_load_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="No dataset"):
        load_dataset(tmp_path / "missing")
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(DatasetError, match="not a TapAffordance dataset"):
        load_dataset(tmp_path / "notes.txt")
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "manifest.json").write_text(json.dumps({"format": "something else"}))
    with pytest.raises(DatasetError, match="not a TapAffordance dataset"):
        load_dataset(foreign)
    (foreign / "manifest.json").write_text("{not json")
    with pytest.raises(DatasetError, match="manifest"):
        load_dataset(foreign)


def test_newer_schema_and_corrupt_chunk(tmp_path):
    out = tmp_path / "d"
    collect(out, 4, seed=1, workers=1, env_options=SMALL, chunk_size=4, progress=False)
    manifest = json.loads((out / "manifest.json").read_text())
    (out / "chunk-00000.parquet").write_bytes(b"PAR1 garbage")
    with pytest.raises(DatasetError, match="corrupt"):
        load_dataset(out)
    manifest["schema_version"] = 99
    (out / "manifest.json").write_text(json.dumps(manifest))
    with pytest.raises(DatasetError, match="schema version 99"):
        load_dataset(out)


@pytest.mark.slow
def test_kill_minus_nine_then_resume_equals_uninterrupted(reference, tmp_path):
    out = tmp_path / "killed"
    code = (
        "from affordance_env.dataset import collect\n"
        f"collect({str(out)!r}, 24, seed=5, workers=1, env_options={SMALL!r}, chunk_size=8, progress=False)\n"
    )
    process = subprocess.Popen([sys.executable, "-c", code])
    deadline = time.time() + 60
    while time.time() < deadline and not (out / "chunk-00000.parquet").exists():
        time.sleep(0.05)
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    assert (out / "chunk-00000.parquet").exists()
    with pytest.raises(DatasetError, match="incomplete"):
        load_dataset(out)
    collect(out, 24, seed=5, workers=2, env_options=SMALL, chunk_size=8, progress=False)
    pd.testing.assert_frame_equal(load_dataset(out), reference)
    assert not list(out.glob(".*.tmp"))


@pytest.mark.slow
def test_a_local_dask_cluster_collects_the_same_dataset(reference, tmp_path):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        collect(tmp_path / "dask", 24, seed=5, env_options=SMALL, chunk_size=8, progress=False,
                dask_address=cluster.scheduler_address)
    pd.testing.assert_frame_equal(load_dataset(tmp_path / "dask"), reference)


def test_saved_images_decode_to_the_observations(tmp_path):
    from affordance_env.dataset import images, interaction_seed
    from affordance_env.tap_env import TapAffordanceEnv

    collect(tmp_path / "img", 3, seed=2, env_options=SMALL, chunk_size=3, progress=False, save_images=True)
    frame = load_dataset(tmp_path / "img")
    ranges, masks = images(frame, "initial_range"), images(frame, "initial_mask")
    assert ranges.shape == (len(frame), 32, 32) and masks.dtype == bool
    obs, _ = TapAffordanceEnv(**SMALL).reset(seed=interaction_seed(2, int(frame.episode[0])))
    np.testing.assert_array_equal(masks[0], obs["mask"].astype(bool))
    np.testing.assert_allclose(ranges[0], obs["range"], rtol=1e-3)  # float16 on disk
    with pytest.raises(ValueError, match="save_images"):
        images(load_dataset(tmp_path / "img").drop(columns="final_mask"), "final_mask")
