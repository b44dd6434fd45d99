"""Fingerprints of a dataset's first interactions: a few hundred bytes that pin them down bit for bit.

Shipped beside a reference result (``docs/reproduction/<behavior>/fingerprint.json``), a fingerprint lets a test
collect the same interactions again with the current code and tell, cheaply, whether they are still the ones the
shipped numbers came from. Per interaction it holds the SHA-256 of each namespace of its row (the action, the
ground truth, the initial and final features and the effect; every float as its float64 bytes), so that a drift is
reported as which interactions and which parts of them changed.

Bit for bit is a promise for one set of versions on one kind of CPU: a fingerprint records what it was made with
(:func:`made_with`), and :func:`compare_fingerprints` checks bit for bit where that matches. Elsewhere contacts
make the simulation chaotic (an object's final pose moves with the last bit of a servo target), and it checks what
holds across machines and versions instead: the same interactions drawn (seeds and object types), and their outcome
labels, but for at most :data:`MAX_LABEL_CHANGES` of them.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import platform
from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from affordance_env.dataset.format import GROUND_TRUTH_COLUMNS, POSE_COLUMNS, with_later_defaults

#: Interactions a reference fingerprint covers.
FINGERPRINT_EPISODES = 30
#: The parts of a row that are hashed separately, by the prefix or the names of their columns.
PARTS = ("action", "truth", "initial", "final", "effect")
#: The packages whose versions decide the bits of an interaction (the simulation, its kinematics and linear
#: algebra, the robot's model) or of the learning on it.
PACKAGES = ("mujoco", "numpy", "pin", "eigenpy", "icub-models", "scipy", "scikit-learn")
#: Across machines or versions, interactions of a fingerprint whose outcome label (failed, success, outcome) may
#: differ. Measured over 1000 canonical interactions: between OpenBLAS's Haswell and SkylakeX kernels (two CPUs, the
#: same versions, before the simulation's linear algebra was made independent of them) 0 taps and 5 grasps changed
#: their success label; between MuJoCo 3.17 and 4.0, 0 taps and 27 grasps (2.7 %; 2 of the first 30). At 2.7 %,
#: more than 4 of 30 change with probability 0.1 %.
MAX_LABEL_CHANGES = 4


def made_with() -> dict[str, Any]:
    """What interactions collected here are made with: the Python and package versions (:data:`PACKAGES`) and the
    CPU (its architecture and the instruction-set features numpy detects)."""
    packages = {}
    for name in PACKAGES:
        try:
            packages[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            packages[name] = None
    try:
        features = np._core._multiarray_umath.__cpu_features__  # what numpy.show_runtime() reports
        cpu_features = sorted(name for name, present in features.items() if present)
    except AttributeError:  # a numpy that does not expose them
        cpu_features = None
    return {"python": platform.python_version(), "packages": packages,
            "cpu": {"machine": platform.machine(), "features": cpu_features}}


def making_differences(expected: dict[str, Any] | None, found: dict[str, Any]) -> list[str]:
    """How two :func:`made_with` records differ, for a person to read (empty: the same versions and CPU)."""
    if not expected:
        return ["the fingerprint does not record what it was made with"]
    problems = []
    if expected.get("python") != found.get("python"):
        problems.append(f"python {expected.get('python')} here {found.get('python')}")
    old, new = expected.get("packages") or {}, found.get("packages") or {}
    problems += [f"{name} {old.get(name)} here {new.get(name)}" for name in sorted(set(old) | set(new))
                 if old.get(name) != new.get(name)]
    old_cpu, new_cpu = expected.get("cpu") or {}, found.get("cpu") or {}
    if old_cpu.get("machine") != new_cpu.get("machine"):
        problems.append(f"CPU {old_cpu.get('machine')} here {new_cpu.get('machine')}")
    elif old_cpu.get("features") != new_cpu.get("features"):
        lost = sorted(set(old_cpu.get("features") or ()) - set(new_cpu.get("features") or ()))
        gained = sorted(set(new_cpu.get("features") or ()) - set(old_cpu.get("features") or ()))
        problems.append("CPU features " + ", ".join([*(f"-{f}" for f in lost), *(f"+{f}" for f in gained)]))
    return problems


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
                             "success": bool(row["success"]), "outcome": str(row.get("outcome", "")),
                             "sha256": digests})
    failures = {str(k): v for k, v in frame.attrs.get("failures", {}).items() if int(k) < episodes}
    settings = manifest.get("settings", {})
    return {"episodes": int(episodes), "package_version": manifest.get("package_version"),
            "schema_version": manifest.get("schema_version"), "made_with": made_with(),
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


def _label(interaction: dict[str, Any] | None) -> tuple:
    """An interaction's outcome label: failed, or its success and outcome (older fingerprints: success only)."""
    if interaction is None:
        return ("failed",)
    return (bool(interaction["success"]), interaction.get("outcome"))


