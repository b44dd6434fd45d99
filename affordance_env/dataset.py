"""Datasets of interactions: collected in parallel, deterministically, resumably; read back as a DataFrame.

On disk a dataset is a directory::

    manifest.json          settings, package version, feature names and groups, schema version
    chunk-00000.parquet    interactions 0 .. chunk_size-1, one row each
    chunk-00001.parquet    ...

Interaction ``i`` depends only on ``(seed, i)``: its environment seed is drawn from
``numpy.random.SeedSequence([seed, i])`` (and so is its action when actions are random), so a dataset is the
same whatever the number of workers. A chunk is written to a temporary name and renamed when complete, so a
crash or ``kill -9`` leaves only whole chunks, and running the same command again collects just the missing
ones. Interactions the environment marks as failed (``info["failure"]``) are not written as rows; their
episode and reason are kept in the chunk's metadata and listed by :func:`load_dataset` in
``frame.attrs["failures"]``.
"""

from __future__ import annotations

import functools
import json
import os
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from affordance_env.features import FEATURE_GROUPS, FEATURE_NAMES

SCHEMA_VERSION = 1
MANIFEST = "manifest.json"
FORMAT = "tap-affordance-dataset"
ACTIONS = ("canonical", "random")
POSE_FIELDS = ("x", "y", "z", "qw", "qx", "qy", "qz")


class DatasetError(ValueError):
    """A dataset that cannot be read or extended, with the reason."""


def interaction_seed(seed: int, episode: int) -> int:
    """Environment seed of interaction ``episode`` of a dataset collected with ``seed``."""
    return int(np.random.SeedSequence([seed, episode]).generate_state(1)[0])


def interaction_action(seed: int, episode: int, action: str) -> np.ndarray:
    """Action of interaction ``episode``: zeros (the canonical tap) or uniform in [-1, 1]^3 from ``(seed, i)``."""
    if action == "canonical":
        return np.zeros(3, dtype=np.float32)
    rng = np.random.default_rng(np.random.SeedSequence([seed, episode, 1]))
    return rng.uniform(-1.0, 1.0, 3).astype(np.float32)


def _full_options(env_options: dict[str, Any]) -> dict[str, Any]:
    """The env options with every default filled in, so that equal settings compare equal however given."""
    import inspect

    from affordance_env.tap_env import TapAffordanceEnv

    parameters = inspect.signature(TapAffordanceEnv.__init__).parameters
    unknown = sorted(set(env_options) - set(parameters) | ({"reward_fn", "render_mode"} & set(env_options)))
    if unknown:
        allowed = sorted(set(parameters) - {"self", "reward_fn", "render_mode", "render_width", "render_height"})
        raise ValueError(f"unknown or unsupported env options {unknown} for collection; allowed: {allowed}.")
    full = {name: p.default for name, p in parameters.items()
            if name not in ("self", "reward_fn", "render_mode", "render_width", "render_height")}
    full.update(env_options)
    return json.loads(json.dumps(full, default=list))


def _settings(seed: int, action: str, chunk_size: int, env_options: dict[str, Any], save_images: bool) -> dict:
    return {"seed": int(seed), "action": action, "chunk_size": int(chunk_size), "save_images": bool(save_images),
            "env_options": json.loads(json.dumps(env_options, default=list))}


def images(frame: pd.DataFrame, column: str) -> np.ndarray:
    """Decode an image column of a dataset collected with ``save_images=True``.

    Args:
        frame: From :func:`load_dataset`.
        column: ``initial_range``, ``final_range`` (metres, float16 on disk; 0 where nothing was hit) or
            ``initial_mask``, ``final_mask`` (bool).

    Returns:
        (n, H, W) array: float32 ranges or bool masks.
    """
    if column not in ("initial_range", "final_range", "initial_mask", "final_mask"):
        raise ValueError(f"column must be one of initial_range, final_range, initial_mask, final_mask, got {column!r}.")
    if column not in frame.columns:
        raise ValueError(f"the dataset has no {column!r} column: collect it with save_images=True (--save-images).")
    options = frame.attrs["manifest"]["settings"]["env_options"]
    shape = (int(options["camera_height"]), int(options["camera_width"]))
    if column.endswith("range"):
        return np.stack([np.frombuffer(b, np.float16).reshape(shape).astype(np.float32) for b in frame[column]])
    n = shape[0] * shape[1]
    return np.stack([np.unpackbits(np.frombuffer(b, np.uint8))[:n].reshape(shape).astype(bool) for b in frame[column]])


