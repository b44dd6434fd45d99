"""Reading a dataset back: one DataFrame row per interaction, checked chunk by chunk; images decoded."""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from affordance_env.behaviors import ROLL_THRESHOLD, get_behavior, is_success
from affordance_env.dataset.format import (
    CHECKSUMS,
    FEATURE_PREFIXES,
    GROUND_TRUTH_COLUMNS,
    IMAGE_COLUMNS,
    MANIFEST,
    POSE_COLUMNS,
    POSE_FIELDS,
    STAGES,
    DatasetError,
    arrow_schema,
    check_checksum,
    check_chunk,
    chunk_metadata,
    chunk_name,
    chunk_ranges,
    collect_command,
    is_goal_dataset,
    read_manifest,
)
from affordance_env.exceptions import InvalidValueError

#: The names the columns of datasets of schema versions 1 to 4 had, where version 5 renamed them.
_OLD_IMAGE_NAMES = {f"{stage}_{kind}": f"image_{stage}_{kind}" for stage in STAGES for kind in ("range", "mask")}


def _old_names(version: int) -> dict[str, str]:
    """Old column name -> current one, for a dataset of schema ``version``."""
    if version >= 5:
        return {}
    pose = "object_{}_{}" if version == 1 else "{}_{}"  # version 1 named the poses object_initial_x ...
    renames = {pose.format(stage, f): f"true_{stage}_{f}" for stage in STAGES for f in POSE_FIELDS}
    return {**renames, **_OLD_IMAGE_NAMES}


def images(frame: pd.DataFrame, column: str) -> np.ndarray:
    """Decode an image column of a dataset collected with ``save_images=True``, loaded ``with_images=True``.

    Args:
        frame: From :func:`load_dataset`.
        column: ``image_initial_range``, ``image_final_range`` (distance along each pixel's ray [m]; float16
            on disk, about 0.5 mm resolution at 1 m; 0 where nothing was hit) or ``image_initial_mask``,
            ``image_final_mask``.

    Returns:
        (n, H, W) array: float32 ranges or bool masks.
    """
    if column not in IMAGE_COLUMNS:
        renamed = f" ({column!r} is named {_OLD_IMAGE_NAMES[column]!r} now)" if column in _OLD_IMAGE_NAMES else ""
        raise InvalidValueError(f"column must be one of {IMAGE_COLUMNS}, got {column!r}{renamed}.")
    if column not in frame.columns:
        raise InvalidValueError(f"the frame has no {column!r} column: collect with save_images=True (--save-images) "
                         "and load with load_dataset(path, with_images=True).")
    options = frame.attrs["manifest"]["settings"]["env_options"]
    shape = (int(options["camera_height"]), int(options["camera_width"]))
    if column.endswith("range"):
        decoded = [np.frombuffer(b, np.float16).reshape(shape).astype(np.float32) for b in frame[column]]
        return np.stack(decoded) if decoded else np.zeros((0, *shape), np.float32)
    n = shape[0] * shape[1]
    decoded = [np.unpackbits(np.frombuffer(b, np.uint8))[:n].reshape(shape).astype(bool)
               for b in frame[column]]
    return np.stack(decoded) if decoded else np.zeros((0, *shape), bool)


def _derived_success(frame: pd.DataFrame, manifest: dict) -> np.ndarray:
    """The ``success`` label of a dataset of schema version 3 or older, which did not store it: computed from
    ``behavior``, ``rolled`` and ``displacement`` by the rule the environment uses (:func:`is_success`)."""
    settings = manifest.get("settings")
    options = settings.get("env_options") if isinstance(settings, dict) else None
    threshold = float((options if isinstance(options, dict) else {}).get("roll_threshold", ROLL_THRESHOLD))
    success = np.zeros(len(frame), dtype=bool)
    rolled, displacement = frame["rolled"].to_numpy(bool), frame["displacement"].to_numpy(np.float64)
    for name in frame["behavior"].unique():
        try:
            rule = get_behavior(name).success_rule
        except ValueError as exc:
            raise DatasetError(f"the dataset's behavior {name!r} is unknown to this tap-affordance, so its "
                               f"success label cannot be derived ({exc})") from None
        rows = (frame["behavior"] == name).to_numpy()
        success[rows] = is_success(rule, rolled[rows], displacement[rows], threshold)
    return success