def _changed_labels(expected: dict[str, Any], found: dict[str, Any]) -> tuple[list[str], list[str]]:
    """The episodes whose interaction was drawn differently (seed or object type), and those whose outcome label
    changed, each as a line for a person to read."""
    old = {i["episode"]: i for i in expected.get("interactions", [])}
    new = {i["episode"]: i for i in found.get("interactions", [])}
    drawn, changed = [], []
    for episode in range(int(expected.get("episodes", 0))):
        a, b = old.get(episode), new.get(episode)
        if a is not None and b is not None and (a["seed"], a["type"]) != (b["seed"], b["type"]):
            drawn.append(f"episode {episode}: drew {b['type']} (seed {b['seed']}) instead of {a['type']} "
                         f"(seed {a['seed']})")
            continue
        la, lb = _label(a), _label(b)
        if a is not None and b is not None and a.get("outcome") is None:  # an older fingerprint: success only
            lb = (lb[0], None)
        if la != lb:
            changed.append(f"episode {episode}: {_shown(la)} -> {_shown(lb)}")
    return drawn, changed


def contract_differences(expected: dict[str, Any], found: dict[str, Any]) -> list[str]:
    """How ``found`` breaks what holds across machines and versions (empty: it keeps it): the same settings, the
    same interactions drawn (seed and object type per episode), and the same outcome label for all but at most
    :data:`MAX_LABEL_CHANGES` of them."""
    problems = []
    if with_later_defaults(expected.get("settings") or {}) != with_later_defaults(found.get("settings") or {}):
        problems.append(f"collected with other settings: {found.get('settings')} instead of "
                        f"{expected.get('settings')}")
    drawn, changed = _changed_labels(expected, found)
    problems += drawn
    if len(changed) > MAX_LABEL_CHANGES:
        problems.append(f"{len(changed)} outcome labels changed, more than the {MAX_LABEL_CHANGES} allowed: "
                        + "; ".join(changed))
    return problems


def _shown(label: tuple) -> str:
    if label == ("failed",):
        return "failed"
    return ("success" if label[0] else "no success") + (f" ({label[1]})" if label[1] else "")


@dataclass(frozen=True)
class FingerprintCheck:
    """What :func:`compare_fingerprints` found.

    Attributes:
        mode: ``"bit for bit"`` (made with the same versions and CPU) or ``"across machines"``.
        differs_in: How what the fingerprint was made with differs from here (empty in ``"bit for bit"`` mode).
        problems: What breaks the promise of the mode (empty: kept).
        interactions: Interactions compared.
        identical: Of them, those found again bit for bit.
        labels_changed: Of them, those whose outcome label changed.
    """

    mode: str
    differs_in: tuple[str, ...]
    problems: tuple[str, ...]
    interactions: int
    identical: int
    labels_changed: int

    @property
    def ok(self) -> bool:
        return not self.problems

    def summary(self) -> str:
        """One line: which check was made, and its verdict."""
        if self.mode == "bit for bit":
            return (f"bit for bit (made with these versions on this CPU): {self.identical} of {self.interactions} "
                    f"interactions identical" + ("" if self.ok else f", {len(self.problems)} difference(s)"))
        return (f"across machines (made with other versions or another CPU: {'; '.join(self.differs_in)}): "
                f"{self.labels_changed} of {self.interactions} outcome labels changed (at most {MAX_LABEL_CHANGES} "
                f"allowed), {self.identical} of {self.interactions} interactions bit for bit"
                + ("" if self.ok else " -- contract broken"))


def compare_fingerprints(expected: dict[str, Any], found: dict[str, Any]) -> FingerprintCheck:
    """Compare interactions collected now (``found``) with a fingerprint made earlier (``expected``): bit for bit
    where both were made with the same versions and CPU (:func:`made_with`), otherwise by what holds across
    machines (:func:`contract_differences`)."""
    differs_in = making_differences(expected.get("made_with"), found.get("made_with") or made_with())
    old = {i["episode"]: i for i in expected.get("interactions", [])}
    new = {i["episode"]: i for i in found.get("interactions", [])}
    identical = sum(1 for e, i in new.items() if e in old and old[e]["sha256"] == i["sha256"])
    labels_changed = len(_changed_labels(expected, found)[1])
    if differs_in:
        mode, problems = "across machines", contract_differences(expected, found)
    else:
        mode, problems = "bit for bit", fingerprint_differences(expected, found)
    return FingerprintCheck(mode, tuple(differs_in), tuple(problems), int(expected.get("episodes", 0)), identical,
                            labels_changed)