@functools.cache
def _env(options_json: str):
    """One environment per worker process and option set (building one takes about a second)."""
    from affordance_env.tap_env import TapAffordanceEnv

    return TapAffordanceEnv(**json.loads(options_json))


def _row(episode: int, env_seed: int, action: np.ndarray, info: dict) -> dict[str, Any]:
    row: dict[str, Any] = {"episode": episode, "seed": env_seed}
    row.update({f"action_{j}": float(a) for j, a in enumerate(action)})
    obj = info["object"]
    row.update(type=obj["type"], size=float(obj["size"]))
    row.update({f"object_initial_{f}": float(v) for f, v in zip(POSE_FIELDS, obj["initial_pose"], strict=True)})
    row.update({f"object_final_{f}": float(v) for f, v in zip(POSE_FIELDS, obj["final_pose"], strict=True)})
    row.update(displacement=float(info["displacement"]), rolled=bool(info["rolled"]), outcome=info["outcome"],
               contact=bool(info["contact"]), hand_speed=float(info["hand_speed"]),
               visible_initial=bool(np.any(info["initial_features"])), visible_final=bool(info["visible"]),
               ik_success=bool(info["ik"]["success"]), behavior=info["behavior"])
    for prefix, values in (("initial", info["initial_features"]), ("final", info["final_features"]),
                           ("effect", info["effect"])):
        row.update({f"{prefix}_{n}": float(v) for n, v in zip(FEATURE_NAMES, values, strict=True)})
    return row


def _collect_chunk(out: str, index: int, episodes: range, seed: int, action: str, options_json: str,
                   save_images: bool = False) -> int:
    """Run the interactions of one chunk and write it atomically; returns the number of interactions."""
    env = _env(options_json)
    rows, failures = [], {}
    for episode in episodes:
        env_seed = interaction_seed(seed, episode)
        act = interaction_action(seed, episode, action)
        obs_initial, _ = env.reset(seed=env_seed)
        obs_final, _, _, _, info = env.step(act)
        if info["failure"] is not None:
            failures[str(episode)] = info["failure"]
            continue
        row = _row(episode, env_seed, act, info)
        if not all(np.isfinite(v) for v in row.values() if isinstance(v, float)):
            failures[str(episode)] = "non-finite values in the interaction's record"
            continue
        if save_images:
            for stage, obs in (("initial", obs_initial), ("final", obs_final)):
                row[f"{stage}_range"] = obs["range"].astype(np.float16).tobytes()
                row[f"{stage}_mask"] = np.packbits(obs["mask"].astype(bool)).tobytes()
        rows.append(row)
    table = pa.Table.from_pandas(pd.DataFrame(rows), preserve_index=False)
    table = table.replace_schema_metadata({**(table.schema.metadata or {}),
                                           b"tap_affordance_failures": json.dumps(failures).encode()})
    path = Path(out) / f"chunk-{index:05d}.parquet"
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    pq.write_table(table, tmp, compression="zstd")
    os.replace(tmp, path)
    return len(episodes)


def _chunk_ranges(episodes: int, chunk_size: int) -> list[range]:
    return [range(s, min(s + chunk_size, episodes)) for s in range(0, episodes, chunk_size)]


