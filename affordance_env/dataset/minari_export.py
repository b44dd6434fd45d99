"""Export a collected dataset as a Minari dataset (Farama's standard for offline datasets beside Gymnasium).

The Parquet dataset stays the source of truth; :func:`export_minari` writes a copy that Minari users load with
``minari.load_dataset(dataset_id)``. One episode per interaction, of one step:

- episodes: the valid interactions in order, numbered 0..n-1 (failed ones are left out), each with its seed.
- observations: the environment's ``Dict`` observation, before and after the interaction, with the keys a
  dataset stores: ``features`` (49,) float32, and ``range`` (H, W) float32 and ``mask`` (H, W) int8 when the
  dataset saved its images (``save_images``). Each key has the environment's own space, so the dataset's
  observation space is that of ``recover_environment()`` without the keys of :func:`left_out`: ``joints`` (a
  dataset does not store the robot's joint positions) and, without saved images, ``range`` and ``mask``.
- infos: the interaction's ground truth, the labels a learner is evaluated against (never an input): the
  dataset's ``episode``, ``type``, ``size`` [m], ``success``, ``rolled``, ``displacement`` [m], ``outcome``, ...
  (every column of :data:`~affordance_env.dataset.format.GROUND_TRUTH_COLUMNS` the dataset has), and
  ``true_initial_pose`` and ``true_final_pose`` (x, y, z [m], qw, qx, qy, qz). An episode is one interaction,
  so both entries of each info (Minari keeps one per observation) hold the same labels.
- action (3,) float32; reward: the object's displacement [m] (the environment's default reward); terminated
  True, truncated False.
- the environment spec: ``TapAffordance-v2`` with the dataset's settings, so that
  ``dataset.recover_environment()`` makes the environment the data came from.

The id is checked before anything is written, and the dataset is written to a hidden directory beside Minari's
datasets and moved into place only when complete: an export that fails leaves nothing behind. Minari stores
datasets where its own convention says (``MINARI_DATASETS_PATH``, by default ``~/.minari/datasets``), in its
Arrow format by default (``pip install "tap-affordance[minari]"``).
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import tempfile
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from affordance_env.dataset.format import GROUND_TRUTH_COLUMNS, POSE_FIELDS, STAGES, DatasetError, is_goal_dataset
from affordance_env.dataset.load import check_complete, images, load_dataset
from affordance_env.exceptions import InvalidValueError, MissingDependencyError
from affordance_env.features import FEATURE_NAMES

#: Data formats Minari writes.
DATA_FORMATS = ("arrow", "hdf5")
#: The form of a Minari dataset id that this export accepts (Minari's own, with the version required).
ID_FORM = ("(namespace/)name-v(version), e.g. tap-affordance/canonical-taps-v0: an optional namespace of at least "
           "2 characters, then a name, each of letters, digits, '_' and '-' (a namespace may have '/' between its "
           "parts), then -v and the version's digits")
#: Minari's rules for the parts of an id (``minari.dataset.minari_dataset.DATASET_ID_RE``): the namespace, before
#: the last "/", at least 2 characters, neither first nor last a "/"; the name; the version, "-v" and digits.
_NAMESPACE_RE = re.compile(r"[-_\w][-_\w/]*[-_\w]+")
_PART_CHARACTER_RE = re.compile(r"[-_\w]")
_VERSIONED_RE = re.compile(r"(?P<name>.*)-v(?P<version>\d+)", re.DOTALL)


def _minari():
    try:
        import minari
        from minari.data_collector import EpisodeBuffer
    except ImportError as exc:
        raise MissingDependencyError(
            "exporting to Minari needs the minari package: pip install 'tap-affordance[minari]'"
        ) from exc
    return minari, EpisodeBuffer


def _not_allowed(part: str, also: str = "") -> str:
    """The characters of ``part`` that Minari does not allow in it (besides those of ``also``), quoted."""
    found = dict.fromkeys(c for c in part if c not in also and not _PART_CHARACTER_RE.fullmatch(c))
    return ", ".join(repr(c) for c in found)


def dataset_id_problem(dataset_id: object) -> str | None:
    """What makes ``dataset_id`` other than a Minari dataset id with a version, naming the part it is in, for a
    person; None for an id of that form (Minari's rule, which this follows part by part, is the authority:
    :func:`check_dataset_id`)."""
    if not isinstance(dataset_id, str):
        return f"it is a {type(dataset_id).__name__}, not a string"
    if not dataset_id:
        return "it is empty"
    namespace, slash, rest = dataset_id.rpartition("/")
    if slash:
        if not namespace:
            return "it starts with '/', with no namespace before it"
        if bad := _not_allowed(namespace, also="/"):
            return f"its namespace {namespace!r} has {bad}, which it may not"
        if namespace.startswith("/"):
            return f"its namespace {namespace!r} starts with '/'"
        if namespace.endswith("/"):
            return "'//' before the name: a single '/' separates the namespace from the name"
        if not _NAMESPACE_RE.fullmatch(namespace):  # what remains: a single character
            return f"its namespace {namespace!r} is a single character, Minari's have at least 2"
    if not rest:
        return "nothing follows the last '/': the name and the version are missing"
    versioned = _VERSIONED_RE.fullmatch(rest)
    if versioned is None:
        return f"{rest!r} does not end in a version, -v and digits (e.g. -v0)"
    name = versioned["name"]
    if not name:
        return f"it has no name before -v{versioned['version']}"
    if bad := _not_allowed(name):
        return f"its name {name!r} has {bad}, which it may not"
    return None


def check_dataset_id_form(dataset_id: str) -> None:
    """ValueError naming ``dataset_id``, the form expected and what breaks it, unless it is a Minari dataset id
    with a version; Minari need not be installed."""
    problem = dataset_id_problem(dataset_id)
    if problem is not None:
        raise InvalidValueError(f"Minari dataset id {dataset_id!r} is malformed: expected {ID_FORM}; {problem}.")


def check_dataset_id(dataset_id: str) -> tuple[str | None, str, int]:
    """``(namespace, name, version)`` of a Minari dataset id; ValueError naming it, the expected form and what
    breaks it when it is malformed or has no version (Minari itself would fail midway, after creating
    directories)."""
    from minari.dataset.minari_dataset import DATASET_ID_RE, parse_dataset_id

    check_dataset_id_form(dataset_id)
    match = DATASET_ID_RE.fullmatch(dataset_id)
    if match is None or match.group("version") is None:  # the installed Minari has rules of its own
        raise InvalidValueError(f"Minari dataset id {dataset_id!r} is malformed: expected {ID_FORM}; the installed "
                         "Minari refuses it.")
    return parse_dataset_id(dataset_id)


def left_out(with_images: bool) -> dict[str, str]:
    """The environment's observation keys that the export leaves out, and why."""
    why = {"joints": "a dataset does not store the robot's joint positions"}
    if not with_images:
        why.update({key: "the dataset was collected without save_images" for key in ("range", "mask")})
    return why


