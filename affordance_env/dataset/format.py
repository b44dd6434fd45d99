"""The on-disk format of a dataset: its schema, its manifest, its chunks and how they are checked.

A dataset is a directory::

    manifest.json          what the dataset is: settings, package version, feature names and groups, schema
                           version, labels version (:data:`LABELS_VERSION`), progress, the interactions left out
                           (count, kinds, episode -> reason), and the SHA-256 of every finished chunk
                           (``chunk_sha256``)
    chunk-00000.parquet    interactions 0 .. chunk_size-1, one row each (columns: :func:`arrow_schema`)
    chunk-00001.parquet    ...
    .lock                  held by the collection writing the dataset (empty)

Each chunk also carries the dataset's description, its episode range and its failures in its Parquet key-value
metadata (key ``tap_affordance``), so that a chunk can be checked on its own. Files are written to a temporary
name and renamed when complete (:func:`write_atomically`). A chunk counts as finished once the manifest records
its SHA-256; reading checks every chunk against it, so any changed byte is an error, never silently changed data.

The columns fall in namespaces that cannot be confused (:func:`arrow_schema`):

- features: ``initial_<f>``, ``final_<f>``, ``effect_<f>``, exactly one per name ``f`` of ``FEATURE_NAMES`` (49);
- ground truth, measured by the simulator and never an input of the learner: ``true_initial_<p>`` and
  ``true_final_<p>`` (the object's pose, ``p`` in :data:`POSE_FIELDS`) and the labels of
  :data:`GROUND_TRUTH_COLUMNS` (``type``, ``size``, ``success``, ...);
- the action: ``action_<j>``; the images: ``image_<stage>_<kind>`` (:data:`IMAGE_COLUMNS`);
- bookkeeping: ``episode``, ``seed``, ``behavior``;
- in a dataset of TapAffordanceGoal-v2 episodes (``env_id``), one row per interaction of an episode, also
  ``step`` (0, 1, ... within the episode) and the goal: :data:`GOAL_COLUMNS`.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from affordance_env.behaviors import ACTION_DIM
from affordance_env.exceptions import DatasetError, InvalidValueError
from affordance_env.features import FEATURE_GROUPS, FEATURE_NAMES
from affordance_env.fileio import write_atomically
from affordance_env.registry import ENV_IDS, GOAL_ENV_ID
from affordance_env.values import is_integer

if TYPE_CHECKING:  # the results are made by the simulator, which reading a dataset does not need
    from affordance_env.results import InteractionResult

#: Version of the on-disk format; :func:`~affordance_env.dataset.load_dataset` reads versions 1 up to this one.
#: Version 4 added the ``success`` column. Version 5 named the object's pose ``true_initial_x`` ... (it was
#: ``initial_x``, beside the features) and the images ``image_initial_range`` ... (``initial_range``), and
#: recorded each chunk's SHA-256 in the manifest.
SCHEMA_VERSION = 5
#: Version of what the rows' labels mean, for the same columns: a dataset is resumed or extended only with rows
#: labelled as its own (one written before this was recorded is of version 1). Version 2: an object the grasp's
#: hand holds beyond the table's edge has not left the table (``outcome``; version 1 said ``"off_table"`` the
#: moment its centre crossed the edge, in the hand or not).
LABELS_VERSION = 2
FORMAT = "tap-affordance-dataset"
MANIFEST = "manifest.json"
METADATA_KEY = b"tap_affordance"
#: The most episodes (interactions, or goal episodes) a dataset may hold: a hundred million, two weeks of collection
#: at a hundred interactions a second, and a chunk list that fits in memory.
MAX_EPISODES = 100_000_000
POSE_FIELDS = ("x", "y", "z", "qw", "qx", "qy", "qz")
#: The stages of an interaction whose features (and images) are stored, and the prefix of its effects.
STAGES = ("initial", "final")
FEATURE_PREFIXES = ("initial_", "final_", "effect_")
#: Prefix of the ground-truth pose columns: ``true_initial_x`` ... ``true_final_qz``.
TRUE_PREFIX = "true_"
POSE_COLUMNS = tuple(f"{TRUE_PREFIX}{stage}_{f}" for stage in STAGES for f in POSE_FIELDS)
#: The ground truth besides the pose: measured by the simulator, for evaluating, never an input of a learner.
GROUND_TRUTH_COLUMNS = ("type", "size", "displacement", "rolling_distance", "rolled", "success", "tilt",
                        "toppled", "outcome", "outcome_time", "contact", "hand_speed", "visible_initial",
                        "visible_final", "ik_success")
IMAGE_COLUMNS = tuple(f"image_{stage}_{kind}" for stage in STAGES for kind in ("range", "mask"))
#: The manifest's record of each finished chunk's SHA-256 (hex), by file name.
CHECKSUMS = "chunk_sha256"
#: The environments a dataset can be collected from: one interaction per episode, or goal episodes of several.
#: The goal columns of a dataset of TapAffordanceGoal-v2 episodes: the goal (x, y) [m], where the object was seen
#: after the interaction (``achieved_goal``) [m], its distance to the goal [m] and whether it reached it.
GOAL_COLUMNS = ("goal_x", "goal_y", "achieved_x", "achieved_y", "goal_distance", "goal_reached")
#: Settings added after the first datasets, with the value every dataset made before had: a dataset that lacks
#: one was made with that value.
LATER_SETTINGS = {"env_id": "TapAffordance-v2"}
LATER_ENV_OPTIONS = {"position_range": "canonical", "two_arms": False}


def arrow_schema(save_images: bool = False, goal: bool = False) -> pa.Schema:
    """The columns of every chunk, in order: bookkeeping, action, ground truth, (goal,) 3 x 49 features, images.
    ``goal``: a dataset of TapAffordanceGoal-v2 episodes, with ``step`` and :data:`GOAL_COLUMNS`."""
    fields = [("episode", pa.int64())] + ([("step", pa.int64())] if goal else [])
    fields += [("seed", pa.int64()), ("behavior", pa.string()), ("type", pa.string()), ("size", pa.float64())]
    fields += [(f"action_{j}", pa.float32()) for j in range(ACTION_DIM)]
    fields += [(column, pa.float64()) for column in POSE_COLUMNS]
    fields += [("displacement", pa.float64()), ("rolling_distance", pa.float64()), ("rolled", pa.bool_()),
               ("success", pa.bool_()), ("tilt", pa.float64()), ("toppled", pa.bool_()), ("outcome", pa.string()),
               ("outcome_time", pa.float64()), ("contact", pa.bool_()), ("hand_speed", pa.float64()),
               ("visible_initial", pa.bool_()), ("visible_final", pa.bool_()), ("ik_success", pa.bool_())]
    if goal:
        fields += [(column, pa.bool_() if column == "goal_reached" else pa.float64()) for column in GOAL_COLUMNS]
    fields += [(f"{stage}_{name}", pa.float64())
               for stage in ("initial", "final", "effect") for name in FEATURE_NAMES]
    if save_images:
        fields += [(column, pa.binary()) for column in IMAGE_COLUMNS]
    return pa.schema(fields)


@dataclass(frozen=True)
class GoalStep:
    """Where a TapAffordanceGoal-v2 episode stands after one of its interactions.

    Attributes:
        step: The interaction's index in its episode.
        goal: The goal (x, y) [m].
        achieved: The object's perceived position (x, y) [m] after the interaction.
        distance: Its distance to the goal [m].
        reached: Whether it is within the goal tolerance.
    """

    step: int
    goal: np.ndarray
    achieved: np.ndarray
    distance: float
    reached: bool


def interaction_row(episode: int, env_seed: int, result: InteractionResult, save_images: bool,
                    goal: GoalStep | None = None) -> dict[str, Any]:
    """The row of a valid interaction (``result.failure`` is None; a failed one has no row, InvalidValueError).
    A row with non-finite numbers raises RuntimeError: a bug, not a failed interaction. ``goal``: the interaction
    is a step of a TapAffordanceGoal-v2 episode."""
    if result.failure is not None:
        raise InvalidValueError(f"interaction {episode} failed ({result.failure}): a failed interaction has no row.")
    row: dict[str, Any] = {"episode": episode, "seed": env_seed, "behavior": result.behavior,
                           "type": result.object_type, "size": float(result.size)}
    row.update({f"action_{j}": a for j, a in enumerate(result.action)})
    for stage, pose in (("initial", result.initial.pose), ("final", result.final_pose)):
        row.update({f"{TRUE_PREFIX}{stage}_{f}": float(v) for f, v in zip(POSE_FIELDS, pose, strict=True)})
    row.update(displacement=float(result.displacement), rolling_distance=float(result.rolling_distance),
               rolled=bool(result.rolled), success=bool(result.success), tilt=float(result.tilt),
               toppled=bool(result.toppled), outcome=result.outcome, outcome_time=float(result.outcome_time),
               contact=bool(result.contact), hand_speed=float(result.hand_speed),
               visible_initial=bool(result.initial.visible), visible_final=bool(result.visible),
               ik_success=bool(result.ik.success))
    for stage, values in (("initial", result.initial.features.values), ("final", result.final_features),
                          ("effect", result.effect)):
        row.update({f"{stage}_{name}": float(v) for name, v in zip(FEATURE_NAMES, values, strict=True)})
    if goal is not None:
        row["step"] = int(goal.step)
        row.update(goal_x=float(goal.goal[0]), goal_y=float(goal.goal[1]), achieved_x=float(goal.achieved[0]),
                   achieved_y=float(goal.achieved[1]), goal_distance=float(goal.distance),
                   goal_reached=bool(goal.reached))
    bad = [k for k, v in row.items() if isinstance(v, float | np.floating) and not np.isfinite(v)]
    if bad:  # the env promises finite numbers for every interaction it does not mark failed: this is a bug
        raise RuntimeError(f"interaction {episode} (env seed {env_seed}) was not marked failed but has "
                           f"{len(bad)} non-finite value(s), e.g. {bad[:3]}; nothing of it was written.")
    if save_images:
        for stage, snapshot in (("initial", result.initial.snapshot), ("final", result.final)):
            row[f"image_{stage}_range"] = snapshot.ranges.astype(np.float16).tobytes()
            row[f"image_{stage}_mask"] = np.packbits(snapshot.mask.astype(bool)).tobytes()
    return row


@dataclass(frozen=True)
class ChunkResult:
    """One chunk file of a dataset, as its metadata records it and the manifest lists it.

    Attributes:
        index: The chunk's index.
        start, stop: Its episodes, ``start .. stop - 1``.
        failures: The failed interactions' reasons, by episode (as a string).
        rows: The rows written.
        sha256: The file's SHA-256 ("" until it is written).
        truncated: For goal episodes, those cut short and why, by episode; None for TapAffordance-v2.
    """

    index: int
    start: int
    stop: int
    failures: Mapping[str, str]
    rows: int
    sha256: str = ""
    truncated: Mapping[str, str] | None = None

    @property
    def episodes(self) -> int:
        """How many episodes it holds."""
        return self.stop - self.start

    def metadata(self) -> dict[str, Any]:
        """Its entry in the chunk file's metadata (``"chunk"``)."""
        chunk = {"index": self.index, "start": self.start, "stop": self.stop, "failures": dict(self.failures),
                 "rows": self.rows}
        if self.truncated is not None:
            chunk["truncated"] = dict(self.truncated)
        return chunk

    @classmethod
    def from_metadata(cls, chunk: Mapping[str, Any], sha256: str) -> ChunkResult:
        """The chunk its file's metadata describes (:func:`chunk_metadata`), with the file's SHA-256."""
        return cls(chunk["index"], chunk["start"], chunk["stop"], chunk["failures"], chunk["rows"], sha256,
                   chunk.get("truncated"))