def collect(
    out,
    episodes: int,
    seed: int = 0,
    workers: int = 1,
    action: str = "canonical",
    env_options: dict[str, Any] | None = None,
    chunk_size: int = 50,
    progress: bool | None = None,
    dask_address: str | None = None,
    save_images: bool = False,
) -> Path:
    """Collect ``episodes`` interactions into the dataset directory ``out`` (resuming if it exists).

    Args:
        out: Dataset directory; created if missing.
        episodes: Number of interactions.
        seed: Seed of the dataset; interaction ``i`` depends only on ``(seed, i)``.
        workers: Worker processes (joblib). The result does not depend on it.
        action: ``"canonical"`` (the paper's tap, all zeros) or ``"random"`` (uniform in the action box).
        env_options: Keyword arguments of ``TapAffordance-v0`` (behavior, object_types, size_range, ...).
        chunk_size: Interactions per file; what a crash can lose at most, per worker.
        progress: Show a progress bar; default: on a terminal, and not when ``CI`` is set.
        save_images: Also store the initial and final range images (float16) and object masks (bit-packed),
            compressed; decode them with :func:`images`.
        dask_address: Run the chunks on this Dask distributed scheduler (``"tcp://host:8786"``) instead of local
            processes; the workers must see ``out`` (a shared file system). The dataset is the same.

    Returns:
        The dataset directory.
    """
    from joblib import Parallel, delayed

    if not isinstance(episodes, int | np.integer) or episodes < 1:
        raise ValueError(f"episodes must be a positive integer, got {episodes!r}.")
    if not isinstance(workers, int | np.integer) or workers < 1:
        raise ValueError(f"workers must be a positive integer, got {workers!r}.")
    if action not in ACTIONS:
        raise ValueError(f"action must be one of {ACTIONS}, got {action!r}.")
    if not isinstance(chunk_size, int | np.integer) or chunk_size < 1:
        raise ValueError(f"chunk_size must be a positive integer, got {chunk_size!r}.")
    env_options = _full_options(dict(env_options or {}))
    _env(json.dumps(env_options, sort_keys=True, default=list))  # bad options fail here, clearly, before any work
    out = Path(out)
    settings = _settings(seed, action, chunk_size, env_options, save_images)
    manifest_path = out / MANIFEST
    if manifest_path.exists():
        existing = _read_manifest(out)
        stored = {"save_images": False, **existing["settings"]}  # datasets from before save_images existed
        differs = {k: (stored.get(k), v) for k, v in settings.items() if stored.get(k) != v}
        if differs:
            details = "; ".join(f"{k}: dataset has {old!r}, asked for {new!r}" for k, (old, new) in differs.items())
            raise DatasetError(f"{out} holds a dataset made with other settings ({details}). Use another --out "
                               "or the same settings to resume or extend it.")
        episodes = max(episodes, int(existing["episodes"]))
    elif out.exists() and any(out.iterdir()):
        raise DatasetError(f"{out} exists and is not a TapAffordance dataset (no {MANIFEST}); choose an empty or "
                           "new directory.")
    out.mkdir(parents=True, exist_ok=True)
    for stale in out.glob(".chunk-*.tmp"):  # left by a run that was killed while writing
        stale.unlink()
    _write_manifest(out, episodes, settings)
    chunks = _chunk_ranges(episodes, chunk_size)
    todo = [(i, r) for i, r in enumerate(chunks) if not (out / f"chunk-{i:05d}.parquet").exists()]
    done = episodes - sum(len(r) for _, r in todo)
    if progress is None:
        progress = sys.stderr.isatty() and not os.environ.get("CI")
    options_json = json.dumps(env_options, sort_keys=True, default=list)
    from tqdm.auto import tqdm

    with tqdm(total=episodes, initial=done, unit="interaction", disable=not progress, smoothing=0.1) as bar:
        if dask_address is not None:
            tasks = [(str(out), i, r, seed, action, options_json, save_images) for i, r in todo]
            results = _dask_results(dask_address, tasks)
        elif workers == 1:
            results: Iterator[int] = (
                _collect_chunk(str(out), i, r, seed, action, options_json, save_images) for i, r in todo
            )
        else:
            results = Parallel(n_jobs=workers, return_as="generator_unordered")(
                delayed(_collect_chunk)(str(out), i, r, seed, action, options_json, save_images) for i, r in todo
            )
        for n in results:
            bar.update(n)
    return out


