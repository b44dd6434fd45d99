"""Datasets of interactions: collected in parallel, deterministically and resumably; read back as a DataFrame.

On disk a dataset is a directory::

    manifest.json          what the dataset is: settings, package version, feature names and groups, schema
                           version, progress, and the failed interactions (count, kinds, episode -> reason)
    chunk-00000.parquet    interactions 0 .. chunk_size-1, one row each (:func:`arrow_schema`), zstd
    chunk-00001.parquet    ...

Every chunk also carries the dataset's description in its Parquet key-value metadata (key ``tap_affordance``),
with its own episode range and failures, so that a chunk is self-describing and can be checked on its own.

Interaction ``i`` depends only on ``(seed, i)``: its environment seed is ``SeedSequence([seed, i])`` and its
random action (``action="random"``) comes from ``SeedSequence([seed, i, 1])``; the dataset is the same whatever
the number of workers or the scheduler. A chunk is written to a temporary name and renamed when complete, so a
crash or ``kill -9`` leaves only whole chunks, and running the same command again collects just the missing
ones. An interaction that raises, returns non-finite numbers or that the environment marks as failed
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
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pyarrow as pa
import pyarrow.parquet as pq

from affordance_env.behaviors import ACTION_DIM
from affordance_env.features import FEATURE_GROUPS, FEATURE_NAMES

#: Version of the on-disk format; :func:`load_dataset` reads versions up to this one.
SCHEMA_VERSION = 2
FORMAT = "tap-affordance-dataset"
MANIFEST = "manifest.json"
METADATA_KEY = b"tap_affordance"
ACTIONS = ("canonical", "random")
SCHEDULERS = ("joblib", "dask")
POSE_FIELDS = ("x", "y", "z", "qw", "qx", "qy", "qz")
IMAGE_COLUMNS = ("initial_range", "initial_mask", "final_range", "final_mask")
#: Env arguments that a dataset cannot record or that do not change the data.
_NOT_COLLECTED = ("self", "reward_fn", "render_mode", "render_width", "render_height")


class DatasetError(ValueError):
    """A dataset that cannot be read or extended, with the reason."""


# --- schema -----------------------------------------------------------------------------------------------------
def arrow_schema(save_images: bool = False) -> pa.Schema:
    """The columns of every chunk, in order: bookkeeping, action, ground truth, the 3 x 49 features, images."""
    fields = [("episode", pa.int64()), ("seed", pa.int64()), ("behavior", pa.string()), ("type", pa.string()),
              ("size", pa.float64())]
    fields += [(f"action_{j}", pa.float32()) for j in range(ACTION_DIM)]
    fields += [(f"{stage}_{f}", pa.float64()) for stage in ("initial", "final") for f in POSE_FIELDS]
    fields += [("displacement", pa.float64()), ("rolled", pa.bool_()), ("outcome", pa.string()),
               ("contact", pa.bool_()), ("hand_speed", pa.float64()), ("visible_initial", pa.bool_()),
               ("visible_final", pa.bool_()), ("ik_success", pa.bool_())]
    fields += [(f"{stage}_{n}", pa.float64()) for stage in ("initial", "final", "effect") for n in FEATURE_NAMES]
    if save_images:
        fields += [(column, pa.binary()) for column in IMAGE_COLUMNS]
    return pa.schema(fields)


def interaction_seed(seed: int, episode: int) -> int:
    """Environment seed of interaction ``episode`` of a dataset collected with ``seed``."""
    return int(np.random.SeedSequence([seed, episode]).generate_state(1)[0])


def interaction_action(seed: int, episode: int, action: str) -> np.ndarray:
    """Action of interaction ``episode``: zeros (the canonical tap) or uniform in [-1, 1]^3 from ``(seed, i)``."""
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
        column: ``initial_range``, ``final_range`` (distance along each pixel's ray [m], float16 on disk, so
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
    if len(frame) == 0:
        return np.zeros((0, *shape), np.float32 if column.endswith("range") else bool)
    if column.endswith("range"):
        return np.stack([np.frombuffer(b, np.float16).reshape(shape).astype(np.float32) for b in frame[column]])
    n = shape[0] * shape[1]
    return np.stack([np.unpackbits(np.frombuffer(b, np.uint8))[:n].reshape(shape).astype(bool)
                     for b in frame[column]])


# --- one worker: interactions -> one chunk file -------------------------------------------------------------------
_worker = threading.local()  # per worker thread: {options_json: env}; building an env takes about a second


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
    row.update(displacement=float(info["displacement"]), rolled=bool(info["rolled"]), outcome=info["outcome"],
               contact=bool(info["contact"]), hand_speed=float(info["hand_speed"]),
               visible_initial=bool(reset_info["visible"]), visible_final=bool(info["visible"]),
               ik_success=bool(info["ik"]["success"]))
    for stage, values in (("initial", info["initial_features"]), ("final", info["final_features"]),
                          ("effect", info["effect"])):
        row.update({f"{stage}_{n}": float(v) for n, v in zip(FEATURE_NAMES, values, strict=True)})
    return row


def _interaction(env, seed: int, episode: int, action: str, save_images: bool) -> dict[str, Any] | str:
    """One interaction as a row, or the reason it is not one."""
    env_seed = interaction_seed(seed, episode)
    act = interaction_action(seed, episode, action)
    obs_initial, reset_info = env.reset(seed=env_seed)
    obs_final, _, _, _, info = env.step(act)
    if info["failure"] is not None:
        return info["failure"]
    row = _record(episode, env_seed, act, reset_info, info)
    bad = [k for k, v in row.items() if isinstance(v, float | np.floating) and not np.isfinite(v)]
    if bad:
        return f"non-finite: {len(bad)} non-finite value(s) in the record, e.g. {bad[:3]}"
    if save_images:
        for stage, obs in (("initial", obs_initial), ("final", obs_final)):
            row[f"{stage}_range"] = obs["range"].astype(np.float16).tobytes()
            row[f"{stage}_mask"] = np.packbits(obs["mask"].astype(bool)).tobytes()
    return row


def _collect_chunk(out: str, index: int, start: int, stop: int, header: dict) -> tuple[int, int, dict[str, str]]:
    """Run interactions ``start .. stop-1`` and write them as chunk ``index``; returns (index, n, failures)."""
    from affordance_env import __version__

    if __version__ != header["package_version"]:
        raise RuntimeError(f"this worker has tap-affordance {__version__}, the dataset is collected with "
                           f"{header['package_version']}: install the same version on every worker.")
    settings = header["settings"]
    options_json = json.dumps(settings["env_options"], sort_keys=True)
    save_images = settings["save_images"]
    schema = arrow_schema(save_images)
    columns: dict[str, list] = {name: [] for name in schema.names}
    failures: dict[str, str] = {}
    for episode in range(start, stop):
        env = _worker_env(options_json)  # an env that cannot be built stops the collection: not a failed interaction
        try:
            result = _interaction(env, settings["seed"], episode, settings["action"], save_images)
        except Exception as exc:  # a crashing interaction is reported, never written nor fatal to the dataset
            _drop_worker_env(options_json)
            result = f"exception: {type(exc).__name__}: {exc}"
        if isinstance(result, str):
            failures[str(episode)] = result
            continue
        for name in schema.names:
            columns[name].append(result[name])
    chunk_meta = {**header, "chunk": {"index": index, "start": start, "stop": stop, "failures": failures}}
    table = pa.Table.from_pydict(columns, schema=schema.with_metadata({METADATA_KEY: json.dumps(chunk_meta)}))
    _write_atomically(Path(out) / chunk_name(index), lambda tmp: pq.write_table(table, tmp, compression="zstd"))
    return index, stop - start, failures


def _write_atomically(path: Path, write) -> None:
    """``write(tmp)`` to a unique temporary name beside ``path``, flush it to disk, then rename it to ``path``."""
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        write(tmp)
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
    with contextlib.suppress(OSError):  # make the rename itself durable (not possible on every file system)
        fd = os.open(path.parent, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def chunk_name(index: int) -> str:
    return f"chunk-{index:05d}.parquet"


def _chunk_ranges(episodes: int, chunk_size: int) -> list[tuple[int, int]]:
    return [(s, min(s + chunk_size, episodes)) for s in range(0, episodes, chunk_size)]


# --- the coordinator ------------------------------------------------------------------------------------------------
def _full_options(env_options: dict[str, Any]) -> dict[str, Any]:
    """The env options with every default filled in, as JSON values, so equal settings compare equal."""
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
    from affordance_env import __version__

    settings = {"seed": int(seed), "action": action, "chunk_size": int(chunk_size), "save_images": bool(save_images),
                "env_options": env_options}
    return {"format": FORMAT, "schema_version": SCHEMA_VERSION, "package_version": __version__,
            "settings": settings, "feature_names": list(FEATURE_NAMES), "feature_groups": dict(FEATURE_GROUPS)}


def _differences(stored: dict, header: dict) -> list[str]:
    """What differs between a stored dataset's description and the one asked for, for a person to read."""
    diffs = []
    if stored.get("schema_version") != header["schema_version"]:
        diffs.append(f"schema_version: dataset has {stored.get('schema_version')!r}, "
                     f"this tap-affordance writes {header['schema_version']!r}")
    if stored.get("package_version") != header["package_version"]:
        diffs.append(f"package_version: dataset has {stored.get('package_version')!r}, "
                     f"this is {header['package_version']!r}")
    old, new = stored.get("settings", {}), header["settings"]
    for key in new:
        if key == "env_options":
            for name in new[key]:
                if old.get(key, {}).get(name) != new[key][name]:
                    diffs.append(f"{name}: dataset has {old.get(key, {}).get(name)!r}, asked for {new[key][name]!r}")
        elif old.get(key) != new[key]:
            diffs.append(f"{key}: dataset has {old.get(key)!r}, asked for {new[key]!r}")
    return diffs