def chunk_name(index: int) -> str:
    return f"chunk-{index:05d}.parquet"


def chunk_ranges(episodes: int, chunk_size: int) -> list[tuple[int, int]]:
    return [(s, min(s + chunk_size, episodes)) for s in range(0, episodes, chunk_size)]


def dataset_header(seed: int, action: str, chunk_size: int, env_options: dict, save_images: bool,
                   env_id: str = ENV_IDS[0]) -> dict[str, Any]:
    """What a dataset is: written to the manifest and to every chunk."""
    from affordance_env import __version__

    settings = {"seed": int(seed), "action": action, "chunk_size": int(chunk_size),
                "save_images": bool(save_images), "env_id": env_id, "env_options": env_options}
    return {"format": FORMAT, "schema_version": SCHEMA_VERSION, "labels_version": LABELS_VERSION,
            "package_version": __version__, "settings": settings, "feature_names": list(FEATURE_NAMES),
            "feature_groups": dict(FEATURE_GROUPS)}


def is_goal_dataset(description: dict) -> bool:
    """Whether the dataset (its manifest, or a chunk's metadata) holds goal episodes (TapAffordanceGoal-v2, or an
    earlier version)."""
    settings = description.get("settings")
    return isinstance(settings, dict) and str(settings.get("env_id")).startswith(GOAL_ENV_ID.rsplit("-", 1)[0] + "-")


