"""Datasets of interactions: collected in parallel, deterministically and resumably; read back as a DataFrame.

- :mod:`.format`: what a dataset is on disk (schema, manifest, chunks) and how its files are checked.
- :mod:`.collect`: :func:`collect` runs interactions into a dataset, resumably.
- :mod:`.load`: :func:`load_dataset` reads one back, every chunk checked against its SHA-256; :func:`images`
  decodes its stored images; :func:`learning_data` gives a learner its X, E and the labels.
- :mod:`.minari_export`: :func:`export_minari` writes one as a Minari dataset.
"""

from affordance_env.dataset.collect import (
    ACTIONS,
    SCHEDULERS,
    FailureShareError,
    collect,
    failure_summary,
    interaction_action,
    interaction_seed,
    show_progress,
)
from affordance_env.dataset.format import (
    FEATURE_PREFIXES,
    FORMAT,
    GROUND_TRUTH_COLUMNS,
    IMAGE_COLUMNS,
    MANIFEST,
    POSE_COLUMNS,
    POSE_FIELDS,
    SCHEMA_VERSION,
    DatasetError,
    arrow_schema,
    chunk_name,
    collect_command,
    read_manifest,
)

_LAZY = {"images": "load", "load_dataset": "load", "learning_data": "load", "export_minari": "minari_export"}


def __getattr__(name: str):
    # Reading (pandas) and the Minari export are imported when first asked: collecting needs neither.
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f"affordance_env.dataset.{_LAZY[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "ACTIONS",
    "FEATURE_PREFIXES",
    "FORMAT",
    "GROUND_TRUTH_COLUMNS",
    "IMAGE_COLUMNS",
    "MANIFEST",
    "POSE_COLUMNS",
    "POSE_FIELDS",
    "SCHEDULERS",
    "SCHEMA_VERSION",
    "DatasetError",
    "FailureShareError",
    "arrow_schema",
    "chunk_name",
    "collect",
    "collect_command",
    "export_minari",
    "failure_summary",
    "images",
    "interaction_action",
    "interaction_seed",
    "learning_data",
    "load_dataset",
    "read_manifest",
    "show_progress",
]