def load_dataset(path: str | os.PathLike, *, with_images: bool = False, allow_incomplete: bool = False
                 ) -> pd.DataFrame:
    """Read a dataset directory into a DataFrame, one row per interaction, ordered by episode.

    The columns (:func:`arrow_schema`) fall in namespaces that cannot be confused:

    - bookkeeping: ``episode`` (index i), ``seed`` (env seed of interaction i), ``behavior``;
    - the action: ``action_0..2``;
    - the ground truth, measured by the simulator (see the environment's ``info``), for evaluating and never an
      input of a learner: ``type``, ``size`` [m], ``true_initial_x, _y, _z, _qw, _qx, _qy, _qz`` and
      ``true_final_...`` (the object's position [m] and quaternion), ``displacement`` [m],
      ``rolling_distance`` [m], ``rolled``, ``success``, ``tilt`` [rad], ``toppled``, ``outcome``,
      ``outcome_time`` [s], ``contact``, ``hand_speed`` [m/s], ``visible_initial``, ``visible_final``,
      ``ik_success`` (:data:`GROUND_TRUTH_COLUMNS` and :data:`POSE_COLUMNS`);
    - the features: ``initial_<f>``, ``final_<f>``, ``effect_<f>``, exactly one column per prefix for each
      name ``f`` of ``FEATURE_NAMES`` (:func:`learning_data` returns them as X and E);
    - with ``with_images``, the encoded images ``image_initial_range`` ... (decode them with :func:`images`).

    ``frame.attrs["manifest"]`` holds the manifest and ``frame.attrs["failures"]`` the interactions left out
    (episode -> reason).

    Every chunk is checked against the SHA-256 the manifest recorded when it was written: a chunk that changed
    by a single byte raises DatasetError naming it and the command that redoes it.

    Older datasets load with the current names: those of schema version 4 and older named the pose
    ``initial_x`` ... and the images ``initial_range`` ... (version 1: ``object_initial_x`` ...), and have no
    checksums; those of version 2 and older lack ``rolling_distance``, ``tilt``, ``toppled`` and
    ``outcome_time``; those of version 3 and older did not store ``success``: it is derived on loading by the
    environment's rule, from ``behavior``, ``rolled``, ``displacement`` and the dataset's ``roll_threshold``.

    Args:
        path: The dataset directory (or its ``manifest.json``).
        with_images: Also read the image columns of a dataset collected with ``save_images``.
        allow_incomplete: Read the chunks finished so far of a dataset whose collection has not finished.

    Raises:
        FileNotFoundError: ``path`` does not exist.
        DatasetError: not a dataset, a newer schema, a corrupt, changed or foreign chunk, or (unless
            ``allow_incomplete``) missing chunks.
    """
    path = _dataset_directory(Path(path))
    manifest = read_manifest(path)
    renames = _old_names(manifest["schema_version"])
    redo = collect_command(path, manifest)
    tables, failures, missing = _read_chunks(path, manifest, renames, with_images, redo)
    if missing and not allow_incomplete:
        raise DatasetError(f"{_incomplete(path, missing, redo)}, or pass allow_incomplete=True.")
    return _frame(tables, failures, manifest, renames, with_images)


def check_complete(path: str | os.PathLike, before: str) -> None:
    """Raise DatasetError if a chunk of the dataset at ``path`` is missing or unfinished, naming them and the
    ``affordance collect`` command that finishes the dataset ``before`` what the caller does (``"exporting it"``);
    FileNotFoundError or DatasetError, as :func:`load_dataset`, if it is no dataset."""
    path = _dataset_directory(Path(path))
    manifest = read_manifest(path)
    missing = _unfinished(path, manifest)
    if missing:
        raise DatasetError(f"{_incomplete(path, missing, collect_command(path, manifest))} before {before}.")


