"""Export a collected dataset as a Minari dataset (Farama's standard for offline datasets beside Gymnasium).

The Parquet dataset stays the source of truth; :func:`export_minari` writes a copy that Minari users load with
``minari.load_dataset(dataset_id)``. One episode per interaction, of one step:

- episodes: the valid interactions in order, numbered 0..n-1 (failed ones are left out), each with its seed.
- observations: a ``Dict`` of ``features`` (49,) float32, and ``range`` (H, W) float32 and ``mask`` (H, W)
  int8 when the dataset saved its images (``save_images``); two of each, before and after the interaction.
  The environment's ``joints`` observation is not stored in datasets, so it is not in the export.
- action (3,) float32; reward: the object's displacement [m] (the environment's default reward); terminated
  True, truncated False.
- the environment spec: ``TapAffordance-v0`` with the dataset's settings, so that
  ``dataset.recover_environment()`` makes the environment the data came from.

Minari stores datasets where its own convention says (``MINARI_DATASETS_PATH``, by default
``~/.minari/datasets``), in its Arrow format by default (``pip install "tap-affordance[minari]"``).
"""

from __future__ import annotations

import dataclasses
import os
from pathlib import Path
from typing import Any

import numpy as np

from affordance_env.dataset.load import images, load_dataset
from affordance_env.features import FEATURE_NAMES

#: Data formats Minari writes.
DATA_FORMATS = ("arrow", "hdf5")


def _minari():
    try:
        import minari
        from minari.data_collector import EpisodeBuffer
    except ImportError as exc:
        raise ImportError(
            "exporting to Minari needs the minari package: pip install 'tap-affordance[minari]'"
        ) from exc
    return minari, EpisodeBuffer


def observation_space(env_options: dict[str, Any], with_images: bool):
    """The exported observation space: ``features``, and ``range`` and ``mask`` if the images were saved."""
    from gymnasium import spaces

    spaces_ = {"features": spaces.Box(-np.inf, np.inf, (len(FEATURE_NAMES),), np.float32)}
    if with_images:
        shape = (int(env_options["camera_height"]), int(env_options["camera_width"]))
        spaces_["range"] = spaces.Box(0.0, np.inf, shape, np.float32)
        spaces_["mask"] = spaces.Box(0, 1, shape, np.int8)
    return spaces.Dict(spaces_)


def export_minari(dataset: str | os.PathLike, dataset_id: str, *, data_format: str = "arrow",
                  description: str | None = None, author: str = "tap-affordance", author_email: str | None = None):
    """Write the collected dataset at ``dataset`` as the Minari dataset ``dataset_id``.

    Args:
        dataset: Directory of a dataset made by :func:`affordance_env.dataset.collect` (complete).
        dataset_id: Minari's id, ``(namespace/)(env_name/)dataset_name-v(version)``, e.g.
            ``"tap-affordance/canonical-taps-v0"``.
        data_format: ``"arrow"`` (default) or ``"hdf5"`` (needs h5py).
        description, author, author_email: Recorded in the Minari metadata (Minari warns without an email).

    Returns:
        The ``minari.MinariDataset``.

    Raises:
        ImportError: minari is not installed (the message says how to install it).
        ValueError: an unknown data format, or a Minari dataset with that id exists already.
        DatasetError: ``dataset`` is not a complete dataset.
    """
    if data_format not in DATA_FORMATS:
        raise ValueError(f"data_format must be one of {DATA_FORMATS}, got {data_format!r}.")
    minari, EpisodeBuffer = _minari()
    if dataset_id in minari.list_local_datasets():
        raise ValueError(f"a Minari dataset {dataset_id!r} exists already; delete it with "
                         f"`minari delete {dataset_id}` or choose another id.")
    frame = load_dataset(dataset, with_images=True)
    manifest = frame.attrs["manifest"]
    options = manifest["settings"]["env_options"]
    with_images = bool(manifest["settings"].get("save_images"))
    stages = {stage: frame[[f"{stage}_{n}" for n in FEATURE_NAMES]].to_numpy(np.float32)
              for stage in ("initial", "final")}
    if with_images:
        decoded = {f"{stage}_{kind}": images(frame, f"image_{stage}_{kind}")
                   for stage in ("initial", "final") for kind in ("range", "mask")}
    actions = frame[[f"action_{j}" for j in range(3)]].to_numpy(np.float32)
    rewards = frame["displacement"].to_numpy(np.float64)
    buffers = []
    for i, seed in enumerate(frame["seed"]):
        observations = {"features": np.stack([stages["initial"][i], stages["final"][i]])}
        if with_images:
            observations["range"] = np.stack([decoded["initial_range"][i], decoded["final_range"][i]])
            observations["mask"] = np.stack([decoded["initial_mask"][i], decoded["final_mask"][i]]).astype(np.int8)
        # Minari numbers episodes 0..n-1 (it counts them from the largest id); the valid interactions are
        # renumbered in order, each keeps its seed.
        buffers.append(EpisodeBuffer(id=i, seed=int(seed), observations=observations,
                                     actions=actions[i : i + 1], rewards=[float(rewards[i])], terminations=[True],
                                     truncations=[False]))
    import gymnasium as gym

    from affordance_env.registration import ENV_ID, register_envs

    register_envs()
    spec = dataclasses.replace(gym.spec(ENV_ID), kwargs=dict(options))
    from gymnasium import spaces

    return minari.create_dataset_from_buffers(
        dataset_id=dataset_id,
        buffer=buffers,
        env=spec,
        eval_env=spec,
        observation_space=observation_space(options, with_images),
        action_space=spaces.Box(-1.0, 1.0, (3,), np.float32),
        algorithm_name=f"TapAffordance collect ({manifest['settings']['action']} actions)",
        author=author,
        author_email=author_email,
        description=description or f"TapAffordance interactions exported from {Path(dataset).resolve()}.",
        data_format=data_format,
        jpeg_encoding=False,
        requirements=[f"tap-affordance=={manifest['package_version']}"],
    )
