"""MkDocs hooks: pages that show a Markdown file from outside docs/ as it is (the scene's assets/README.md).

A page holding ``<!-- include: PATH -->`` (PATH from the repository root) shows that file in its place; the file's
links are written from its own folder, so those into docs/ (``../docs/NAME``) are rewritten to the site's.
"""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
INCLUDE = re.compile(r"<!-- include: (\S+) -->")


def _included(match: re.Match) -> str:
    path = ROOT / match.group(1)
    return path.read_text(encoding="utf-8").replace("](../docs/", "](")


def on_page_markdown(markdown, page, **kwargs):
    return INCLUDE.sub(_included, markdown)
