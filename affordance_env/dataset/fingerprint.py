"""Fingerprints of a dataset's first interactions: a few hundred bytes that pin them down bit for bit.

Shipped beside a reference result (``docs/reproduction/<behavior>/fingerprint.json``), a fingerprint lets a test
collect the same interactions again with the current code and tell, cheaply, whether they are still the ones the
shipped numbers came from. Per interaction it holds the SHA-256 of each namespace of its row (the action, the
ground truth, the initial and final features and the effect; every float as its float64 bytes), so that a drift is
reported as which interactions and which parts of them changed.
"""

from __future__ import annotations

import hashlib
from typing import Any

import numpy as np
import pandas as pd

from affordance_env.dataset.format import GROUND_TRUTH_COLUMNS, POSE_COLUMNS, with_later_defaults

#: Interactions a reference fingerprint covers.
FINGERPRINT_EPISODES = 30
#: The parts of a row that are hashed separately, by the prefix or the names of their columns.
PARTS = ("action", "truth", "initial", "final", "effect")


def _part_columns(frame: pd.DataFrame, part: str) -> list[str]:
    if part == "truth":
        return [c for c in (*GROUND_TRUTH_COLUMNS, *POSE_COLUMNS) if c in frame.columns]
    return [c for c in frame.columns if c.startswith(f"{part}_")]


def _value_bytes(value: Any) -> bytes:
    if isinstance(value, bool | np.bool_):
        return b"\x01" if value else b"\x00"
    if isinstance(value, str):
        return value.encode() + b"\x00"
    return np.float64(value).tobytes()  # exact: every stored number is a float64 or narrower


def fingerprint(frame: pd.DataFrame, episodes: int = FINGERPRINT_EPISODES) -> dict[str, Any]:
    """The fingerprint of the interactions ``0 .. episodes-1`` of a dataset frame (from ``load_dataset``): its
    collection settings, the failed ones among them, and per interaction its seed, type, success and a SHA-256
    of each part of its row (:data:`PARTS`)."""
    manifest = frame.attrs.get("manifest", {})
    rows = frame[frame["episode"] < episodes]
    interactions = []
    for _, row in rows.iterrows():
        digests = {part: hashlib.sha256(b"".join(_value_bytes(row[c]) for c in _part_columns(frame, part)))
                   .hexdigest() for part in PARTS}
        interactions.append({"episode": int(row["episode"]), "seed": int(row["seed"]), "type": str(row["type"]),
                             "success": bool(row["success"]), "sha256": digests})
    failures = {str(k): v for k, v in frame.attrs.get("failures", {}).items() if int(k) < episodes}
    settings = manifest.get("settings", {})
    return {"episodes": int(episodes), "package_version": manifest.get("package_version"),
            "schema_version": manifest.get("schema_version"),
            "settings": {"seed": settings.get("seed"), "action": settings.get("action"),
                         "env_options": settings.get("env_options")},
            "failures": failures, "interactions": interactions}


def fingerprint_differences(expected: dict[str, Any], found: dict[str, Any]) -> list[str]:
    """How ``found`` differs from ``expected``, for a person to read (empty: the same interactions, bit for bit).
    The package version is not compared: the data may stay the same across versions; settings added since
    ``expected`` was made count at the value it was made with (:data:`~.format.LATER_SETTINGS`)."""
    problems = []
    if with_later_defaults(expected.get("settings") or {}) != with_later_defaults(found.get("settings") or {}):
        problems.append(f"collected with other settings: {found.get('settings')} instead of "
                        f"{expected.get('settings')}")
    if expected.get("failures") != found.get("failures"):
        problems.append(f"failed interactions {found.get('failures')} instead of {expected.get('failures')}")
    old = {i["episode"]: i for i in expected.get("interactions", [])}
    new = {i["episode"]: i for i in found.get("interactions", [])}
    for episode in sorted(set(old) | set(new)):
        if episode not in new or episode not in old:
            problems.append(f"episode {episode}: {'missing' if episode not in new else 'not expected'}")
            continue
        a, b = old[episode], new[episode]
        changed = [part for part in PARTS if a["sha256"].get(part) != b["sha256"].get(part)]
        if changed or a["seed"] != b["seed"]:
            labels = ("" if (a["type"], a["success"]) == (b["type"], b["success"]) else
                      f"; was {a['type']} success={a['success']}, now {b['type']} success={b['success']}")
            problems.append(f"episode {episode} ({b['type']}): {', '.join(changed) or 'seed'} changed{labels}")
    return problems
