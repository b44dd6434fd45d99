"""Datasets of interactions: collected in parallel, deterministically and resumably; read back as a DataFrame.

On disk a dataset is a directory::

    manifest.json          what the dataset is: settings, package version, feature names and groups, schema
                           version, progress, and the interactions left out (count, kinds, episode -> reason)
    chunk-00000.parquet    interactions 0 .. chunk_size-1, one row each (columns: :func:`arrow_schema`)
    chunk-00001.parquet    ...
    .lock                  held by the collection writing the dataset (empty)

Each chunk also carries the dataset's description, its episode range and its failures in its Parquet key-value
metadata (key ``tap_affordance``), so that a chunk can be checked on its own.

Interaction ``i`` depends only on ``(seed, i)``: its environment seed comes from ``SeedSequence([seed, i])``
and its random action (``action="random"``) from ``SeedSequence([seed, i, 1])``, so the data are the same
whatever the workers or the scheduler. A chunk is written to a temporary name and renamed when complete: a
crash or ``kill -9`` leaves only whole chunks, and the same command collects just the missing ones. An
interaction that raises, yields non-finite numbers, or that the environment marks as failed
(``info["failure"]``) is not written; its episode and reason go to the chunk's metadata and the manifest.
"""

from __future__ import annotations

import contextlib
import inspect
import json
import os
import sys
import threading
import uuid
import warnings
from collections import Counter
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from affordance_env.behaviors import ACTION_DIM
from affordance_env.features import FEATURE_GROUPS, FEATURE_NAMES

#: Version of the on-disk format; :func:`load_dataset` reads versions 1 up to this one.
SCHEMA_VERSION = 3
FORMAT = "tap-affordance-dataset"
MANIFEST = "manifest.json"
METADATA_KEY = b"tap_affordance"
ACTIONS = ("canonical", "random")
SCHEDULERS = ("joblib", "dask")
POSE_FIELDS = ("x", "y", "z", "qw", "qx", "qy", "qz")
IMAGE_COLUMNS = ("initial_range", "initial_mask", "final_range", "final_mask")
#: Env arguments that a dataset cannot record, or that do not change the data.
_NOT_COLLECTED = ("self", "reward_fn", "render_mode", "render_width", "render_height")


class DatasetError(ValueError):
    """A dataset that cannot be read or extended, with the reason."""


# --- schema ---------------------------------------------------------------------------------------------
def arrow_schema(save_images: bool = False) -> pa.Schema:
    """The columns of every chunk, in order: bookkeeping, action, ground truth, 3 x 49 features, images."""
    fields = [("episode", pa.int64()), ("seed", pa.int64()), ("behavior", pa.string()),
              ("type", pa.string()), ("size", pa.float64())]
    fields += [(f"action_{j}", pa.float32()) for j in range(ACTION_DIM)]
    fields += [(f"{stage}_{f}", pa.float64()) for stage in ("initial", "final") for f in POSE_FIELDS]
    fields += [("displacement", pa.float64()), ("rolling_distance", pa.float64()), ("rolled", pa.bool_()),
               ("tilt", pa.float64()), ("toppled", pa.bool_()), ("outcome", pa.string()),
               ("outcome_time", pa.float64()), ("contact", pa.bool_()), ("hand_speed", pa.float64()),
               ("visible_initial", pa.bool_()), ("visible_final", pa.bool_()), ("ik_success", pa.bool_())]
    fields += [(f"{stage}_{name}", pa.float64())
               for stage in ("initial", "final", "effect") for name in FEATURE_NAMES]
    if save_images:
        fields += [(column, pa.binary()) for column in IMAGE_COLUMNS]
    return pa.schema(fields)


def interaction_seed(seed: int, episode: int) -> int:
    """Environment seed of interaction ``episode`` of a dataset collected with ``seed``."""
    return int(np.random.SeedSequence([seed, episode]).generate_state(1)[0])


def interaction_action(seed: int, episode: int, action: str) -> np.ndarray:
    """Action of interaction ``episode``: zeros (canonical tap) or uniform in [-1, 1]^3 by (seed, i)."""
    if action == "canonical":
        return np.zeros(ACTION_DIM, dtype=np.float32)
    if action != "random":
        raise ValueError(f"action must be one of {ACTIONS}, got {action!r}.")
    rng = np.random.default_rng(np.random.SeedSequence([seed, episode, 1]))
    return rng.uniform(-1.0, 1.0, ACTION_DIM).astype(np.float32)


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