def _incomplete(path: Path, missing: list[str], redo: str) -> str:
    """What is missing of the dataset at ``path`` (the names of its chunks ``missing``) and ``redo``, the command
    that finishes it."""
    return (f"{path} is incomplete: {len(missing)} chunk(s) missing or unfinished ({', '.join(missing[:3])}"
            f"{', ...' if len(missing) > 3 else ''}); finish it with `{redo}`")


def _unfinished(path: Path, manifest: dict) -> list[str]:
    """The names of the chunks of the dataset at ``path`` that are missing or unfinished: a chunk is finished once
    the manifest records its checksum (schema version 5 on), before that once it exists."""
    version, recorded = manifest["schema_version"], manifest.get(CHECKSUMS) or {}
    names = [chunk_name(i) for i in range(len(chunk_ranges(manifest["episodes"], manifest["settings"]["chunk_size"])))]
    return [name for name in names if not (path / name).exists() or (version >= 5 and name not in recorded)]


def _dataset_directory(path: Path) -> Path:
    """The directory of the dataset at ``path`` (the directory or its manifest); FileNotFoundError if nothing is
    there, DatasetError if it is one of a dataset's chunks or not a dataset."""
    if not path.exists():
        raise FileNotFoundError(f"No dataset at {path}.")
    if path.is_file() and path.name == MANIFEST:
        path = path.parent
    if path.is_file() and path.suffix == ".parquet":
        try:
            chunk_metadata(path)
        except DatasetError as exc:
            raise DatasetError(f"{path} is not a TapAffordance dataset: {exc}") from None
        raise DatasetError(f"{path} is one chunk of a dataset: load its directory, {path.parent}.")
    if not path.is_dir() or not (path / MANIFEST).is_file():
        raise DatasetError(f"{path} is not a TapAffordance dataset (a directory with {MANIFEST}); make one "
                           "with `affordance collect`.")
    return path


def _read_chunks(path: Path, manifest: dict, renames: dict[str, str], with_images: bool, redo: str
                 ) -> tuple[list[pa.Table], dict, list[str]]:
    """The tables of the dataset's finished chunks in order (:func:`_read_chunk`), the failures they record
    (episode -> reason) and the names of the chunks missing or unfinished."""
    images_on_disk = {old for old, new in renames.items() if new in IMAGE_COLUMNS} | set(IMAGE_COLUMNS)
    tables, failures, missing = [], {}, _unfinished(path, manifest)
    ranges = chunk_ranges(manifest["episodes"], manifest["settings"]["chunk_size"])
    for index, (start, stop) in enumerate(ranges):
        chunk = path / chunk_name(index)
        if chunk.name not in missing:
            tables.append(_read_chunk(chunk, manifest, (start, stop), images_on_disk, with_images, redo, failures))
    return tables, failures, missing


def _read_chunk(chunk: Path, manifest: dict, episodes: tuple[int, int], images_on_disk: set[str],
                with_images: bool, redo: str, failures: dict) -> pa.Table:
    """The table of one chunk of episodes ``(start, stop)``, checked against the manifest (its checksum from
    version 5 on, its metadata from version 2 on), without its image columns (``images_on_disk``, by any of
    their names) unless ``with_images``, and without schema metadata; the failures it records are added to
    ``failures``. DatasetError naming the chunk and ``redo``, the command that collects it again, if it is
    changed, foreign or corrupt."""
    version = manifest["schema_version"]
    try:
        if version >= 5:
            check_checksum(chunk, manifest)
        if version >= 2:
            failures.update(check_chunk(chunk, manifest, *episodes)["chunk"]["failures"])
        names = pq.read_schema(chunk).names
        columns = None if with_images else [c for c in names if c not in images_on_disk]
        table = pq.read_table(chunk, columns=columns)
    except DatasetError as exc:
        raise DatasetError(f"{exc} Redo it with `{redo}` (it collects that chunk again).") from exc
    except Exception as exc:  # pyarrow raises several types for damaged files
        raise DatasetError(f"{chunk} is corrupt ({exc}); redo it with `{redo}` (it collects that chunk "
                           "again).") from exc
    if version == 1:
        failures.update(json.loads((table.schema.metadata or {}).get(b"tap_affordance_failures", b"{}")))
        table = table.drop_columns([c for c in images_on_disk if c in table.column_names])
    return table.replace_schema_metadata(None)


