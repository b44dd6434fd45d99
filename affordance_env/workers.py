"""Work spread over processes, each with the environments it built kept for the next item.

Building an environment takes about a second (the robot's meshes, the scene, the kinematics), so a worker keeps
the ones it built: :func:`worker_env` returns the same environment for the same id and options within one
process (one per thread). The dataset collection's chunks and the plan evaluation's objects and episodes both
reach their environments through it.

:func:`map_in_processes` runs ``function(item, **shared)`` for every item on fresh processes of the standard
library's :class:`~concurrent.futures.ProcessPoolExecutor`: ``shared`` (the planners of an evaluation, about
300 MB) goes to each process once, through the pool's initializer, and the items go one at a time to the first
process free, so that none idles while another works through its costlier items. The results come back in the
items' order and depend on each item and ``shared`` alone: the same for any number of processes.
"""

from __future__ import annotations

import json
import multiprocessing
import threading
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import ProcessPoolExecutor
from typing import Any

#: Per worker thread, {(env id, options as JSON): env}.
_local = threading.local()


def worker_env(env_id: str, options: Mapping[str, Any] | str):
    """The environment ``env_id`` (``TapAffordance-v2`` or ``TapAffordanceGoal-v2``) with ``options`` (its keyword
    arguments, or their JSON) that this thread built before, or a new one, kept for the next call.

    Built directly, not through ``gym.make``: a worker steps it from snapshots and resets it itself, so no wrapper
    (the time limit, the order checks) stands between."""
    options_json = options if isinstance(options, str) else json.dumps(dict(options), sort_keys=True)
    envs = _local.__dict__.setdefault("envs", {})
    key = (env_id, options_json)
    if key not in envs:
        from affordance_env.registry import GOAL_ENV_ID

        if env_id == GOAL_ENV_ID:
            from affordance_env.goal_env import TapAffordanceGoalEnv as Env
        else:
            from affordance_env.tap_env import TapAffordanceEnv as Env  # type: ignore[assignment]
        envs[key] = Env(**json.loads(options_json))
    return envs[key]


_shared: dict[str, Any] = {}


def _keep(shared: dict[str, Any]) -> None:
    """The pool's initializer: what every item of this process's calls gets."""
    _shared.clear()
    _shared.update(shared)


def _call(function: Callable[..., Any], item: Any) -> Any:
    return function(item, **_shared)


def map_in_processes(function: Callable[..., Any], items: Iterable[Any], workers: int, **shared: Any) -> list[Any]:
    """``[function(item, **shared) for item in items]`` on ``workers`` new processes (in this one for a single worker
    or item). The processes are started for this call ("spawn": nothing of this process's state but ``shared`` and
    its environment variables reaches them; the cache of compiled models is checked first,
    :func:`~affordance_env.model_cache.check_cache`) and end with it."""
    items = list(items)
    if workers == 1 or len(items) <= 1:
        return [function(item, **shared) for item in items]
    from affordance_env.model_cache import check_cache

    check_cache()  # a cache of compiled models that cannot be written is said here, not by every process
    context = multiprocessing.get_context("spawn")
    with ProcessPoolExecutor(max_workers=min(workers, len(items)), mp_context=context, initializer=_keep,
                             initargs=(shared,)) as pool:
        return list(pool.map(_call, [function] * len(items), items, chunksize=1))


__all__ = ["map_in_processes", "worker_env"]