def _dask_results(address: str, tasks: list[tuple]) -> Iterator[int]:
    """Run chunk tasks on a Dask distributed cluster, yielding as they complete."""
    try:
        from distributed import Client, as_completed
    except ImportError as exc:
        raise ImportError("dask_address needs Dask distributed: pip install 'tap-affordance[dask]'") from exc
    with Client(address) as client:
        futures = [client.submit(_collect_chunk, *task, pure=False) for task in tasks]
        for future in as_completed(futures):
            yield future.result()


def _write_manifest(out: Path, episodes: int, settings: dict) -> None:
    from affordance_env import __version__

    manifest = {
        "format": FORMAT,
        "schema_version": SCHEMA_VERSION,
        "package_version": __version__,
        "episodes": int(episodes),
        "settings": settings,
        "feature_names": list(FEATURE_NAMES),
        "feature_groups": dict(FEATURE_GROUPS),
    }
    tmp = out / f".{MANIFEST}.tmp"
    tmp.write_text(json.dumps(manifest, indent=2))
    os.replace(tmp, out / MANIFEST)


def _read_manifest(path: Path) -> dict:
    try:
        manifest = json.loads((path / MANIFEST).read_text())
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DatasetError(f"{path / MANIFEST} is not a readable TapAffordance manifest ({exc}).") from exc
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise DatasetError(f"{path} is not a TapAffordance dataset (its {MANIFEST} has no format {FORMAT!r}).")
    version = manifest.get("schema_version")
    if not isinstance(version, int) or version > SCHEMA_VERSION:
        raise DatasetError(f"{path} has dataset schema version {version!r}; this tap-affordance reads versions up "
                           f"to {SCHEMA_VERSION}: upgrade the package.")
    return manifest


def load_dataset(path, *, allow_incomplete: bool = False) -> pd.DataFrame:
    """Read a dataset directory into a DataFrame, one row per interaction, ordered by episode.

    Columns: ``episode``, ``seed``, ``action_0..2``, ``type``, ``size``, ``object_initial_x..qz`` and
    ``object_final_x..qz`` (position [m] and quaternion),
    ``displacement``, ``rolled``, ``outcome``, ``contact``, ``hand_speed``, ``visible_initial``,
    ``visible_final``, ``ik_success``, ``behavior``, and ``initial_<f>``, ``final_<f>``, ``effect_<f>`` for every
    feature name ``f``. ``frame.attrs`` holds the manifest (``"manifest"``) and the failed interactions
    (``"failures"``: episode -> reason).

    Raises:
        FileNotFoundError: ``path`` does not exist.
        DatasetError: not a dataset, a newer schema, a corrupt chunk, or (unless ``allow_incomplete``) missing
            chunks.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"No dataset at {path}.")
    if not path.is_dir() or not (path / MANIFEST).is_file():
        raise DatasetError(f"{path} is not a TapAffordance dataset (a directory with {MANIFEST}); make one with "
                           "`affordance collect`.")
    manifest = _read_manifest(path)
    chunks = _chunk_ranges(int(manifest["episodes"]), int(manifest["settings"]["chunk_size"]))
    frames, failures, missing = [], {}, []
    for i in range(len(chunks)):
        chunk = path / f"chunk-{i:05d}.parquet"
        if not chunk.exists():
            missing.append(chunk.name)
            continue
        try:
            table = pq.read_table(chunk)
        except Exception as exc:  # pyarrow raises several types for damaged files
            raise DatasetError(f"{chunk} is corrupt ({exc}); delete it and rerun the collection to redo it.") from exc
        failures.update(json.loads((table.schema.metadata or {}).get(b"tap_affordance_failures", b"{}")))
        frames.append(table.to_pandas())
    if missing and not allow_incomplete:
        raise DatasetError(f"{path} is incomplete: {len(missing)} chunk(s) missing ({missing[:3]}...); rerun the "
                           "same `affordance collect` command to finish it, or pass allow_incomplete=True.")
    frame = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    if len(frame):
        frame = frame.sort_values("episode", ignore_index=True)
    frame.attrs["manifest"] = manifest
    frame.attrs["failures"] = {int(k): v for k, v in failures.items()}
    return frame