@contextlib.contextmanager
def _exclusive(out: Path) -> Iterator[None]:
    """Hold ``out/.lock`` so that two collections never write the same dataset (released even on kill -9)."""
    try:
        import fcntl
    except ImportError:  # not POSIX: no lock
        yield
        return
    with open(out / ".lock", "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise DatasetError(f"another collection is writing to {out} (it holds {out / '.lock'}); wait for it "
                               "to finish or use another --out.") from None
        yield


def _summary(failures: dict[str, str]) -> dict[str, Any]:
    kinds: dict[str, int] = {}
    for reason in failures.values():
        kind = reason.split(":", 1)[0]
        kinds[kind] = kinds.get(kind, 0) + 1
    return {"count": len(failures), "by_kind": dict(sorted(kinds.items())),
            "episodes": {k: failures[k] for k in sorted(failures, key=int)}}


def _write_manifest(out: Path, header: dict, episodes: int, done: dict[int, tuple[int, dict]]) -> None:
    failures = {k: v for _, chunk_failures in done.values() for k, v in chunk_failures.items()}
    n_chunks = len(_chunk_ranges(episodes, header["settings"]["chunk_size"]))
    manifest = {**header, "episodes": episodes, "chunks": n_chunks, "chunks_done": len(done),
                "complete": len(done) == n_chunks, "rows": sum(n - len(f) for n, f in done.values()),
                "failures": _summary(failures)}
    _write_atomically(out / MANIFEST, lambda tmp: tmp.write_text(json.dumps(manifest, indent=1)))


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
        out: Dataset directory; created if missing. An existing dataset made with the same settings is resumed
            (or extended, if ``episodes`` is larger); one made with other settings is refused.
        episodes: Number of interactions.
        seed: Seed of the dataset (>= 0); interaction ``i`` depends only on ``(seed, i)``.
        workers: Worker processes on this machine (joblib), or of the local Dask cluster started with
            ``scheduler="dask"``. The data do not depend on it.
        action: ``"canonical"`` (the paper's tap, all zeros) or ``"random"`` (uniform in the action box).
        env_options: Keyword arguments of ``TapAffordance-v0`` (behavior, object_types, size_range, camera_width,
            camera_height, camera_fovy, roll_threshold, settle_timeout); missing ones take the env's defaults.
        chunk_size: Interactions per file: the most a crash can lose, per worker.
        progress: Show a progress bar; default: when stderr is a terminal and ``CI`` is not set.
        scheduler: ``"joblib"`` (processes on this machine) or ``"dask"`` (Dask distributed: the cluster at
            ``dask_address``, or a local one of ``workers`` processes).
        dask_address: Address of a Dask scheduler (``"tcp://host:8786"``); implies ``scheduler="dask"``. Its
            workers need the same tap-affordance version and must see ``out`` (a shared file system).
        save_images: Also store the initial and final range images (float16) and object masks (bit-packed), zstd
            compressed; load them with ``load_dataset(out, with_images=True)`` and decode with :func:`images`.

    Returns:
        The dataset directory.
    """
    for name, value, low in (("episodes", episodes, 1), ("workers", workers, 1), ("chunk_size", chunk_size, 1),
                             ("seed", seed, 0)):
        if isinstance(value, bool) or not isinstance(value, int | np.integer) or value < low:
            raise ValueError(f"{name} must be an integer >= {low}, got {value!r}.")
    if action not in ACTIONS:
        raise ValueError(f"action must be one of {ACTIONS}, got {action!r}.")
    if scheduler not in SCHEDULERS:
        raise ValueError(f"scheduler must be one of {SCHEDULERS}, got {scheduler!r}.")
    if dask_address is not None and scheduler != "dask":
        if scheduler != "joblib":
            raise ValueError(f"dask_address needs scheduler='dask', got {scheduler!r}.")
        scheduler = "dask"
    options = _full_options(dict(env_options or {}))
    options_json = json.dumps(options, sort_keys=True)
    _worker_env(options_json)  # bad options fail here, clearly, before any work
    if not (scheduler == "joblib" and workers == 1):
        _drop_worker_env(options_json)  # the workers build their own
    header = _header(seed, action, chunk_size, options, save_images)
    out = Path(out)
    episodes = int(episodes)

    if (out / MANIFEST).exists():
        _check_resumable(out, header, episodes)
    elif out.exists() and (not out.is_dir() or any(p.name != ".lock" for p in out.iterdir())):
        raise DatasetError(f"{out} exists and is not a TapAffordance dataset (no {MANIFEST}); choose an empty or "
                           "new directory.")
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
        todo = [(index, start, stop) for index, (start, stop) in enumerate(ranges) if index not in done]
        from tqdm.auto import tqdm

        n_failed = sum(len(f) for _, f in done.values())
        with tqdm(total=episodes, initial=sum(n for n, _ in done.values()), unit="interaction",
                  disable=not show_progress(progress), desc=out.name, smoothing=0.05, dynamic_ncols=True) as bar:
            bar.set_postfix(failed=n_failed)
            tasks = [(str(out), index, start, stop, header) for index, start, stop in todo]
            for index, n, failures in _run(tasks, scheduler, workers, dask_address):
                done[index] = (n, failures)
                _write_manifest(out, header, episodes, done)
                n_failed += len(failures)
                bar.set_postfix(failed=n_failed, refresh=False)
                bar.update(n)
    return out


def show_progress(progress: bool | None) -> bool:
    """Whether to draw the progress bar: as asked, or by default on a terminal unless ``CI`` is set."""
    if progress is not None:
        return bool(progress)
    return sys.stderr.isatty() and not os.environ.get("CI")


def _check_resumable(out: Path, header: dict, episodes: int) -> None:
    stored = read_manifest(out)
    diffs = _differences(stored, header)
    if diffs:
        raise DatasetError(f"{out} holds a dataset made with other settings ({'; '.join(diffs)}). Use another "
                           "--out, or the same settings to resume or extend it.")
    if episodes < int(stored["episodes"]):
        raise DatasetError(f"{out} holds a dataset of {stored['episodes']} interactions, asked for {episodes}: "
                           "a dataset can be resumed or extended, not shortened; load it and take the first "
                           f"{episodes} episodes instead.")


def _existing_chunk(path: Path, header: dict, start: int, stop: int) -> dict | None:
    """The metadata of a finished chunk that matches; None if it is missing or must be collected again."""
    if not path.exists():
        return None
    try:
        return _check_chunk(path, header, start, stop)
    except DatasetError as exc:
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
        raise ImportError("scheduler='dask' needs Dask distributed: pip install 'tap-affordance[dask]'") from exc
    with contextlib.ExitStack() as stack:
        if address is None:
            address = stack.enter_context(LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                                       dashboard_address=None))
        client = stack.enter_context(Client(address))
        futures = [client.submit(_collect_chunk, *task, pure=False, retries=1) for task in tasks]
        for future in as_completed(futures):
            yield future.result()
            future.release()


# --- reading --------------------------------------------------------------------------------------------------------
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
        raise DatasetError(f"{path} is not a TapAffordance dataset (its {MANIFEST} has no format {FORMAT!r}).")
    version = manifest.get("schema_version")
    if not isinstance(version, int) or isinstance(version, bool) or not 1 <= version <= SCHEMA_VERSION:
        raise DatasetError(f"{path} has dataset schema version {version!r}; this tap-affordance reads versions 1 "
                           f"to {SCHEMA_VERSION}: upgrade the package (pip install -U tap-affordance).")
    for key, kind in (("episodes", int), ("settings", dict)):
        if not isinstance(manifest.get(key), kind):
            raise DatasetError(f"{path / MANIFEST} is damaged: {key!r} is {manifest.get(key)!r}.")
    if not isinstance(manifest["settings"].get("chunk_size"), int) or manifest["settings"]["chunk_size"] < 1:
        raise DatasetError(f"{path / MANIFEST} is damaged: chunk_size is {manifest['settings'].get('chunk_size')!r}.")
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
    return meta, parquet.num_rows


def _check_chunk(path: Path, header: dict, start: int, stop: int) -> dict:
    """A chunk's metadata, after checking that it is chunk ``start .. stop-1`` of the dataset ``header``."""
    meta, rows = _chunk_metadata(path)
    chunk = meta.get("chunk") if isinstance(meta, dict) else None
    if not isinstance(chunk, dict) or (chunk.get("start"), chunk.get("stop")) != (start, stop):
        got = (chunk.get("start"), chunk.get("stop")) if isinstance(chunk, dict) else None
        raise DatasetError(f"{path} holds episodes {got}, expected [{start}, {stop}).")
    diffs = _differences(meta, header)
    if diffs:
        raise DatasetError(f"{path} was made with other settings than its dataset ({'; '.join(diffs)}).")
    if rows + len(chunk.get("failures", {})) != stop - start:
        raise DatasetError(f"{path} is inconsistent: {rows} rows and {len(chunk['failures'])} failures for "
                           f"{stop - start} interactions.")
    return meta


def _schema_1_frame(frame: pd.DataFrame) -> pd.DataFrame:
    """Datasets of schema version 1 named the poses ``object_initial_x``...: rename to ``initial_x``..."""
    return frame.rename(columns={f"object_{stage}_{f}": f"{stage}_{f}"
                                 for stage in ("initial", "final") for f in POSE_FIELDS})


def load_dataset(path: str | os.PathLike, *, with_images: bool = False, allow_incomplete: bool = False
                 ) -> pd.DataFrame:
    """Read a dataset directory into a DataFrame, one row per interaction, ordered by episode.

    Columns (:func:`arrow_schema`): ``episode`` (index i), ``seed`` (env seed of interaction i), ``behavior``,
    ``type``, ``size`` [m], ``action_0..2``, ``initial_x, _y, _z, _qw, _qx, _qy, _qz`` and ``final_...`` (object
    position [m] and quaternion), ``displacement`` [m], ``rolled``, ``outcome``, ``contact``, ``hand_speed``
    [m/s], ``visible_initial``, ``visible_final``, ``ik_success``, and ``initial_<f>``, ``final_<f>``,
    ``effect_<f>`` for every name ``f`` of ``FEATURE_NAMES``; with ``with_images`` also the encoded images
    (decode with :func:`images`). ``frame.attrs["manifest"]`` holds the manifest and
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
        raise DatasetError(f"{path} is not a TapAffordance dataset (a directory with {MANIFEST}); make one with "
                           "`affordance collect`.")
    manifest = read_manifest(path)
    settings = manifest["settings"]
    version = manifest["schema_version"]
    header = {k: manifest.get(k) for k in ("schema_version", "package_version", "settings")}
    frames, failures, missing = [], {}, []
    for index, (start, stop) in enumerate(_chunk_ranges(manifest["episodes"], settings["chunk_size"])):
        chunk = path / chunk_name(index)
        if not chunk.exists():
            missing.append(chunk.name)
            continue
        try:
            if version >= 2:
                failures.update(_check_chunk(chunk, header, start, stop)["chunk"]["failures"])
            table = pq.read_table(chunk)
        except DatasetError as exc:
            raise DatasetError(f"{exc} Delete {chunk.name} and rerun the same collect command to redo it.") from exc
        except Exception as exc:  # pyarrow raises several types for damaged files
            raise DatasetError(f"{chunk} is corrupt ({exc}); delete it and rerun the same collect command to redo "
                               "it.") from exc
        if version == 1:
            failures.update(json.loads((table.schema.metadata or {}).get(b"tap_affordance_failures", b"{}")))
        if not with_images:
            table = table.drop_columns([c for c in IMAGE_COLUMNS if c in table.column_names])
        frames.append(table.to_pandas())
    if missing and not allow_incomplete:
        raise DatasetError(f"{path} is incomplete: {len(missing)} chunk(s) missing ({', '.join(missing[:3])}"
                           f"{', ...' if len(missing) > 3 else ''}); rerun the same collect command to finish it, "
                           "or pass allow_incomplete=True.")
    if frames:
        frame = pd.concat(frames, ignore_index=True)
    else:
        frame = arrow_schema(with_images and settings.get("save_images", False)).empty_table().to_pandas()
    if version == 1:
        frame = _schema_1_frame(frame)
    frame.attrs["manifest"] = manifest
    frame.attrs["failures"] = {int(k): v for k, v in sorted(failures.items(), key=lambda kv: int(kv[0]))}
    return frame

