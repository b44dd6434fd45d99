"""Collecting a dataset: interactions run in parallel, deterministically and resumably, into chunk files.

Interaction ``i`` depends only on ``(seed, i)``: its environment seed comes from ``SeedSequence([seed, i])``
and its random action (``action="random"``) from ``SeedSequence([seed, i, 1])``, so the data are the same
whatever the workers or the scheduler. A chunk is written to a temporary name and renamed when complete: a
crash or ``kill -9`` leaves only whole chunks, and the same command collects just the missing ones.

An interaction that the environment marks as failed (``info["failure"]``: an unreachable stroke, a missed tap,
a physics fault) is not written; its episode and reason go to the chunk's metadata and the manifest. Anything
else that goes wrong (an exception from ``reset`` or ``step``, a record with non-finite numbers) is a bug: it
stops the collection with its traceback, and the chunks already written stay. A goal episode never runs an action
that ``feasible`` refuses: where no feasible action is drawn, or the head does not see the object (hidden behind an
arm, or out of every view of the head: its interaction would fail), the episode ends there, truncated (its reason
in the chunk's metadata: ``"truncated"``: episode -> ``"infeasible: ..."`` or ``"lost: ..."``), keeps its rows and is
no failure; an episode is recorded up to its first failed interaction (left out; the episode counts as failed).
When more than
``max_failure_share`` of the interactions collected so far have failed, the collection stops with
:class:`FailureShareError`, which lists the reasons: rerun with a larger share to accept them.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import signal
import sys
import warnings
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from affordance_env.behaviors import ACTION_DIM
from affordance_env.dataset.format import (
    CHECKSUMS,
    ENV_IDS,
    GOAL_ENV_ID,
    IMAGE_COLUMNS,
    MANIFEST,
    MAX_EPISODES,
    METADATA_KEY,
    ChunkResult,
    DatasetError,
    GoalStep,
    arrow_schema,
    check_chunk,
    chunk_metadata,
    chunk_name,
    chunk_ranges,
    dataset_header,
    file_sha256,
    interaction_row,
    is_goal_dataset,
    read_manifest,
    settings_differences,
    write_atomically,
    write_manifest,
)
from affordance_env.exceptions import InvalidValueError, MissingDependencyError
from affordance_env.options import EnvOptions
from affordance_env.progress import progress_bar, show_progress  # noqa: F401  (show_progress: re-exported)
from affordance_env.registry import BEHAVIOR_NAMES
from affordance_env.values import check_dask_address, is_integer
from affordance_env.workers import worker_env

ACTIONS = ("canonical", "random")
SCHEDULERS = ("joblib", "dask")


def interaction_seed(seed: int, episode: int) -> int:
    """Environment seed of interaction ``episode`` of a dataset collected with ``seed``."""
    return int(np.random.SeedSequence([seed, episode]).generate_state(1)[0])


def interaction_action(seed: int, episode: int, action: str) -> np.ndarray:
    """Action of interaction ``episode``: zeros (canonical tap) or uniform in [-1, 1]^3 by (seed, i)."""
    if action == "canonical":
        return np.zeros(ACTION_DIM, dtype=np.float32)
    if action != "random":
        raise InvalidValueError(f"action must be one of {ACTIONS}, got {action!r}.")
    rng = np.random.default_rng(np.random.SeedSequence([seed, episode, 1]))
    return rng.uniform(-1.0, 1.0, ACTION_DIM).astype(np.float32)


#: A goal episode's step draws, for each behaviour, up to this many parameter vectors until the arm can reach one
#: (``feasible``; :func:`goal_step_actions`).
PARAM_DRAWS = 10
#: How goal episodes are collected, recorded in the settings of every goal dataset (a dataset collected otherwise
#: is not resumed with it): only feasible actions are run; an episode ends where none is drawn or the head does
#: not see the object. What ``feasible`` checks is part of the rule: since it checks the end of a pick and place's
#: carry where the held object will hang, a dataset whose grasps it chose before is not resumed.
GOAL_EPISODE_RULE = (f"feasible actions only (a pick and place's carry checked where the object hangs, a reach "
                     f"kept 2 mm from the object), the "
                     f"behaviours in a random order, {PARAM_DRAWS} draws each per step; truncated where none is or the "
                     "object is not seen")


def goal_step_actions(seed: int, episode: int, step: int, action: str) -> Iterator[dict[str, Any]]:
    """The actions drawn for step ``step`` of goal episode ``episode``, in the order they are tried: the behaviours
    (:data:`~affordance_env.registry.BEHAVIOR_NAMES`) in a random order, each with ``PARAM_DRAWS`` parameter
    vectors, zeros (``"canonical"``) or uniform in [-1, 1]^3, all from ``SeedSequence([seed, episode, 1, step])``.

    The collector runs the first feasible one: every behaviour is tried before a step is given up, and each is the
    first tried as often as the others, so that a behaviour whose parameters are rarely feasible where the object
    is (the grasp, the push, the draw far from the robot) still gets its share of the interactions."""
    if action not in ACTIONS:
        raise InvalidValueError(f"action must be one of {ACTIONS}, got {action!r}.")
    rng = np.random.default_rng(np.random.SeedSequence([seed, episode, 1, step]))
    for behavior in rng.permutation(len(BEHAVIOR_NAMES)):
        for _ in range(PARAM_DRAWS):
            params = rng.uniform(-1.0, 1.0, ACTION_DIM).astype(np.float32)
            yield {"behavior": int(behavior),
                   "params": params if action == "random" else np.zeros(ACTION_DIM, np.float32)}


# --- a worker: interactions -> one chunk file --------------------------------------------------------------
def _goal_episode_rows(env, settings: dict, episode: int) -> tuple[list[dict], str | None, str | None]:
    """The rows of goal episode ``episode`` (one per interaction, until the episode ends), the reason of its failed
    interaction (the last one run, left out), or None, and why the episode was cut short (truncated), or None.

    Only actions that ``env.feasible`` accepts are run: at each step the actions of :func:`goal_step_actions` are
    drawn, the first feasible one is run, and an episode where none is ends before that step
    (``"infeasible: ..."``). An
    episode whose object the head does not see ends there too (``"lost: ..."``): its next interaction would fail."""
    from affordance_env.registration import GOAL_MAX_EPISODE_STEPS

    env_seed = interaction_seed(settings["seed"], episode)
    visible = env.reset(seed=env_seed)[1]["visible"]
    rows: list[dict] = []
    for step in range(GOAL_MAX_EPISODE_STEPS):
        if not visible:  # hidden behind an arm, or out of every view of the head
            return rows, None, f"lost: the head did not find the object for step {step}"
        actions = goal_step_actions(settings["seed"], episode, step, settings["action"])
        action = next((a for a in actions if env.feasible(a["behavior"], a["params"])), None)
        if action is None:
            return rows, None, (f"infeasible: none of the {PARAM_DRAWS} actions drawn for each behaviour for step "
                                f"{step} is feasible")
        obs, _, terminated, _, info = env.step(action)
        result = env.last_result
        if result.failure is not None:
            return rows, f"{result.failure} (at step {step})", None
        goal = GoalStep(step, obs["desired_goal"], obs["achieved_goal"], info["distance"], info["is_success"])
        rows.append(interaction_row(episode, env_seed, result, settings["save_images"], goal))
        if terminated:  # the goal reached, or the object left the table
            break
        # the next interaction starts from the observation the head took after this one
        visible = info["observation_visible"]
    return rows, None, None


def _collect_chunk(out: str, index: int, start: int, stop: int, header: dict) -> ChunkResult:
    """Run episodes ``start .. stop-1``, write them as chunk ``index``, and return what it holds."""
    from affordance_env import __version__

    if __version__ != header["package_version"]:
        raise RuntimeError(f"this worker has tap-affordance {__version__}, the dataset is collected with "
                           f"{header['package_version']}: install the same version on every worker.")
    settings = header["settings"]
    options_json = json.dumps(settings["env_options"], sort_keys=True)
    goal = is_goal_dataset(header)
    schema = arrow_schema(settings["save_images"], goal=goal)
    columns: dict[str, list] = {name: [] for name in schema.names}
    failures: dict[str, str] = {}
    truncated: dict[str, str] = {}  # goal episodes cut short, and why
    for episode in range(start, stop):
        # an env that cannot be built stops the run: not a failed interaction
        env = worker_env(settings.get("env_id", ENV_IDS[0]), options_json)
        if goal:
            rows, failure, truncation = _goal_episode_rows(env, settings, episode)
            if failure is not None:
                failures[str(episode)] = failure
            if truncation is not None:
                truncated[str(episode)] = truncation
            for row in rows:
                for name in schema.names:
                    columns[name].append(row[name])
            continue
        env_seed = interaction_seed(settings["seed"], episode)
        action = interaction_action(settings["seed"], episode, settings["action"])
        # An exception here is a bug, not a failed interaction (the env reports those in info["failure"]): it
        # stops the collection with its traceback; the chunks already written stay.
        env.reset(seed=env_seed)
        env.step(action)
        result = env.last_result
        if result.failure is not None:
            failures[str(episode)] = result.failure
            continue
        row = interaction_row(episode, env_seed, result, settings["save_images"])
        for name in schema.names:
            columns[name].append(row[name])
    chunk = ChunkResult(index, start, stop, failures, len(columns["episode"]), truncated=truncated if goal else None)
    meta = {**header, "chunk": chunk.metadata()}
    table = pa.Table.from_pydict(columns, schema=schema.with_metadata({METADATA_KEY: json.dumps(meta)}))
    # zstd for the images (small); snappy for the numbers: zstd saves little there and reads twice as slowly
    codecs = {name: "zstd" if name in IMAGE_COLUMNS else "snappy" for name in schema.names}
    digest = []

    def write(tmp: Path) -> None:
        pq.write_table(table, tmp, compression=codecs)
        digest.append(file_sha256(tmp))  # of the bytes written, before anything else can touch them

    write_atomically(Path(out) / chunk_name(index), write)
    return dataclasses.replace(chunk, sha256=digest[0])


# --- the coordinator -------------------------------------------------------------------------------------
def _full_options(env_options: dict[str, Any], env_id: str = ENV_IDS[0]) -> dict[str, Any]:
    """The env options with every default filled in, as JSON values, so that equal settings compare equal;
    checked (:class:`~affordance_env.options.EnvOptions`) without building an env or importing the simulator.
    TapAffordanceGoal-v2 chooses the behaviour at every step and always has both arms: it has no ``behavior`` and
    no ``two_arms`` option."""
    if env_id == GOAL_ENV_ID:
        for name, flag in (("behavior", "--behavior"), ("two_arms", "--two-arms")):
            if name in env_options:
                raise InvalidValueError(f"{GOAL_ENV_ID} chooses among all the behaviours at every step, with both "
                                        f"arms: drop the {name} option ({flag}), got {env_options[name]!r}.")
    EnvOptions.checked(**env_options)
    full = {f.name: f.default for f in dataclasses.fields(EnvOptions)}
    full.update(env_options)
    if env_id == GOAL_ENV_ID:
        del full["behavior"], full["two_arms"]
    return json.loads(json.dumps(full, default=list))


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
    max_failure_share: float = 0.2,
    env_id: str = ENV_IDS[0],
    oversubscribe: bool = False,
) -> Path:
    """Collect ``episodes`` interactions into the dataset directory ``out``, resuming it if it exists.

    Args:
        out: Dataset directory; created if missing. A dataset there made with the same settings is resumed, or
            extended if ``episodes`` is larger; one made with other settings is refused.
        episodes: Number of interactions.
        seed: Seed of the dataset (>= 0); interaction ``i`` depends only on ``(seed, i)``.
        workers: Processes on this machine (joblib), or in the local Dask cluster of ``scheduler="dask"``: at
            most one per chunk to collect, and at most one per core (``os.cpu_count()``) unless ``oversubscribe``
            (a one-line note on stderr says when fewer are started than asked). The data do not depend on it.
        action: ``"canonical"`` (the paper's tap, all zeros) or ``"random"`` (uniform in the action box).
        env_options: Keyword arguments of ``TapAffordance-v2`` (behavior, object_types, size_range,
            camera_width, camera_height, camera_fovy, roll_threshold, settle_timeout); the others keep the
            env's defaults, which are recorded too.
        chunk_size: Interactions per file: the most a crash can lose, per worker.
        progress: Draw a progress bar; by default on a terminal when ``CI`` is not set, and otherwise write a
            progress line every 10 s (:func:`~affordance_env.progress.progress_bar`); False: nothing.
        scheduler: ``"joblib"`` (processes on this machine) or ``"dask"`` (Dask distributed: the cluster at
            ``dask_address``, or a local cluster of ``workers`` processes).
        dask_address: A Dask scheduler (``"tcp://host:8786"``); implies ``scheduler="dask"``. Its workers need
            the same tap-affordance version and must see ``out`` (a shared file system).
        save_images: Also store the initial and final range images (float16) and object masks (bit-packed),
            zstd-compressed; read them with ``load_dataset(out, with_images=True)`` and :func:`images`.
        max_failure_share: Stop with :class:`FailureShareError` once more than this share of the interactions
            collected so far were marked failed by the environment, in [0, 1] (1 accepts any).
        env_id: ``"TapAffordance-v2"`` (one interaction per episode, a row each) or ``"TapAffordanceGoal-v2"``: goal
            episodes of up to 5 interactions (``GOAL_MAX_EPISODE_STEPS``), each the first action the arm can reach
            (``feasible``) among the behaviours in a random order, each with ``PARAM_DRAWS`` parameter vectors by
            ``action`` (:func:`goal_step_actions`), one row per interaction with its ``step`` and the goal columns;
            episodes end early as the module docstring says (truncated: ``"infeasible: ..."`` or ``"lost: ..."`` in
            the chunk's metadata; or at a failed interaction, left out). The rule is part of the dataset's settings
            (``goal_episodes``): a dataset collected otherwise is not resumed with it.
        oversubscribe: Start ``workers`` processes even where they are more than this machine's cores.

    Returns:
        The dataset directory.
    """
    _check_collect_arguments(episodes, seed, workers, action, chunk_size, scheduler, max_failure_share, env_id)
    if dask_address is not None:
        check_dask_address(dask_address)  # before anything is written: Dask's own error is a long traceback
        scheduler = "dask"
    options = _full_options(dict(env_options or {}), env_id)
    if scheduler == "joblib" and workers == 1:  # this process collects: build its env now, before any work
        worker_env(env_id, json.dumps(options, sort_keys=True))
    header = dataset_header(seed, action, chunk_size, options, save_images, env_id)
    if env_id == GOAL_ENV_ID:
        header["settings"]["goal_episodes"] = GOAL_EPISODE_RULE
    out, episodes = Path(out), int(episodes)

    stored = _stored_or_new(out, header, episodes)
    out.mkdir(parents=True, exist_ok=True)
    with _exclusive(out):
        for stale in out.glob(".*.tmp"):  # left by a run that was killed while writing
            stale.unlink(missing_ok=True)
        ranges = chunk_ranges(episodes, chunk_size)
        done = _chunks_done(out, ranges, header, stored)
        write_manifest(out, header, episodes, done)
        _check_failure_share(done, max_failure_share, out)
        tasks = [(str(out), i, start, stop, header) for i, (start, stop) in enumerate(ranges) if i not in done]
        if dask_address is None:  # a cluster of its own: processes of this machine
            workers = _worker_count(workers, len(tasks), oversubscribe)
        _collect_chunks(out, tasks, done, header, episodes, progress, max_failure_share,
                        (scheduler, workers, dask_address))
    return out


def _worker_count(workers: int, chunks: int, oversubscribe: bool = False) -> int:
    """The processes to start for ``chunks`` chunks when ``workers`` are asked: no more than the chunks (a process
    without a chunk only costs its start), and no more than this machine's cores unless ``oversubscribe`` (more
    processes than cores slow each other down and can exhaust the memory: each builds its own environment). The
    cap by the cores is said in one line on stderr."""
    count = max(1, min(workers, chunks))
    cores = os.cpu_count() or 1
    if count > cores and not oversubscribe:
        print(f"affordance: note: {count} worker processes asked, more than this machine's {cores} cores: "
              f"starting {cores} (--oversubscribe, or oversubscribe=True, starts {count})", file=sys.stderr)
        count = cores
    return count


def _stored_or_new(out: Path, header: dict, episodes: int) -> dict:
    """The manifest of the dataset in ``out`` that these settings resume or extend (DatasetError where they cannot),
    or an empty one where ``out`` is new or empty; DatasetError where it holds something else."""
    if (out / MANIFEST).exists():
        return _check_resumable(out, header, episodes)
    if out.exists() and (not out.is_dir() or any(p.name != ".lock" for p in out.iterdir())):
        raise DatasetError(f"{out} exists and is not a TapAffordance dataset (no {MANIFEST}); choose an "
                           "empty or new directory.")
    return {}


def _check_collect_arguments(episodes: int, seed: int, workers: int, action: str, chunk_size: int, scheduler: str,
                             max_failure_share: float, env_id: str) -> None:
    """InvalidValueError naming the first argument of :func:`collect` that it cannot take."""
    for name, value, low in (("episodes", episodes, 1), ("workers", workers, 1),
                             ("chunk_size", chunk_size, 1), ("seed", seed, 0)):
        if not is_integer(value) or value < low:
            raise InvalidValueError(f"{name} must be an integer >= {low}, got {value!r}.")
    if episodes > MAX_EPISODES:
        raise InvalidValueError(f"episodes must be at most {MAX_EPISODES:,} (a dataset's limit), got {episodes!r}.")
    if action not in ACTIONS:
        raise InvalidValueError(f"action must be one of {ACTIONS}, got {action!r}.")
    if isinstance(max_failure_share, bool) or not (isinstance(max_failure_share, int | float | np.floating)
                                                   and 0.0 <= max_failure_share <= 1.0):
        raise InvalidValueError(f"max_failure_share must be a share in [0, 1], got {max_failure_share!r}.")
    if env_id not in ENV_IDS:
        raise InvalidValueError(f"env_id must be one of {ENV_IDS}, got {env_id!r}.")
    if scheduler not in SCHEDULERS:
        raise InvalidValueError(f"scheduler must be one of {SCHEDULERS}, got {scheduler!r}.")


def _chunks_done(out: Path, ranges: list[tuple[int, int]], header: dict, stored: dict) -> dict[int, ChunkResult]:
    """The chunks of ``out`` already written whole with these settings, by index."""
    done = {}
    for index, (start, stop) in enumerate(ranges):
        found = _existing_chunk(out / chunk_name(index), header, start, stop, stored)
        if found is not None:
            meta, digest = found
            done[index] = ChunkResult.from_metadata(meta["chunk"], digest)
    return done


def _collect_chunks(out: Path, tasks: list, done: dict[int, ChunkResult], header: dict, episodes: int,
                    progress: bool | None, max_failure_share: float, how: tuple[str, int, str | None]) -> None:
    """Run the missing chunks' ``tasks`` (``how``: scheduler, workers, Dask address), recording each in ``done`` and
    the manifest as it comes, with a progress bar over all ``episodes``."""
    n_failed = sum(len(chunk.failures) for chunk in done.values())
    with progress_bar(progress, total=episodes, initial=sum(chunk.episodes for chunk in done.values()),
                      unit="interaction", desc=out.name, smoothing=0.05) as bar:
        bar.set_postfix(failed=n_failed, refresh=False)
        for chunk in _run(tasks, *how):
            if not (out / chunk_name(chunk.index)).exists():
                raise DatasetError(f"a worker wrote {chunk_name(chunk.index)} where this process cannot see "
                                   f"it: the Dask workers must share {out} with this machine.")
            done[chunk.index] = chunk
            write_manifest(out, header, episodes, done)
            n_failed += len(chunk.failures)
            bar.set_postfix(failed=n_failed, refresh=False)
            bar.update(chunk.episodes)
            _check_failure_share(done, max_failure_share, out)


def failure_summary(failures: dict[str, str], examples: int = 1) -> str:
    """Failed interactions by kind, most common first, with an example reason of each kind:
    ``"reach 10 (e.g. episode 3: reach: the arm moved ...), ik 2 (...)"``; ``"none"`` if there are none."""
    by_kind: dict[str, list[str]] = {}
    for episode in sorted(failures, key=int):
        by_kind.setdefault(failures[episode].split(":", 1)[0], []).append(episode)
    parts = []
    for kind, episodes in sorted(by_kind.items(), key=lambda item: -len(item[1])):
        shown = "; ".join(f"episode {e}: {failures[e][:160]}" for e in episodes[:examples])
        parts.append(f"{kind} {len(episodes)} (e.g. {shown})")
    return ", ".join(parts) or "none"


class FailureShareError(DatasetError):
    """More interactions failed than the collection was told to accept."""


def _check_failure_share(done: Mapping[int, ChunkResult], max_share: float, out: Path) -> None:
    collected = sum(chunk.episodes for chunk in done.values())
    failures = {k: v for chunk in done.values() for k, v in chunk.failures.items()}
    if collected and len(failures) / collected > max_share:
        raise FailureShareError(
            f"{len(failures)} of the {collected} interactions collected so far failed "
            f"({100 * len(failures) / collected:.0f} %), more than max_failure_share = {max_share:g}: "
            f"{failure_summary(failures)}. The {len(done)} chunk(s) written are kept in {out}; rerun with a "
            f"larger max_failure_share (--max-failure-share) to accept such failures and go on, or remove "
            "their cause.")


def _check_resumable(out: Path, header: dict, episodes: int) -> dict:
    """The manifest of the dataset in ``out``, checked to be resumable as ``header`` with ``episodes``."""
    stored = read_manifest(out)
    diffs = settings_differences(stored, header)
    if diffs:
        raise DatasetError(f"{out} holds a dataset made with other settings ({'; '.join(diffs)}). Use "
                           "another --out, or the same settings to resume or extend it.")
    if episodes < stored["episodes"]:
        raise DatasetError(f"{out} holds a dataset of {stored['episodes']} interactions, asked for "
                           f"{episodes}: a dataset can be resumed or extended, not shortened; load it and "
                           f"keep the first {episodes} episodes instead.")
    return stored


def _existing_chunk(path: Path, header: dict, start: int, stop: int, stored: dict) -> tuple[dict, str] | None:
    """The metadata and SHA-256 of a finished chunk that matches; None if it is missing or must be collected
    again (warning why, unless it is the short last chunk of a grown dataset). ``stored``: the manifest found."""
    if not path.exists():
        return None
    try:
        meta = check_chunk(path, header, start, stop)
        digest = file_sha256(path)
        recorded = (stored.get(CHECKSUMS) or {}).get(path.name)
        if recorded is not None and recorded != digest:
            raise DatasetError(f"{path} has changed since it was written (its SHA-256 is not the one the "
                               f"{MANIFEST} recorded).")
        # not recorded: written by a run stopped before its manifest was updated; checked above, so kept
        return meta, digest
    except DatasetError as exc:
        with contextlib.suppress(DatasetError, AttributeError, KeyError, TypeError):
            chunk = chunk_metadata(path)[0]["chunk"]
            if chunk["start"] == start and chunk["stop"] < stop:  # the short last chunk of a grown dataset
                return None
        warnings.warn(f"collecting {path.name} again: {exc}", stacklevel=3)
        return None


def _run(tasks: list[tuple], scheduler: str, workers: int, address: str | None) -> Iterator[ChunkResult]:
    """Run chunk tasks, yielding each chunk as it is written."""
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
            delayed(_collect_chunk_in_worker)(*task) for task in tasks
        )


def _collect_chunk_in_worker(*task) -> ChunkResult:
    """:func:`_collect_chunk` in a worker process of this machine, which leaves Ctrl-C to the coordinating
    process: that one stops the workers (whole chunks stay, as always) and says so once, instead of every worker
    printing a traceback."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    return _collect_chunk(*task)


def _run_dask(tasks: list[tuple], workers: int, address: str | None) -> Iterator[tuple]:
    try:
        from distributed import Client, LocalCluster, as_completed
    except ImportError as exc:
        raise MissingDependencyError("scheduler='dask' needs Dask distributed: pip install "
                                     "'tap-affordance[dask]'") from exc
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