def observation_space(env_space, with_images: bool):
    """The exported observation space: the environment's ``Dict`` without the keys of :func:`left_out`."""
    from gymnasium import spaces

    dropped = left_out(with_images)
    return spaces.Dict({key: space for key, space in env_space.spaces.items() if key not in dropped})


@contextlib.contextmanager
def _minari_root(path: Path) -> Iterator[None]:
    """Make Minari read and write its datasets under ``path`` for the duration (it reads the variable on
    every call)."""
    saved = os.environ.get("MINARI_DATASETS_PATH")
    os.environ["MINARI_DATASETS_PATH"] = str(path)
    try:
        yield
    finally:
        if saved is None:
            del os.environ["MINARI_DATASETS_PATH"]
        else:
            os.environ["MINARI_DATASETS_PATH"] = saved


def _infos(frame, i: int) -> dict[str, Any]:
    row = frame.iloc[i]
    infos: dict[str, Any] = {"episode": [int(row["episode"])] * 2}
    for column in GROUND_TRUTH_COLUMNS:
        if column in frame.columns:
            value = row[column].item() if hasattr(row[column], "item") else row[column]
            infos[column] = [value, value]
    for stage in STAGES:
        pose = row[[f"true_{stage}_{f}" for f in POSE_FIELDS]].to_numpy(np.float64)
        infos[f"true_{stage}_pose"] = np.stack([pose, pose])
    return infos