def with_later_defaults(settings: dict) -> dict[str, Any]:
    """A dataset's settings with those added after it was made (:data:`LATER_SETTINGS`) at their old values."""
    settings = {**LATER_SETTINGS, **settings}
    if isinstance(settings.get("env_options"), dict):
        settings["env_options"] = {**LATER_ENV_OPTIONS, **settings["env_options"]}
    return settings


def _flat_settings(description: dict) -> dict[str, Any]:
    settings = description.get("settings")
    settings = with_later_defaults(settings) if isinstance(settings, dict) else {}
    env_options = settings.pop("env_options", None)
    return {"schema_version": description.get("schema_version"),
            "labels_version": description.get("labels_version", 1),
            "package_version": description.get("package_version"),
            **settings, **(env_options if isinstance(env_options, dict) else {})}


def settings_differences(stored: dict, asked: dict) -> list[str]:
    """The settings in which a stored dataset differs from the one asked for, for a person to read."""
    old, new = _flat_settings(stored), _flat_settings(asked)
    return [f"{key}: dataset has {old.get(key)!r}, asked for {value!r}"
            for key, value in new.items() if old.get(key) != value]


def file_sha256(path: Path) -> str:
    """The SHA-256 of a file's bytes, as hex."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def collect_command(path: str | os.PathLike, manifest: dict) -> str:
    """The ``affordance collect`` command that makes (or finishes, or redoes chunks of) the dataset ``path``
    described by ``manifest``: its settings, with the env options that differ from the env's defaults."""
    import dataclasses
    import shlex

    from affordance_env.options import EnvOptions

    settings = manifest.get("settings") or {}
    words = ["affordance", "collect", "--out", str(path)]
    for flag, value in (("--episodes", manifest.get("episodes")), ("--seed", settings.get("seed")),
                        ("--chunk-size", settings.get("chunk_size"))):
        if value is not None:  # a manifest that lacks it: the collection's own default
            words += [flag, str(value)]
    if settings.get("env_id", ENV_IDS[0]) != ENV_IDS[0]:
        words += ["--env", str(settings["env_id"])]
    if settings.get("action", "canonical") != "canonical":
        words += ["--action", str(settings["action"])]
    if settings.get("save_images"):
        words.append("--save-images")
    defaults = json.loads(json.dumps({f.name: f.default for f in dataclasses.fields(EnvOptions)}, default=list))
    options = settings.get("env_options")
    for name, value in (options if isinstance(options, dict) else {}).items():
        if value is None or value == defaults.get(name):
            continue
        values = value if isinstance(value, list | tuple) else [value]
        words += [f"--{name.replace('_', '-')}", *(str(v) for v in values)]
    return shlex.join(words)


