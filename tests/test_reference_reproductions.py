"""The shipped reproductions stay what the code gives: their first interactions, collected again, bit for bit, and
their reports, drawn again from their results.json."""

import copy
import json
from pathlib import Path

import pytest

from affordance_env import load_dataset
from affordance_env.dataset import collect
from affordance_env.dataset.fingerprint import fingerprint, fingerprint_differences
from affordance_learning.cli import main
from affordance_learning.paper.report import render_overview, render_report
from affordance_learning.paper.reproduce import FINGERPRINT, check_fingerprint

REPRODUCTIONS = sorted(p.parent for p in (Path(__file__).resolve().parent.parent / "docs" / "reproduction")
                       .glob("*/results.json"))


def test_every_shipped_reproduction_has_a_fingerprint_of_its_settings():
    assert {p.name for p in REPRODUCTIONS} >= {"tap", "grasp", "tap-kinect-noise"}
    for where in REPRODUCTIONS:
        config = json.loads((where / "results.json").read_text())["config"]
        pinned = json.loads((where / FINGERPRINT).read_text())
        options = pinned["settings"]["env_options"]
        assert options["behavior"] == config["behavior"] and pinned["settings"]["seed"] == config["seed"], where
        assert (options["range_noise"] or "none") == config["range_noise"], where
        assert pinned["episodes"] == 30 and len(pinned["interactions"]) + len(pinned["failures"]) == 30, where


@pytest.mark.parametrize("where", REPRODUCTIONS, ids=[p.name for p in REPRODUCTIONS])
def test_each_shipped_report_is_what_its_results_give(where):
    # Fails when the reading of results.json, a claim's rule or verdict, or the report's text changed: regenerate the
    # reports with the reproductions (docs/reproduction/README.md says how), or undo the change.
    figures = sorted(p.name for p in where.glob("*.png"))
    results = json.loads((where / "results.json").read_text())
    assert render_report(results, figures) == (where / "REPORT.md").read_text()


def test_the_shipped_overview_is_what_the_results_give():
    root = REPRODUCTIONS[0].parent
    runs = {b: json.loads((root / b / "results.json").read_text()) for b in ("tap", "grasp")}
    figures = {b: sorted(p.name for p in (root / b).glob("*.png")) for b in runs}
    assert render_overview(runs, figures) == (root / "REPORT.md").read_text()


@pytest.mark.slow
@pytest.mark.parametrize("where", REPRODUCTIONS, ids=[p.name for p in REPRODUCTIONS])
def test_the_first_30_interactions_of_each_shipped_reproduction_are_collected_again(where):
    # Fails when a change to the simulation changes the data behind docs/reproduction: regenerate the
    # reproductions and their fingerprints (docs/reproduction/README.md says how), or undo the change. Bit for bit
    # with the versions and the CPU the fingerprint records; elsewhere, what holds across machines.
    check = check_fingerprint(where, workers=2)
    assert check.ok, f"{check.summary()}: {check.problems}"


@pytest.fixture(scope="module")
def taps(tmp_path_factory):
    out = tmp_path_factory.mktemp("fingerprint") / "taps"
    collect(out, 4, seed=2, env_options={"camera_width": 32, "camera_height": 32}, chunk_size=4, progress=False)
    return load_dataset(out)


def test_a_fingerprint_names_what_changed_down_to_the_part_of_the_row(taps):
    pinned = fingerprint(taps, episodes=3)
    assert [i["episode"] for i in pinned["interactions"]] == [e for e in taps.episode if e < 3]
    assert fingerprint_differences(pinned, fingerprint(taps.copy(), episodes=3)) == []
    nudged = taps.copy()
    first = nudged.index[0]
    nudged.loc[first, "effect_mean_x"] = float(nudged.loc[first, "effect_mean_x"]) + 1e-15  # one ulp or so
    nudged.loc[first, "true_final_x"] = float(nudged.loc[first, "true_final_x"]) * (1 + 1e-16)
    problems = fingerprint_differences(pinned, fingerprint(nudged, episodes=3))
    changed = "effect, truth" if nudged.loc[first, "true_final_x"] != taps.loc[first, "true_final_x"] else "effect"
    assert problems == [f"episode {taps.episode[first]} ({taps.type[first]}): {changed} changed"]
    other = copy.deepcopy(pinned)
    other["settings"]["env_options"]["settle_timeout"] = 2.0
    assert "collected with other settings" in fingerprint_differences(other, pinned)[0]


def test_fingerprint_command_errors_are_one_line(tmp_path, capsys):
    assert main(["fingerprint", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{tmp_path} holds no results.json of `affordance reproduce`" in err
    # --check of a directory without results.json once said to write its fingerprint there, which cannot work
    assert main(["fingerprint", "--check", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{tmp_path} holds no results.json of `affordance reproduce`" in err, err
    assert "affordance fingerprint" not in err