def export_minari(dataset: str | os.PathLike, dataset_id: str, *, data_format: str = "arrow",
                  description: str | None = None, author: str = "tap-affordance", author_email: str | None = None,
                  code_permalink: str | None = None):
    """Write the collected dataset at ``dataset`` as the Minari dataset ``dataset_id``.

    Args:
        dataset: Directory of a dataset made by :func:`affordance_env.dataset.collect` (complete).
        dataset_id: Minari's id, ``(namespace/)name-v(version)``, e.g. ``"tap-affordance/canonical-taps-v0"``.
        data_format: ``"arrow"`` (default) or ``"hdf5"`` (needs h5py).
        description: Recorded in the Minari metadata (by default, where the dataset was exported from), followed
            by what the observations leave out and what the infos hold.
        author: Recorded in the Minari metadata.
        author_email: Recorded in the Minari metadata; left out if not given (Minari's reminder about it is not
            shown).
        code_permalink: Recorded in the Minari metadata; left out if not given (Minari's reminder about it is not
            shown).

    Returns:
        dataset (minari.MinariDataset): The dataset as Minari loads it.

    Raises:
        ImportError: minari is not installed (the message says how to install it).
        ValueError: a malformed id, an unknown data format, or a Minari dataset (or a directory) with that id
            exists already; nothing is written.
        DatasetError: ``dataset`` is not a complete dataset.
    """
    minari, EpisodeBuffer = _minari_for(data_format)
    namespace, _, _ = check_dataset_id(dataset_id)
    root, target = _free_target(minari, dataset_id)
    frame = _interactions(dataset)
    manifest = frame.attrs["manifest"]
    options = manifest["settings"]["env_options"]
    with_images = bool(manifest["settings"].get("save_images"))
    buffers = _episode_buffers(frame, with_images, EpisodeBuffer)
    import gymnasium as gym

    from affordance_env.registration import ENV_ID, register_envs

    register_envs()
    text = _description(description, dataset, with_images)
    env = gym.make(ENV_ID, **options)  # the env recover_environment() makes: its spec and its spaces
    staging = Path(tempfile.mkdtemp(prefix=".tap-affordance-export-", dir=root))  # hidden: Minari skips it
    try:
        with _minari_root(staging), warnings.catch_warnings():
            for field in ("code_permalink", "author_email"):  # left out on purpose when not given
                warnings.filterwarnings("ignore", message=f"`{field}` is set to None", category=UserWarning)
            minari.create_dataset_from_buffers(
                dataset_id=dataset_id,
                buffer=buffers,
                env=env,
                eval_env=env.spec,
                observation_space=observation_space(env.observation_space, with_images),
                action_space=env.action_space,
                algorithm_name=f"TapAffordance collect ({manifest['settings']['action']} actions)",
                author=author,
                author_email=author_email,
                code_permalink=code_permalink,
                description=text,
                data_format=data_format,
                jpeg_encoding=False,
                requirements=[f"tap-affordance=={manifest['package_version']}"],
            )
        _move_into_place(staging / dataset_id, target, namespace)
    finally:
        env.close()
        shutil.rmtree(staging, ignore_errors=True)
    return minari.load_dataset(dataset_id)


def _minari_for(data_format: str):
    """``(minari, EpisodeBuffer)`` once ``data_format`` is one of :data:`DATA_FORMATS` and what it needs is
    installed: ValueError for another format, ImportError (saying how to install it) without minari, or without
    h5py for ``"hdf5"``."""
    if data_format not in DATA_FORMATS:
        raise InvalidValueError(f"data_format must be one of {DATA_FORMATS}, got {data_format!r}.")
    minari, EpisodeBuffer = _minari()
    if data_format == "hdf5":
        try:
            import h5py  # noqa: F401 (Minari's HDF5 storage needs it)
        except ImportError as exc:
            raise MissingDependencyError("Minari's hdf5 format needs the h5py package: pip install 'minari[hdf5]' "
                                         "(or export with data_format='arrow')") from exc
    return minari, EpisodeBuffer


