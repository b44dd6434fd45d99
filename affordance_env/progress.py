"""Progress of long work: a bar on a terminal, a plain line every few seconds in a log.

A collection or a learning run takes from seconds to hours. On a terminal it draws a tqdm bar; when its output
goes to a file or a CI log (no terminal, or ``CI`` set), a bar would be one line redrawn with carriage returns,
so the same tqdm status is written as a plain line instead, at most every :data:`LOG_INTERVAL` seconds and once
at the end.
"""

from __future__ import annotations

import os
import sys
from typing import Any, TextIO

#: Seconds between two progress lines written to a log.
LOG_INTERVAL = 10.0


def show_progress(progress: bool | None) -> bool:
    """Whether to draw the progress bar: as asked, or by default on a terminal when ``CI`` is not set."""
    if progress is not None:
        return bool(progress)
    return sys.stderr.isatty() and not os.environ.get("CI")


class _Lines:
    """A file for tqdm that turns each redraw of its bar into one plain line."""

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream

    def write(self, text: str) -> None:
        line = text.replace("\r", "").strip()
        if line:
            self.stream.write(line + "\n")

    def flush(self) -> None:
        self.stream.flush()


def progress_bar(progress: bool | None, **kwargs: Any):
    """A tqdm progress bar over ``kwargs`` (``total``, ``desc``, ``unit``, ...): drawn when ``progress`` is True,
    or None on a terminal outside CI (:func:`show_progress`); with None and no terminal, a line on stderr every
    :data:`LOG_INTERVAL` seconds; nothing when ``progress`` is False."""
    from tqdm.auto import tqdm

    if show_progress(progress):
        return tqdm(dynamic_ncols=True, **kwargs)
    if progress is False:
        return tqdm(disable=True, **kwargs)
    return tqdm(file=_Lines(sys.stderr), mininterval=LOG_INTERVAL, ascii=True, ncols=100, **kwargs)
