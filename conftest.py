"""The documentation's Python examples run as tests (Sybil): every ```python block of README.md and of the guides
under docs/, in order, each document in one namespace of its own, in a scratch working directory.

- ``<!-- invisible-code-block: python ... -->`` runs code the reader does not see (a small dataset to read, say);
- ``<!-- skip: next if(CONDITION, reason="...") -->`` skips the next block where CONDITION holds;
- ``<!-- slow -->`` just before a block (among the comments right above it) marks it ``slow``; deselecting slow
  tests (``-m "not slow"``) then also fails the blocks after it that use what it made.

pyproject.toml's ``testpaths`` names README.md and docs/ so that ``python -m pytest`` collects them.
"""

import os
import shutil
import tempfile

import pytest
from sybil import Sybil
from sybil.parsers.markdown import PythonCodeBlockParser, SkipParser

SLOW_MARK = "<!-- slow -->"


#: Environment variables a document's examples see, each a folder in their scratch directory: the default models
#: they might train, and the Minari datasets they export, stay out of the user's.
SCRATCH_VARIABLES = {"TAP_AFFORDANCE_DATA": "user-data", "MINARI_DATASETS_PATH": "minari-datasets"}


def _enter_scratch(namespace: dict) -> None:
    """A document's examples run in a scratch directory of their own (they write datasets and MuJoCo's log)."""
    namespace["_docs_previous"] = (os.getcwd(), {name: os.environ.get(name) for name in SCRATCH_VARIABLES})
    scratch = tempfile.mkdtemp(prefix="docs-example-")
    namespace["_docs_scratch"] = scratch
    os.chdir(scratch)
    for name, folder in SCRATCH_VARIABLES.items():
        os.environ[name] = os.path.join(scratch, folder)


def _leave_scratch(namespace: dict) -> None:
    cwd, variables = namespace["_docs_previous"]
    os.chdir(cwd)
    for name, value in variables.items():
        if value is None:
            os.environ.pop(name, None)
        else:
            os.environ[name] = value
    shutil.rmtree(namespace["_docs_scratch"], ignore_errors=True)


pytest_collect_file = Sybil(
    parsers=[PythonCodeBlockParser(), SkipParser()],
    patterns=["README.md", "docs/*.md"],
    excludes=["docs/reproduction/*", "docs/reproduction/*/*", "assets/*", "tests/*"],
    setup=_enter_scratch,
    teardown=_leave_scratch,
).pytest()


def _marked_slow(item) -> bool:
    """Whether the comments right above the item's block (up to three lines) include ``<!-- slow -->``."""
    example = item.example
    above = example.document.text[: example.start].rstrip().splitlines()[-3:]
    return any(line.strip() == SLOW_MARK for line in above)


def pytest_collection_modifyitems(config, items):
    for item in items:
        if hasattr(item, "example") and _marked_slow(item):
            item.add_marker(pytest.mark.slow)