def _frame(tables: list[pa.Table], failures: dict, manifest: dict, renames: dict[str, str], with_images: bool
           ) -> pd.DataFrame:
    """The frame of the chunks' tables (an empty one of the dataset's schema if there are none) under the current
    column names, with ``success`` (derived for versions 1 to 3), and the manifest and the failures (by episode)
    in its attrs."""
    if not tables:
        tables = [arrow_schema(with_images and manifest["settings"].get("save_images", False),
                               goal=is_goal_dataset(manifest)).empty_table()]
    frame = pa.concat_tables(tables).to_pandas()
    frame = frame.rename(columns=renames)
    if "success" not in frame.columns:  # versions 1 to 3: derived, in the column's place after rolled
        frame.insert(frame.columns.get_loc("rolled") + 1, "success", _derived_success(frame, manifest))
    frame.attrs["manifest"] = manifest
    frame.attrs["failures"] = {int(k): v for k, v in sorted(failures.items(), key=lambda kv: int(kv[0]))}
    return frame


def learning_data(frame: pd.DataFrame, behavior: str | None = None) -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """What a learner of one behaviour gets from a dataset frame: ``(X, E, labels)``.

    Args:
        frame: From :func:`load_dataset` (or a frame with its columns).
        behavior: Keep the interactions of this behaviour (the paper learns one model per behaviour); None: the
            frame must hold a single one.

    Returns:
        ``X``: (n, 49) initial features, ``E``: (n, 49) effects (final minus initial), both with the feature
        names as columns, in the order of ``FEATURE_NAMES``; ``labels``: the ground truth of those rows
        (``type``, ``size`` [m], ``success``, and the other :data:`GROUND_TRUTH_COLUMNS` the frame has), for
        evaluating, never for learning. All three keep the frame's index.

    Raises:
        ValueError: the frame lacks feature columns, holds no interaction of ``behavior``, or mixes behaviours
            and ``behavior`` is None.
    """
    from affordance_env.features import FEATURE_NAMES

    missing = [f"{prefix}{n}" for prefix in (FEATURE_PREFIXES[0], FEATURE_PREFIXES[2]) for n in FEATURE_NAMES
               if f"{prefix}{n}" not in frame.columns]
    if missing:
        raise InvalidValueError(f"the frame lacks {len(missing)} feature column(s), e.g. {missing[:3]}; expected "
                         "initial_<f> and effect_<f> for every name f of FEATURE_NAMES (a frame of load_dataset).")
    found = sorted(pd.unique(frame["behavior"].astype(str))) if "behavior" in frame.columns else []
    if behavior is not None:
        if "behavior" in frame.columns:
            if behavior not in found:
                raise InvalidValueError(f"the frame holds no {behavior!r} interactions (it holds {found}).")
            frame = frame[frame["behavior"] == behavior]
    elif len(found) > 1:
        raise InvalidValueError(f"the frame mixes the behaviours {found}; pass behavior= one of them (one model per "
                         "behaviour).")
    X = frame[[f"initial_{n}" for n in FEATURE_NAMES]].set_axis(list(FEATURE_NAMES), axis=1)
    E = frame[[f"effect_{n}" for n in FEATURE_NAMES]].set_axis(list(FEATURE_NAMES), axis=1)
    truth = [c for c in (*GROUND_TRUTH_COLUMNS, *POSE_COLUMNS) if c in frame.columns]
    return X.astype(np.float64), E.astype(np.float64), frame[truth].copy()
