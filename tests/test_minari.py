"""Minari export: every episode equals its Parquet row, the env comes back with its settings, clear errors,
and a failed export leaves nothing behind."""

import sys
import warnings

import numpy as np
import pytest

from affordance_env import FEATURE_NAMES, load_dataset
from affordance_env.dataset import collect, images
from affordance_env.dataset.minari_export import export_minari
from affordance_env.tap_env import TapAffordanceEnv
from affordance_learning.cli import main


@pytest.fixture(scope="module")
def taps(tmp_path_factory):
    out = tmp_path_factory.mktemp("minari-src") / "taps"
    collect(out, 6, seed=3, action="random", save_images=True, progress=False,
            env_options={"camera_width": 40, "camera_height": 30, "size_range": (0.05, 0.08)})
    return out


@pytest.fixture
def minari_home(tmp_path, monkeypatch):
    pytest.importorskip("minari")
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path / "minari"))
    return tmp_path / "minari"


def test_every_episode_equals_its_row(taps, minari_home):
    import minari

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no reminders from Minari about what was deliberately left out
        exported = export_minari(taps, "tap-affordance/test-taps-v0")
    assert (minari_home / "tap-affordance" / "test-taps-v0").is_dir()  # Minari's own location convention
    dataset = minari.load_dataset("tap-affordance/test-taps-v0")
    frame = load_dataset(taps, with_images=True)
    assert dataset.total_episodes == exported.total_episodes == len(frame)
    initial = frame[[f"initial_{n}" for n in FEATURE_NAMES]].to_numpy(np.float32)
    final = frame[[f"final_{n}" for n in FEATURE_NAMES]].to_numpy(np.float32)
    ranges = {s: images(frame, f"image_{s}_range") for s in ("initial", "final")}
    masks = {s: images(frame, f"image_{s}_mask") for s in ("initial", "final")}
    for i, episode in enumerate(dataset.iterate_episodes()):
        np.testing.assert_array_equal(episode.observations["features"], np.stack([initial[i], final[i]]))
        np.testing.assert_array_equal(episode.observations["range"], np.stack([ranges["initial"][i],
                                                                               ranges["final"][i]]))
        np.testing.assert_array_equal(episode.observations["mask"], np.stack([masks["initial"][i],
                                                                              masks["final"][i]]).astype(np.int8))
        np.testing.assert_array_equal(episode.actions[0], frame.loc[i, ["action_0", "action_1", "action_2"]]
                                      .to_numpy(np.float32))
        assert episode.rewards[0] == pytest.approx(frame.loc[i, "displacement"])
        assert episode.terminations.tolist() == [True] and episode.truncations.tolist() == [False]
        row = frame.loc[i]  # the labels, the same for both observations of the one-step episode
        for column in ("episode", "type", "size", "success", "rolled", "displacement", "outcome", "visible_final"):
            assert episode.infos[column].tolist() == [row[column]] * 2, column
        np.testing.assert_array_equal(episode.infos["true_final_pose"][1],
                                      row[[f"true_final_{f}" for f in ("x", "y", "z", "qw", "qx", "qy", "qz")]]
                                      .to_numpy(np.float64))
    env = dataset.recover_environment()
    assert isinstance(env.unwrapped, TapAffordanceEnv)
    assert env.unwrapped.camera.intrinsics.width == 40 and env.unwrapped.options.size_range == (0.05, 0.08)
    # the dataset's observation space is the environment's, without the joints a dataset does not store
    assert set(env.observation_space.spaces) - set(dataset.observation_space.spaces) == {"joints"}
    for key, space in dataset.observation_space.spaces.items():
        assert space == env.observation_space[key], key
    env.close()
    with pytest.raises(ValueError, match="exists already"):
        export_minari(taps, "tap-affordance/test-taps-v0")


def test_export_command(taps, minari_home, capsys):
    assert main(["export", str(taps), "--minari", "tap-affordance/cli-taps-v0"]) == 0
    assert f"{len(load_dataset(taps))} episodes" in capsys.readouterr().out


def test_without_minari_a_clear_error(taps, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "minari", None)  # as if it were not installed
    with pytest.raises(ImportError, match=r"pip install 'tap-affordance\[minari\]'"):
        export_minari(taps, "tap-affordance/none-v0")
    assert main(["export", str(taps), "--minari", "tap-affordance/none-v0"]) == 2
    assert "tap-affordance[minari]" in capsys.readouterr().err


def test_the_hdf5_format_without_h5py_is_a_clear_error(taps, minari_home, monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "h5py", None)  # as if it were not installed
    with pytest.raises(ImportError, match=r"hdf5 format needs the h5py package: pip install 'minari\[hdf5\]'"):
        export_minari(taps, "tap-affordance/h5-v0", data_format="hdf5")
    assert main(["export", str(taps), "--minari", "tap-affordance/h5-v0", "--data-format", "hdf5"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "minari[hdf5]" in err
    assert not (minari_home / "tap-affordance" / "h5-v0").exists()


@pytest.mark.parametrize("bad_id", ["tap-affordance/canonical-taps", "taps-vX", "", "a//b-v0"])
def test_a_malformed_id_is_refused_before_anything_is_written(taps, minari_home, capsys, bad_id):
    import minari

    assert main(["export", str(taps), "--minari", bad_id]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"Minari dataset id {bad_id!r} is malformed: expected (namespace/)name-v" in err
    assert not any(minari_home.iterdir()) if minari_home.exists() else True
    assert minari.list_local_datasets() == {}
    assert main(["export", str(taps), "--minari", "tap-affordance/after-v0"]) == 0  # later exports still work


def test_a_failed_export_leaves_nothing_and_a_retry_works(taps, minari_home, monkeypatch):
    import minari
    from minari.dataset._storages import get_minari_storage

    def full_disk(self, episodes):  # the write fails midway, after Minari has made the dataset's directories
        raise OSError(28, "No space left on device")

    with monkeypatch.context() as patch:
        patch.setattr(get_minari_storage("arrow"), "update_episodes", full_disk)
        with pytest.raises(OSError, match="No space left"):
            export_minari(taps, "tap-affordance/retry-v0")
    assert minari.list_local_datasets() == {}
    assert [p.name for p in minari_home.rglob("*")] == []  # no half dataset, no staging directory
    assert export_minari(taps, "tap-affordance/retry-v0").total_episodes == len(load_dataset(taps))


def test_an_incomplete_dataset_is_refused_with_the_command_that_finishes_it(taps, minari_home, tmp_path, capsys):
    # the refusal once said "or pass allow_incomplete=True", which neither the export nor its command takes
    import shutil

    from affordance_env.dataset import DatasetError

    partial = tmp_path / "partial"
    shutil.copytree(taps, partial)
    (partial / "chunk-00000.parquet").unlink()
    finish = f"finish it with `affordance collect --out {partial} --episodes 6 --seed 3"
    with pytest.raises(DatasetError, match="incomplete") as refused:
        export_minari(partial, "tap-affordance/partial-v0")
    assert finish in str(refused.value) and "before exporting it" in str(refused.value)
    assert "allow_incomplete" not in str(refused.value)
    assert main(["export", str(partial), "--minari", "tap-affordance/partial-v0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and finish in err and "allow_incomplete" not in err, err
    assert not minari_home.exists() or not any(minari_home.rglob("*.json"))
