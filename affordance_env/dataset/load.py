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
    IMAGE_COLUMNS,
    MANIFEST,
    POSE_FIELDS,
    DatasetError,
    arrow_schema,
    check_chunk,
    chunk_metadata,
    chunk_name,
    chunk_ranges,
    read_manifest,
)


def images(frame: pd.DataFrame, column: str) -> np.ndarray:
    """Decode an image column of a dataset collected with ``save_images=True``, loaded ``with_images=True``.

    Args:
        frame: From :func:`load_dataset`.
        column: ``initial_range``, ``final_range`` (distance along each pixel's ray [m]; float16 on disk,
            about 0.5 mm resolution at 1 m; 0 where nothing was hit) or ``initial_mask``, ``final_mask``.

    Returns:
        (n, H, W) array: float32 ranges or bool masks.
    """
    if column not in IMAGE_COLUMNS:
        raise ValueError(f"column must be one of {IMAGE_COLUMNS}, got {column!r}.")
    if column not in frame.columns:
        raise ValueError(f"the frame has no {column!r} column: collect with save_images=True (--save-images) "
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

    Columns (:func:`arrow_schema`): ``episode`` (index i), ``seed`` (env seed of interaction i), ``behavior``,
    ``type``, ``size`` [m], ``action_0..2``, ``initial_x, _y, _z, _qw, _qx, _qy, _qz`` and ``final_...``
    (object position [m] and quaternion), ``displacement`` [m], ``rolling_distance`` [m], ``rolled``,
    ``success``, ``tilt`` [rad], ``toppled``, ``outcome``, ``outcome_time`` [s] (see the environment's ``info``;
    datasets of schema version 2 and older lack ``rolling_distance``, ``tilt``, ``toppled`` and ``outcome_time``;
    those of version 3 and older did not store ``success``: it is derived on loading by the environment's rule,
    from ``behavior``, ``rolled``, ``displacement`` and the dataset's ``roll_threshold``), ``contact``,
    ``hand_speed`` [m/s], ``visible_initial``, ``visible_final``, ``ik_success``, then ``initial_<f>``,
    ``final_<f>``, ``effect_<f>`` for each name ``f`` of ``FEATURE_NAMES``; with ``with_images`` also the
    encoded images (decode them with :func:`images`). ``frame.attrs["manifest"]`` holds the manifest and
    ``frame.attrs["failures"]`` the interactions left out (episode -> reason).

    Args:
        path: The dataset directory (or its ``manifest.json``).
        with_images: Also read the image columns of a dataset collected with ``save_images``.
        allow_incomplete: Read the chunks present of a dataset whose collection has not finished.

    Raises:
        FileNotFoundError: ``path`` does not exist.
        DatasetError: not a dataset, a newer schema, a corrupt or foreign chunk, or (unless
            ``allow_incomplete``) missing chunks.
    """
    path = Path(path)
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
    manifest = read_manifest(path)
    version = manifest["schema_version"]
    tables, failures, missing = [], {}, []
    ranges = chunk_ranges(manifest["episodes"], manifest["settings"]["chunk_size"])
    for index, (start, stop) in enumerate(ranges):
        chunk = path / chunk_name(index)
        if not chunk.exists():
            missing.append(chunk.name)
            continue
        try:
            if version >= 2:
                failures.update(check_chunk(chunk, manifest, start, stop)["chunk"]["failures"])
            columns = None if with_images else [c for c in pq.read_schema(chunk).names if c not in IMAGE_COLUMNS]
            table = pq.read_table(chunk, columns=columns)
        except DatasetError as exc:
            raise DatasetError(f"{exc} Delete {chunk.name} and rerun the same collect command to redo "
                               "it.") from exc
        except Exception as exc:  # pyarrow raises several types for damaged files
            raise DatasetError(f"{chunk} is corrupt ({exc}); delete it and rerun the same collect command to "
                               "redo it.") from exc
        if version == 1:
            failures.update(json.loads((table.schema.metadata or {}).get(b"tap_affordance_failures", b"{}")))
            table = table.drop_columns([c for c in IMAGE_COLUMNS if c in table.column_names])
        tables.append(table.replace_schema_metadata(None))
    if missing and not allow_incomplete:
        raise DatasetError(f"{path} is incomplete: {len(missing)} chunk(s) missing ({', '.join(missing[:3])}"
                           f"{', ...' if len(missing) > 3 else ''}); rerun the same collect command to "
                           "finish it, or pass allow_incomplete=True.")
    if not tables:
        tables = [arrow_schema(with_images and manifest["settings"].get("save_images", False)).empty_table()]
    frame = pa.concat_tables(tables).to_pandas()
    if version == 1:  # version 1 named the poses object_initial_x ...
        frame = frame.rename(columns={f"object_{stage}_{f}": f"{stage}_{f}"
                                      for stage in ("initial", "final") for f in POSE_FIELDS})
    if "success" not in frame.columns:  # versions 1 to 3: derived, in the column's place after rolled
        frame.insert(frame.columns.get_loc("rolled") + 1, "success", _derived_success(frame, manifest))
    frame.attrs["manifest"] = manifest
    frame.attrs["failures"] = {int(k): v for k, v in sorted(failures.items(), key=lambda kv: int(kv[0]))}
    return frame