# --- a worker: interactions -> one chunk file --------------------------------------------------------------
#: Per worker thread, {options: env}: building an env takes about a second, so a worker keeps its own.
_worker = threading.local()


def _worker_env(options_json: str):
    envs = _worker.__dict__.setdefault("envs", {})
    if options_json not in envs:
        from affordance_env.tap_env import TapAffordanceEnv

        envs[options_json] = TapAffordanceEnv(**json.loads(options_json))
    return envs[options_json]


def _drop_worker_env(options_json: str) -> None:
    """Forget an env whose state may be broken (it raised); the next interaction builds a fresh one."""
    env = _worker.__dict__.get("envs", {}).pop(options_json, None)
    if env is not None:
        with contextlib.suppress(Exception):
            env.close()


def _record(episode: int, env_seed: int, action: np.ndarray, reset_info: dict, info: dict) -> dict[str, Any]:
    obj = info["object"]
    row: dict[str, Any] = {"episode": episode, "seed": env_seed, "behavior": info["behavior"],
                           "type": obj["type"], "size": float(obj["size"])}
    row.update({f"action_{j}": a for j, a in enumerate(action)})
    for stage in ("initial", "final"):
        row.update({f"{stage}_{f}": float(v) for f, v in zip(POSE_FIELDS, obj[f"{stage}_pose"], strict=True)})
    row.update(displacement=float(info["displacement"]), rolling_distance=float(info["rolling_distance"]),
               rolled=bool(info["rolled"]), tilt=float(info["tilt"]), toppled=bool(info["toppled"]),
               outcome=info["outcome"], outcome_time=float(info["outcome_time"]), contact=bool(info["contact"]),
               hand_speed=float(info["hand_speed"]), visible_initial=bool(reset_info["visible"]),
               visible_final=bool(info["visible"]), ik_success=bool(info["ik"]["success"]))
    for stage, values in (("initial", info["initial_features"]), ("final", info["final_features"]),
                          ("effect", info["effect"])):
        row.update({f"{stage}_{name}": float(v) for name, v in zip(FEATURE_NAMES, values, strict=True)})
    return row


def _row(episode: int, env_seed: int, action: np.ndarray, reset: tuple, step: tuple, save_images: bool
         ) -> dict[str, Any] | str:
    """The row of an interaction, from what ``env.reset`` and ``env.step`` returned, or why it has none."""
    (obs_initial, reset_info), (obs_final, *_, info) = reset, step
    if info["failure"] is not None:
        return info["failure"]
    row = _record(episode, env_seed, action, reset_info, info)
    bad = [k for k, v in row.items() if isinstance(v, float | np.floating) and not np.isfinite(v)]
    if bad:
        return f"non-finite: {len(bad)} non-finite value(s) in the record, e.g. {bad[:3]}"
    if save_images:
        for stage, obs in (("initial", obs_initial), ("final", obs_final)):
            row[f"{stage}_range"] = obs["range"].astype(np.float16).tobytes()
            row[f"{stage}_mask"] = np.packbits(obs["mask"].astype(bool)).tobytes()
    return row


def _collect_chunk(out: str, index: int, start: int, stop: int, header: dict) -> tuple[int, int, dict]:
    """Run interactions ``start .. stop-1``, write them as chunk ``index``; returns (index, n, failures)."""
    from affordance_env import __version__

    if __version__ != header["package_version"]:
        raise RuntimeError(f"this worker has tap-affordance {__version__}, the dataset is collected with "
                           f"{header['package_version']}: install the same version on every worker.")
    settings = header["settings"]
    options_json = json.dumps(settings["env_options"], sort_keys=True)
    schema = arrow_schema(settings["save_images"])
    columns: dict[str, list] = {name: [] for name in schema.names}
    failures: dict[str, str] = {}
    for episode in range(start, stop):
        env = _worker_env(options_json)  # an env that cannot be built stops the run: not a failed interaction
        env_seed = interaction_seed(settings["seed"], episode)
        action = interaction_action(settings["seed"], episode, settings["action"])
        try:
            reset = env.reset(seed=env_seed)
            step = env.step(action)
        except Exception as exc:  # the simulation's own failure: reported, never written, not fatal
            _drop_worker_env(options_json)  # its state is not to be trusted
            failures[str(episode)] = f"exception: {type(exc).__name__}: {str(exc)[:500]}"
            continue
        row = _row(episode, env_seed, action, reset, step, settings["save_images"])
        if isinstance(row, str):
            failures[str(episode)] = row
            continue
        for name in schema.names:
            columns[name].append(row[name])
    meta = {**header, "chunk": {"index": index, "start": start, "stop": stop, "failures": failures}}
    table = pa.Table.from_pydict(columns, schema=schema.with_metadata({METADATA_KEY: json.dumps(meta)}))
    # zstd for the images (small); snappy for the numbers: zstd saves little there and reads twice as slowly
    codecs = {name: "zstd" if name in IMAGE_COLUMNS else "snappy" for name in schema.names}
    _write_atomically(Path(out) / chunk_name(index),
                      lambda tmp: pq.write_table(table, tmp, compression=codecs))
    return index, stop - start, failures