def write_manifest(out: Path, header: dict, episodes: int, done: Mapping[int, ChunkResult]) -> None:
    """Write the manifest of the dataset ``out``; ``done`` maps the index of each finished chunk to it."""
    failures = {k: v for chunk in done.values() for k, v in chunk.failures.items()}
    kinds = Counter(reason.split(":", 1)[0] for reason in failures.values())
    n_chunks = len(chunk_ranges(episodes, header["settings"]["chunk_size"]))
    manifest = {**header, "episodes": episodes, "chunks": n_chunks, "chunks_done": len(done),
                "complete": len(done) == n_chunks, "rows": sum(chunk.rows for chunk in done.values()),
                "failures": {"count": len(failures), "by_kind": dict(sorted(kinds.items())),
                             "episodes": {k: failures[k] for k in sorted(failures, key=int)}},
                CHECKSUMS: {chunk_name(i): done[i].sha256 for i in sorted(done)}}
    write_atomically(out / MANIFEST, lambda tmp: tmp.write_text(json.dumps(manifest, indent=1)))


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
    if not is_integer(version) or not 1 <= version <= SCHEMA_VERSION:
        raise DatasetError(f"{path} has dataset schema version {version!r}; this tap-affordance reads "
                           f"versions 1 to {SCHEMA_VERSION}: upgrade the package "
                           "(pip install -U tap-affordance).")
    settings = manifest.get("settings")
    if not isinstance(settings, dict) or not isinstance(settings.get("env_options", {}), dict):
        raise DatasetError(f"{path / MANIFEST} is damaged: its settings, with the env's options, are "
                           f"{settings!r}.")
    chunk_size = settings.get("chunk_size")
    episodes = manifest.get("episodes")
    if not is_integer(episodes) or not 1 <= episodes <= MAX_EPISODES or not is_integer(chunk_size) or chunk_size < 1:
        raise DatasetError(f"{path / MANIFEST} is damaged: episodes {episodes!r} (an integer in 1..{MAX_EPISODES}), "
                           f"chunk_size {chunk_size!r} (an integer >= 1).")
    return manifest


