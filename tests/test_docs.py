"""The README and the guides under docs/: what a reader meets first, which code blocks run, and the pictures.

The Python blocks themselves run as tests of their own (conftest.py at the repository root, Sybil); these tests
check that they are all collected, and the rest that no runner would notice.
"""

import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
DOCS = ROOT / "docs"
#: The pages whose Python blocks run as tests (the reference reproductions' reports are written by the code).
PAGES = [README, *sorted(DOCS.glob("*.md"))]
#: A fenced block's language: Python runs, shell commands and printed output do not.
FENCE_LANGUAGES = {"python", "bash", "text"}
#: The front page's length: a reader gets what the project is and how to start; the details are in the guides.
README_MAX_WORDS = 1200

FENCE = re.compile(r"^[ \t]*```(\S*)[^\n]*\n(.*?)^[ \t]*```[ \t]*$", re.MULTILINE | re.DOTALL)
INVISIBLE_PYTHON = re.compile(r"<!-- invisible-code-block: python\n")
SKIP = re.compile(r"<!-- skip: ")


def fenced_blocks(path: Path) -> list[tuple[str, str]]:
    """(language, code) of each fenced code block of ``path``, in order."""
    return FENCE.findall(path.read_text(encoding="utf-8"))


def test_readme_opens_with_the_commands_that_ci_runs():
    # A fresh machine's two commands are the README's first code blocks, before any Python; the second is the
    # test command that .ci/run runs, line for line.
    blocks = fenced_blocks(README)
    assert [language for language, _ in blocks[:2]] == ["bash", "bash"]
    assert blocks[0][1].strip() == "pip install . && affordance reproduce --out reproduction"
    ci_lines = (ROOT / ".ci" / "run").read_text(encoding="utf-8").splitlines()
    test_command = ci_lines[ci_lines.index("# The README's test command:") + 1]
    assert blocks[1][1].strip() == test_command


def test_readme_is_a_front_page():
    words = len(README.read_text(encoding="utf-8").split())
    assert words <= README_MAX_WORDS, f"README.md has {words} words, over {README_MAX_WORDS}: move details to docs/"


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_code_block_says_whether_it_runs(page):
    # ```python runs as a test; a block of another language does not, so a Python example fenced as ```py or
    # left unmarked would silently go untested.
    languages = {language for language, _ in fenced_blocks(page)}
    assert languages <= FENCE_LANGUAGES, f"{page.name}: code blocks fenced as {sorted(languages - FENCE_LANGUAGES)}"


def test_every_python_block_is_collected_by_the_test_command(pytestconfig):
    # `python -m pytest` (the README's test command) collects README.md and docs/ (pyproject's testpaths), one
    # test per Python block, visible or invisible, and per skip directive.
    assert {"README.md", "docs"} <= set(pytestconfig.getini("testpaths"))
    expected = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        count = sum(language == "python" for language, _ in fenced_blocks(page)) + len(INVISIBLE_PYTHON.findall(text))
        expected += [str(page.relative_to(ROOT))] * (count + len(SKIP.findall(text)))
    run = subprocess.run([sys.executable, "-m", "pytest", "--collect-only", "-q", "-p", "no:cacheprovider",
                          "README.md", "docs"], cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    collected = [line.split("::")[0] for line in run.stdout.splitlines() if "::line:" in line]
    assert sorted(collected) == sorted(expected)


def test_every_picture_is_drawn_by_make_figures_and_shown():
    # docs/make_figures.py draws every picture under docs/ (the reproductions' figures are affordance reproduce's)
    # and each picture is shown on some page.
    sys.path.insert(0, str(DOCS))
    try:
        import make_figures
    finally:
        sys.path.remove(str(DOCS))
    pictures = {path.stem for path in DOCS.glob("*.png")}
    assert pictures == set(make_figures.FIGURES)
    for script, *_ in make_figures.FIGURES.values():
        assert (ROOT / script).is_file(), script
    text = "\n".join(page.read_text(encoding="utf-8") for page in PAGES)
    for name in pictures:
        assert f"{name}.png)" in text, f"docs/{name}.png is shown on no page"


def test_every_guide_is_in_the_site_navigation():
    nav = (ROOT / "mkdocs.yml").read_text(encoding="utf-8")
    for page in sorted(DOCS.glob("*.md")):
        assert f": {page.name}\n" in nav, f"docs/{page.name} is missing from mkdocs.yml's nav"


def test_readme_links_lead_somewhere():
    # The site's build checks the guides' links (mkdocs build --strict); the README is read on its own, so its
    # relative links are checked here: each names a file or folder of the repository.
    targets = re.findall(r"\]\(([^)#\s]+)[^)]*\)", README.read_text(encoding="utf-8"))
    relative = [target for target in targets if "://" not in target]
    assert relative
    missing = [target for target in relative if not (ROOT / target).exists()]
    assert not missing, f"README.md links to what is not there: {missing}"