def _write_atomically(path: Path, write: Callable[[Path], Any]) -> None:
    """``write(tmp)`` to a unique temporary name beside ``path``, flush it to disk, rename it to ``path``."""
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        write(tmp)
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    with contextlib.suppress(OSError):  # make the rename durable too (not every file system can)
        fd = os.open(path.parent, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def chunk_name(index: int) -> str:
    return f"chunk-{index:05d}.parquet"


def _chunk_ranges(episodes: int, chunk_size: int) -> list[tuple[int, int]]:
    return [(s, min(s + chunk_size, episodes)) for s in range(0, episodes, chunk_size)]


# --- the coordinator -------------------------------------------------------------------------------------
def _full_options(env_options: dict[str, Any]) -> dict[str, Any]:
    """The env options with every default filled in, as JSON values, so that equal settings compare equal."""
    from affordance_env.tap_env import TapAffordanceEnv

    parameters = inspect.signature(TapAffordanceEnv.__init__).parameters
    allowed = [name for name in parameters if name not in _NOT_COLLECTED]
    unknown = sorted(set(env_options) - set(allowed))
    if unknown:
        raise ValueError(f"unknown or unsupported env options {unknown} for collection; allowed: {allowed}.")
    full = {name: parameters[name].default for name in allowed}
    full.update(env_options)
    return json.loads(json.dumps(full, default=list))


def _header(seed: int, action: str, chunk_size: int, env_options: dict, save_images: bool) -> dict[str, Any]:
    """What a dataset is: written to the manifest and to every chunk."""
    from affordance_env import __version__

    settings = {"seed": int(seed), "action": action, "chunk_size": int(chunk_size),
                "save_images": bool(save_images), "env_options": env_options}
    return {"format": FORMAT, "schema_version": SCHEMA_VERSION, "package_version": __version__,
            "settings": settings, "feature_names": list(FEATURE_NAMES),
            "feature_groups": dict(FEATURE_GROUPS)}


def _flat_settings(description: dict) -> dict[str, Any]:
    settings = description.get("settings")
    settings = dict(settings) if isinstance(settings, dict) else {}
    env_options = settings.pop("env_options", None)
    return {"schema_version": description.get("schema_version"),
            "package_version": description.get("package_version"),
            **settings, **(env_options if isinstance(env_options, dict) else {})}


def _differences(stored: dict, asked: dict) -> list[str]:
    """The settings in which a stored dataset differs from the one asked for, for a person to read."""
    old, new = _flat_settings(stored), _flat_settings(asked)
    return [f"{key}: dataset has {old.get(key)!r}, asked for {value!r}"
            for key, value in new.items() if old.get(key) != value]


@contextlib.contextmanager
def _exclusive(out: Path) -> Iterator[None]:
    """Hold ``out/.lock`` so that two collections never write one dataset (released even on kill -9)."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    with open(out / ".lock", "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise DatasetError(f"another collection is writing to {out} (it holds {out / '.lock'}); wait "
                               "for it to finish or use another --out.") from None
        yield


def _write_manifest(out: Path, header: dict, episodes: int, done: dict[int, tuple[int, dict]]) -> None:
    failures = {k: v for _, chunk_failures in done.values() for k, v in chunk_failures.items()}
    kinds = Counter(reason.split(":", 1)[0] for reason in failures.values())
    n_chunks = len(_chunk_ranges(episodes, header["settings"]["chunk_size"]))
    manifest = {**header, "episodes": episodes, "chunks": n_chunks, "chunks_done": len(done),
                "complete": len(done) == n_chunks, "rows": sum(n - len(f) for n, f in done.values()),
                "failures": {"count": len(failures), "by_kind": dict(sorted(kinds.items())),
                             "episodes": {k: failures[k] for k in sorted(failures, key=int)}}}
    _write_atomically(out / MANIFEST, lambda tmp: tmp.write_text(json.dumps(manifest, indent=1)))


def show_progress(progress: bool | None) -> bool:
    """Whether to draw the progress bar: as asked, or by default on a terminal when ``CI`` is not set."""
    if progress is not None:
        return bool(progress)
    return sys.stderr.isatty() and not os.environ.get("CI")


def collect(
    out: str | os.PathLike,
    episodes: int,
    seed: int = 0,
    workers: int = 1,
    action: str = "canonical",
    env_options: dict[str, Any] | None = None,
    chunk_size: int = 50,
    progress: bool | None = None,
    scheduler: str = "joblib",
    dask_address: str | None = None,
    save_images: bool = False,
) -> Path:
    """Collect ``episodes`` interactions into the dataset directory ``out``, resuming it if it exists.

    Args:
        out: Dataset directory; created if missing. A dataset there made with the same settings is resumed, or
            extended if ``episodes`` is larger; one made with other settings is refused.
        episodes: Number of interactions.
        seed: Seed of the dataset (>= 0); interaction ``i`` depends only on ``(seed, i)``.
        workers: Processes on this machine (joblib), or in the local Dask cluster of ``scheduler="dask"``.
            The data do not depend on it.
        action: ``"canonical"`` (the paper's tap, all zeros) or ``"random"`` (uniform in the action box).
        env_options: Keyword arguments of ``TapAffordance-v0`` (behavior, object_types, size_range,
            camera_width, camera_height, camera_fovy, roll_threshold, settle_timeout); the others keep the
            env's defaults, which are recorded too.
        chunk_size: Interactions per file: the most a crash can lose, per worker.
        progress: Draw a progress bar; by default on a terminal when ``CI`` is not set.
        scheduler: ``"joblib"`` (processes on this machine) or ``"dask"`` (Dask distributed: the cluster at
            ``dask_address``, or a local cluster of ``workers`` processes).
        dask_address: A Dask scheduler (``"tcp://host:8786"``); implies ``scheduler="dask"``. Its workers need
            the same tap-affordance version and must see ``out`` (a shared file system).
        save_images: Also store the initial and final range images (float16) and object masks (bit-packed),
            zstd-compressed; read them with ``load_dataset(out, with_images=True)`` and :func:`images`.

    Returns:
        The dataset directory.
    """
    for name, value, low in (("episodes", episodes, 1), ("workers", workers, 1),
                             ("chunk_size", chunk_size, 1), ("seed", seed, 0)):
        if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < low:
            raise ValueError(f"{name} must be an integer >= {low}, got {value!r}.")
    if action not in ACTIONS:
        raise ValueError(f"action must be one of {ACTIONS}, got {action!r}.")
    if scheduler not in SCHEDULERS:
        raise ValueError(f"scheduler must be one of {SCHEDULERS}, got {scheduler!r}.")
    if dask_address is not None:
        scheduler = "dask"
    options = _full_options(dict(env_options or {}))
    options_json = json.dumps(options, sort_keys=True)
    _worker_env(options_json)  # bad options fail here, clearly, before any work
    if not (scheduler == "joblib" and workers == 1):
        _drop_worker_env(options_json)  # the workers build their own
    header = _header(seed, action, chunk_size, options, save_images)
    out, episodes = Path(out), int(episodes)

    if (out / MANIFEST).exists():
        _check_resumable(out, header, episodes)
    elif out.exists() and (not out.is_dir() or any(p.name != ".lock" for p in out.iterdir())):
        raise DatasetError(f"{out} exists and is not a TapAffordance dataset (no {MANIFEST}); choose an "
                           "empty or new directory.")
    out.mkdir(parents=True, exist_ok=True)
    with _exclusive(out):
        for stale in out.glob(".*.tmp"):  # left by a run that was killed while writing
            stale.unlink(missing_ok=True)
        ranges = _chunk_ranges(episodes, chunk_size)
        done = {}
        for index, (start, stop) in enumerate(ranges):
            meta = _existing_chunk(out / chunk_name(index), header, start, stop)
            if meta is not None:
                done[index] = (stop - start, meta["chunk"]["failures"])
        _write_manifest(out, header, episodes, done)
        tasks = [(str(out), i, start, stop, header)
                 for i, (start, stop) in enumerate(ranges) if i not in done]
        n_failed = sum(len(f) for _, f in done.values())
        from tqdm.auto import tqdm

        with tqdm(total=episodes, initial=sum(n for n, _ in done.values()), unit="interaction", desc=out.name,
                  disable=not show_progress(progress), smoothing=0.05, dynamic_ncols=True) as bar:
            bar.set_postfix(failed=n_failed)
            for index, n, failures in _run(tasks, scheduler, workers, dask_address):
                if not (out / chunk_name(index)).exists():
                    raise DatasetError(f"a worker wrote {chunk_name(index)} where this process cannot see "
                                       f"it: the Dask workers must share {out} with this machine.")
                done[index] = (n, failures)
                _write_manifest(out, header, episodes, done)
                n_failed += len(failures)
                bar.set_postfix(failed=n_failed, refresh=False)
                bar.update(n)
    return out


def _check_resumable(out: Path, header: dict, episodes: int) -> None:
    stored = read_manifest(out)
    diffs = _differences(stored, header)
    if diffs:
        raise DatasetError(f"{out} holds a dataset made with other settings ({'; '.join(diffs)}). Use "
                           "another --out, or the same settings to resume or extend it.")
    if episodes < stored["episodes"]:
        raise DatasetError(f"{out} holds a dataset of {stored['episodes']} interactions, asked for "
                           f"{episodes}: a dataset can be resumed or extended, not shortened; load it and "
                           f"keep the first {episodes} episodes instead.")


def _existing_chunk(path: Path, header: dict, start: int, stop: int) -> dict | None:
    """The metadata of a finished chunk that matches; None if it is missing or must be collected again."""
    if not path.exists():
        return None
    try:
        return _check_chunk(path, header, start, stop)
    except DatasetError as exc:
        with contextlib.suppress(DatasetError, AttributeError, KeyError, TypeError):
            chunk = _chunk_metadata(path)[0]["chunk"]
            if chunk["start"] == start and chunk["stop"] < stop:  # the short last chunk of a grown dataset
                return None
        warnings.warn(f"collecting {path.name} again: {exc}", stacklevel=3)
        return None


def _run(tasks: list[tuple], scheduler: str, workers: int, address: str | None) -> Iterator[tuple]:
    """Run chunk tasks, yielding ``(index, n, failures)`` as each chunk is written."""
    if not tasks:
        return
    if scheduler == "dask":
        yield from _run_dask(tasks, workers, address)
    elif workers == 1:
        for task in tasks:
            yield _collect_chunk(*task)
    else:
        from joblib import Parallel, delayed

        yield from Parallel(n_jobs=workers, return_as="generator_unordered", batch_size=1)(
            delayed(_collect_chunk)(*task) for task in tasks
        )


def _run_dask(tasks: list[tuple], workers: int, address: str | None) -> Iterator[tuple]:
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError as exc:
        raise ImportError("scheduler='dask' needs Dask distributed: pip install 'tap-affordance[dask]'"
                          ) from exc
    with contextlib.ExitStack() as stack:
        if address is None:
            address = stack.enter_context(
                LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
            )
        client = stack.enter_context(Client(address))
        futures = [client.submit(_collect_chunk, *task, pure=False, retries=1) for task in tasks]
        for future in as_completed(futures):
            yield future.result()
            future.release()


# --- reading ---------------------------------------------------------------------------------------------
def read_manifest(path: str | os.PathLike) -> dict[str, Any]:
    """The manifest of the dataset directory ``path``, checked for format and schema version."""
    path = Path(path)
    try:
        manifest = json.loads((path / MANIFEST).read_text())
    except FileNotFoundError:
        raise
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DatasetError(f"{path / MANIFEST} is not a readable TapAffordance manifest ({exc}).") from exc
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise DatasetError(f"{path} is not a TapAffordance dataset (its {MANIFEST} has no format "
                           f"{FORMAT!r}).")
    version = manifest.get("schema_version")
    if not isinstance(version, int) or isinstance(version, bool) or not 1 <= version <= SCHEMA_VERSION:
        raise DatasetError(f"{path} has dataset schema version {version!r}; this tap-affordance reads "
                           f"versions 1 to {SCHEMA_VERSION}: upgrade the package "
                           "(pip install -U tap-affordance).")
    settings = manifest.get("settings")
    chunk_size = settings.get("chunk_size") if isinstance(settings, dict) else None
    if not isinstance(manifest.get("episodes"), int) or not isinstance(chunk_size, int) or chunk_size < 1:
        raise DatasetError(f"{path / MANIFEST} is damaged: episodes {manifest.get('episodes')!r}, "
                           f"chunk_size {chunk_size!r}.")
    return manifest


def _chunk_metadata(path: Path) -> tuple[dict, int]:
    """The ``tap_affordance`` metadata and the row count of a chunk file."""
    try:
        parquet = pq.read_metadata(path)
    except Exception as exc:  # pyarrow raises several types for damaged files
        raise DatasetError(f"{path} is corrupt or not a Parquet file ({exc}).") from exc
    raw = (parquet.metadata or {}).get(METADATA_KEY)
    if raw is None:
        raise DatasetError(f"{path} is a Parquet file but not a TapAffordance dataset chunk (no "
                           f"{METADATA_KEY.decode()!r} entry in its metadata).")
    try:
        meta = json.loads(raw)
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DatasetError(f"{path} is corrupt: its {METADATA_KEY.decode()!r} metadata is not JSON.") from exc
    if not isinstance(meta, dict):
        raise DatasetError(f"{path} is corrupt: its {METADATA_KEY.decode()!r} metadata is not an object.")
    return meta, parquet.num_rows


def _check_chunk(path: Path, header: dict, start: int, stop: int) -> dict:
    """A chunk's metadata, once checked to be chunk ``start .. stop-1`` of the dataset ``header``."""
    meta, rows = _chunk_metadata(path)
    chunk = meta.get("chunk")
    span = (chunk.get("start"), chunk.get("stop")) if isinstance(chunk, dict) else None
    if span != (start, stop) or not isinstance(chunk.get("failures"), dict):
        raise DatasetError(f"{path} holds episodes {span}, expected ({start}, {stop}).")
    diffs = _differences(meta, header)
    if diffs:
        raise DatasetError(f"{path} was made with other settings than its dataset ({'; '.join(diffs)}).")
    if rows + len(chunk["failures"]) != stop - start:
        raise DatasetError(f"{path} is inconsistent: {rows} rows and {len(chunk['failures'])} failures for "
                           f"{stop - start} interactions.")
    return meta


def load_dataset(path: str | os.PathLike, *, with_images: bool = False, allow_incomplete: bool = False
                 ) -> pd.DataFrame:
    """Read a dataset directory into a DataFrame, one row per interaction, ordered by episode.

    Columns (:func:`arrow_schema`): ``episode`` (index i), ``seed`` (env seed of interaction i), ``behavior``,
    ``type``, ``size`` [m], ``action_0..2``, ``initial_x, _y, _z, _qw, _qx, _qy, _qz`` and ``final_...``
    (object position [m] and quaternion), ``displacement`` [m], ``rolling_distance`` [m], ``rolled``, ``tilt``
    [rad], ``toppled``, ``outcome``, ``outcome_time`` [s] (see the environment's ``info``; datasets of schema
    version 2 and older lack ``rolling_distance``, ``tilt``, ``toppled`` and ``outcome_time``), ``contact``,
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
            _chunk_metadata(path)
        except DatasetError as exc:
            raise DatasetError(f"{path} is not a TapAffordance dataset: {exc}") from None
        raise DatasetError(f"{path} is one chunk of a dataset: load its directory, {path.parent}.")
    if not path.is_dir() or not (path / MANIFEST).is_file():
        raise DatasetError(f"{path} is not a TapAffordance dataset (a directory with {MANIFEST}); make one "
                           "with `affordance collect`.")
    manifest = read_manifest(path)
    version = manifest["schema_version"]
    tables, failures, missing = [], {}, []
    ranges = _chunk_ranges(manifest["episodes"], manifest["settings"]["chunk_size"])
    for index, (start, stop) in enumerate(ranges):
        chunk = path / chunk_name(index)
        if not chunk.exists():
            missing.append(chunk.name)
            continue
        try:
            if version >= 2:
                failures.update(_check_chunk(chunk, manifest, start, stop)["chunk"]["failures"])
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
    frame.attrs["manifest"] = manifest
    frame.attrs["failures"] = {int(k): v for k, v in sorted(failures.items(), key=lambda kv: int(kv[0]))}
    return frame
