"""The examples' command lines: their help, and a missing optional package, without the simulator."""

import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def _tap_video(*args: str, without: tuple[str, ...] = ()) -> subprocess.CompletedProcess:
    """``examples/tap_video.py ARGS`` in a new interpreter in which the modules ``without`` cannot be imported."""
    code = (f"import runpy, sys; sys.modules.update(dict.fromkeys({without!r})); sys.argv = ['tap_video.py', "
            f"*{list(args)!r}]; runpy.run_path({str(EXAMPLES / 'tap_video.py')!r}, run_name='__main__')")
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)


def test_tap_video_without_imageio_gives_its_help_and_one_line_naming_the_install():
    # --help was a traceback without imageio, imported before the arguments were read
    without = ("imageio", "imageio.v3", "imageio_ffmpeg")
    shown = _tap_video("--help", without=without)
    assert shown.returncode == 0 and shown.stdout.startswith("usage: tap_video.py"), shown.stderr
    refused = _tap_video("--episodes", "1", without=without)
    assert refused.returncode == 2 and refused.stdout == ""
    assert refused.stderr.count("\n") == 1 and 'pip install "tap-affordance[examples]"' in refused.stderr, \
        refused.stderr


def test_tap_video_with_imageio_but_not_its_ffmpeg_says_which_is_missing():
    pytest.importorskip("imageio")  # the examples extra; the test extra alone has no imageio
    no_ffmpeg = _tap_video("--episodes", "1", without=("imageio_ffmpeg",))  # imageio alone cannot write an mp4
    assert no_ffmpeg.returncode == 2 and "imageio_ffmpeg is missing" in no_ffmpeg.stderr, no_ffmpeg.stderr