def chunk_metadata(path: Path) -> tuple[dict, int]:
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


def check_checksum(path: Path, manifest: dict) -> str:
    """The SHA-256 of the chunk file ``path``, once checked to be the one ``manifest`` records for it; raises
    DatasetError if the file changed after it was written (or the manifest does not know it)."""
    recorded = (manifest.get(CHECKSUMS) or {}).get(path.name)
    digest = file_sha256(path)
    if recorded is None:
        raise DatasetError(f"{path} is not recorded as finished in the dataset's {MANIFEST} (no SHA-256 for it).")
    if digest != recorded:
        raise DatasetError(f"{path} has changed since it was written: its SHA-256 is {digest[:16]}..., the "
                           f"dataset's {MANIFEST} recorded {recorded[:16]}....")
    return digest


def check_chunk(path: Path, header: dict, start: int, stop: int) -> dict:
    """A chunk's metadata, once checked to be chunk ``start .. stop-1`` of the dataset ``header``."""
    meta, rows = chunk_metadata(path)
    chunk = meta.get("chunk")
    span = (chunk.get("start"), chunk.get("stop")) if isinstance(chunk, dict) else None
    if span != (start, stop) or not isinstance(chunk.get("failures"), dict):
        raise DatasetError(f"{path} holds episodes {span}, expected ({start}, {stop}).")
    for episode, reason in chunk["failures"].items():  # {"episode number": "why it failed"}
        if not (isinstance(episode, str) and episode.isdigit() and start <= int(episode) < stop
                and isinstance(reason, str)):
            raise DatasetError(f"{path} is corrupt: a failure {episode!r}: {reason!r} is not an episode of "
                               f"{start}..{stop - 1} with its reason.")
    diffs = settings_differences(meta, header)
    if diffs:
        raise DatasetError(f"{path} was made with other settings than its dataset ({'; '.join(diffs)}).")
    if is_goal_dataset(header):  # goal episodes: a row per interaction, as many as the chunk recorded
        if rows != chunk.get("rows"):
            raise DatasetError(f"{path} is inconsistent: {rows} rows, its metadata recorded {chunk.get('rows')!r}.")
    elif rows + len(chunk["failures"]) != stop - start:
        raise DatasetError(f"{path} is inconsistent: {rows} rows and {len(chunk['failures'])} failures for "
                           f"{stop - start} interactions.")
    meta["rows"] = rows
    return meta