def _free_target(minari, dataset_id: str) -> tuple[Path, Path]:
    """``(root, target)``: the directory of Minari's datasets and the one dataset ``dataset_id`` would have;
    ValueError if a Minari dataset (or a directory) with that id exists already."""
    from minari.storage.datasets_root_dir import get_dataset_path

    root = get_dataset_path()
    target = root / dataset_id
    if dataset_id in minari.list_local_datasets() or target.exists():
        raise InvalidValueError(f"a Minari dataset {dataset_id!r} exists already ({target}); delete it with "
                         f"`minari delete {dataset_id}` (or remove that directory) or choose another id.")
    return root, target


def _interactions(dataset: str | os.PathLike):
    """The frame of the complete dataset at ``dataset``, with its images (:func:`load_dataset`); DatasetError if
    it is incomplete (naming the command that finishes it) or holds goal episodes, which the export does not
    take."""
    check_complete(dataset, "exporting it")
    frame = load_dataset(dataset, with_images=True)
    if is_goal_dataset(frame.attrs["manifest"]):
        raise DatasetError(f"{dataset} holds TapAffordanceGoal-v2 episodes; the Minari export writes one "
                           "TapAffordance-v2 episode per interaction and does not take goal episodes: read them "
                           "with load_dataset (a row per interaction, with 'episode' and 'step').")
    return frame


def _episode_buffers(frame, with_images: bool, EpisodeBuffer) -> list:
    """One Minari episode of one step per row of ``frame``: its observations before and after (the features,
    and the range image and mask ``with_images``), action, reward (the displacement [m]) and infos."""
    stages = {stage: frame[[f"{stage}_{n}" for n in FEATURE_NAMES]].to_numpy(np.float32) for stage in STAGES}
    if with_images:
        decoded = {f"{stage}_{kind}": images(frame, f"image_{stage}_{kind}")
                   for stage in STAGES for kind in ("range", "mask")}
    actions = frame[[f"action_{j}" for j in range(3)]].to_numpy(np.float32)
    rewards = frame["displacement"].to_numpy(np.float64)
    buffers = []
    for i, seed in enumerate(frame["seed"]):
        observations = {"features": np.stack([stages["initial"][i], stages["final"][i]])}
        if with_images:
            observations["range"] = np.stack([decoded["initial_range"][i], decoded["final_range"][i]])
            observations["mask"] = np.stack([decoded["initial_mask"][i], decoded["final_mask"][i]]).astype(np.int8)
        # Minari numbers episodes 0..n-1 (it counts them from the largest id); the valid interactions are
        # renumbered in order, each keeps its seed (and its dataset episode in its infos).
        buffers.append(EpisodeBuffer(id=i, seed=int(seed), observations=observations,
                                     actions=actions[i : i + 1], rewards=[float(rewards[i])], terminations=[True],
                                     truncations=[False], infos=_infos(frame, i)))
    return buffers


def _description(description: str | None, dataset: str | os.PathLike, with_images: bool) -> str:
    """The dataset's description in the Minari metadata: ``description`` (by default where it was exported
    from), then what the observations leave out and why, and what the infos hold."""
    dropped = left_out(with_images)
    text = description or f"TapAffordance interactions exported from {Path(dataset).resolve()}."
    return text + (" Observations: the environment's, without "
                   + "; ".join(f"{k} ({why})" for k, why in dropped.items())
                   + ". Infos: the ground truth of each interaction.")


def _move_into_place(staged: Path, target: Path, namespace: str | None) -> None:
    """Move the dataset written at ``staged`` to ``target``, among Minari's datasets, creating its
    ``namespace`` first if Minari does not know it yet."""
    from minari.namespace import create_namespace, list_local_namespaces

    if namespace is not None and namespace not in list_local_namespaces():
        create_namespace(namespace)
    target.parent.mkdir(parents=True, exist_ok=True)
    os.replace(staged, target)
