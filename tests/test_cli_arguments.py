"""Command-line mistakes: one line on stderr and exit status 2, found before any work starts (before the simulator
is imported), with nothing written."""

import itertools
import json
import subprocess
import sys
from pathlib import Path

import pytest

from affordance_learning.cli import PLAN_DEFAULTS, build_parser, main

COLLECT = ["collect", "--out", "OUT", "--episodes", "3"]
PLAN = ["plan", "--out", "OUT"]
SIZE = "a size in metres in [0.02, 0.15] (what the hand can tap)"
DASK = "PROTOCOL://HOST:PORT with PROTOCOL one of tcp, tls, ws, wss, ucx (e.g. tcp://scheduler:8786)"

# argv (OUT: a path in the test's directory), the option, the value given, what is expected of it
BAD_VALUES = [
    (["demo", "--episodes", "-1"], "--episodes", "-1", "an integer >= 1"),
    (["demo", "--episodes", "0"], "--episodes", "0", "an integer >= 1"),
    (["demo", "--seed", "-1"], "--seed", "-1", "an integer >= 0"),
    ([*PLAN, "--objects", "-2"], "--objects", "-2", "an integer >= 1"),
    ([*PLAN, "--episodes", "0"], "--episodes", "0", "an integer >= 1"),
    ([*PLAN, "--multi-episodes", "0"], "--multi-episodes", "0", "an integer >= 1"),
    ([*PLAN, "--workers", "0"], "--workers", "0", "an integer >= 1"),
    ([*PLAN, "--seed", "-1"], "--seed", "-1", "an integer >= 0"),
    (["reproduce", "--episodes", "19"], "--episodes", "19", "an integer >= 20"),
    (["reproduce", "--trials", "0"], "--trials", "0", "an integer >= 1"),
    (["reproduce", "--workers", "0"], "--workers", "0", "an integer >= 1"),
    (["reproduce", "--seed", "-3"], "--seed", "-3", "an integer >= 0"),
    (["fingerprint", "DIR", "--workers", "0"], "--workers", "0", "an integer >= 1"),
    (["train-default", "--workers", "-1"], "--workers", "-1", "an integer >= 1"),
    (["collect", "--out", "OUT", "--episodes", "0"], "--episodes", "0", "an integer >= 1"),
    (["collect", "--out", "OUT", "--episodes", "2.5"], "--episodes", "2.5", "an integer >= 1"),
    ([*COLLECT, "--workers", "0"], "--workers", "0", "an integer >= 1"),
    ([*COLLECT, "--seed", "-1"], "--seed", "-1", "an integer >= 0"),
    ([*COLLECT, "--chunk-size", "0"], "--chunk-size", "0", "an integer >= 1"),
    ([*COLLECT, "--max-failure-share", "1.5"], "--max-failure-share", "1.5", "a share in [0, 1]"),
    ([*COLLECT, "--max-failure-share", "-0.1"], "--max-failure-share", "-0.1", "a share in [0, 1]"),
    ([*COLLECT, "--max-failure-share", "nan"], "--max-failure-share", "nan", "a share in [0, 1]"),
    ([*COLLECT, "--size-range", "0", "0.05"], "--size-range", "0", SIZE),
    ([*COLLECT, "--size-range", "0.05", "0.5"], "--size-range", "0.5", SIZE),
    ([*COLLECT, "--camera-width", "1"], "--camera-width", "1", "an integer >= 2"),
    ([*COLLECT, "--camera-height", "0"], "--camera-height", "0", "an integer >= 2"),
    ([*COLLECT, "--camera-fovy", "0"], "--camera-fovy", "0", "a field of view in [1, 170] degrees"),
    ([*COLLECT, "--camera-fovy", "171"], "--camera-fovy", "171", "a field of view in [1, 170] degrees"),
    ([*COLLECT, "--roll-threshold", "0"], "--roll-threshold", "0", "a positive distance in metres"),
    ([*COLLECT, "--settle-timeout", "-1"], "--settle-timeout", "-1", "a positive duration in seconds"),
    ([*COLLECT, "--settle-timeout", "inf"], "--settle-timeout", "inf", "a positive duration in seconds"),
    ([*COLLECT, "--dask-address", "127.0.0.1"], "--dask-address", "127.0.0.1", DASK),
    ([*COLLECT, "--dask-address", "notanaddress"], "--dask-address", "notanaddress", DASK),
    ([*COLLECT, "--dask-address", "ftp://host:8786"], "--dask-address", "ftp://host:8786", DASK),
    ([*COLLECT, "--dask-address", "tcp://host:0"], "--dask-address", "tcp://host:0", DASK),
]


def _paths(argv, tmp_path):
    return [str(tmp_path / "out") if a == "OUT" else str(tmp_path / "dir") if a == "DIR" else a for a in argv]


@pytest.mark.parametrize(("argv", "option", "value", "expected"), BAD_VALUES,
                         ids=[" ".join(case[0][:1] + case[0][-2:]) for case in BAD_VALUES])
def test_a_value_that_cannot_be_used_is_one_line_as_it_is_parsed(argv, option, value, expected, tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_:
        build_parser().parse_args(_paths(argv, tmp_path))
    err = capsys.readouterr().err
    assert exit_.value.code == 2 and err.count("\n") == 1, err
    assert f"argument {option}: expected {expected}, got {value!r}" in err
    assert not (tmp_path / "out").exists()


def test_the_values_at_the_bounds_are_accepted(tmp_path):
    parse = build_parser().parse_args
    out = str(tmp_path / "out")
    args = parse(["collect", "--out", out, "--episodes", "1", "--seed", "0", "--max-failure-share", "1",
                  "--size-range", "0.05", "0.05", "--camera-width", "2", "--camera-fovy", "170"])
    assert (args.episodes, args.max_failure_share, args.size_range, args.camera_width) == (1, 1.0, [0.05, 0.05], 2)
    assert parse(["reproduce", "--episodes", "20"]).episodes == 20
    assert parse(["collect", "--out", out, "--episodes", "1", "--max-failure-share", "0"]).max_failure_share == 0
    for address in ("tcp://127.0.0.1:8786", "tls://scheduler.example:8786", "127.0.0.1:8786", "tcp://[::1]:8786"):
        assert parse(["collect", "--out", out, "--episodes", "1", "--dask-address", address]).dask_address == address


class WorkStarted(Exception):
    """Raised in place of a command's work: the command got past its checks."""


@pytest.fixture
def no_work(monkeypatch):
    """Each command's work (an env, a collection, a plan, an export) raises WorkStarted instead of running."""
    import gymnasium

    import affordance_env.dataset as dataset
    import affordance_learning.planning.experiment as plan_experiment
    from affordance_env.dataset import minari_export

    def started(*args, **kwargs):
        raise WorkStarted(args, kwargs)

    for module, name in ((gymnasium, "make"), (dataset, "collect"), (plan_experiment, "run_plan"),
                         (minari_export, "export_minari")):
        monkeypatch.setattr(module, name, started)
    return started


def _refused(argv, capsys, *fragments):
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("affordance: error: "), err
    for fragment in fragments:
        assert fragment in err, (fragment, err)
    return err


def test_plan_takes_the_sizes_given_and_plan_settings_defaults_otherwise(no_work, tmp_path):
    from affordance_learning.planning.experiment import PlanSettings

    assert PLAN_DEFAULTS == {name: getattr(PlanSettings(), name) for name in PLAN_DEFAULTS}  # the help says these
    with pytest.raises(WorkStarted) as started:
        main(["plan", "--out", str(tmp_path / "out"), "--objects", "3"])
    assert started.value.args[1]["settings"] == PlanSettings(objects=3)


def test_a_quick_plan_takes_few_data_and_says_its_verdicts_are_on_too_few(no_work, tmp_path, capsys):
    from dataclasses import replace

    from affordance_learning.planning.experiment import GOALS_PER_OBJECT, QUICK
    from affordance_learning.planning.targets import MIN_CALIBRATION_ACTIONS, MIN_EPISODES, MIN_FEASIBLE_GOALS

    with pytest.raises(WorkStarted) as started:
        main(["plan", "--out", str(tmp_path / "out"), "--quick"])
    settings = started.value.args[1]["settings"]
    assert settings == QUICK and settings.quick
    out = capsys.readouterr().out
    assert "a quick run" in out and "too few data" in out
    # few episodes, objects and trees: every n of the targets below its minimum, so no verdict is given on them
    assert settings.max_episodes <= 100 and settings.max_per_behavior <= 100 and settings.trees <= 50
    assert settings.objects * sum(GOALS_PER_OBJECT.values()) < min(MIN_FEASIBLE_GOALS, MIN_CALIBRATION_ACTIONS)
    assert settings.multi_episodes < MIN_EPISODES
    with pytest.raises(WorkStarted) as started:
        main(["plan", "--out", str(tmp_path / "out"), "--quick", "--objects", "2"])
    assert started.value.args[1]["settings"] == replace(QUICK, objects=2)  # a size given still applies


def _manifest(directory, env_id="TapAffordance-v2", action="canonical", seed=0):
    from affordance_env.dataset.format import MANIFEST, dataset_header

    options = {"behavior": "tap"} if env_id == "TapAffordance-v2" else {"position_range": "workspace"}
    directory.mkdir(parents=True)
    header = dataset_header(seed, action, 25, options, False, env_id)
    (directory / MANIFEST).write_text(json.dumps({**header, "episodes": 6}))


def _listing(directory):
    return sorted(str(p.relative_to(directory)) for p in directory.rglob("*"))


def test_plan_refuses_an_out_that_holds_what_is_not_its_own(no_work, tmp_path, capsys):
    collected = tmp_path / "taps"  # `affordance collect --out taps`
    _manifest(collected)
    before = _listing(collected)
    _refused(["plan", "--out", collected], capsys, f"--out {collected} is a dataset directory",
             "(a TapAffordance-v2 dataset of 6 tap interactions with canonical actions, seed 0)")
    assert _listing(collected) == before  # nothing written into it
    inside = tmp_path / "inside"
    _manifest(inside / "dataset")
    _refused(["plan", "--out", inside], capsys, f"{inside / 'dataset'} holds a TapAffordance-v2 dataset",
             "not the plan's TapAffordanceGoal-v2 episodes")
    other_seed = tmp_path / "other-seed"
    _manifest(other_seed / "dataset", env_id="TapAffordanceGoal-v2", action="random", seed=3)
    _refused(["plan", "--out", other_seed, "--seed", "1"], capsys, "episodes of seed 3, not of --seed 1",
             "give --seed 3")
    reproduction = tmp_path / "reproduction"
    reproduction.mkdir()
    (reproduction / "results.json").write_text(json.dumps({"config": {"behavior": "tap"}}))
    _refused(["plan", "--out", reproduction], capsys, "holds a results.json of format None, not a plan's")
    notes = tmp_path / "notes"
    notes.mkdir()
    (notes / "REPORT.md").write_text("mine")
    _refused(["plan", "--out", notes], capsys, "is not empty (REPORT.md) and holds no earlier plan's")
    a_file = tmp_path / "a-file"
    a_file.write_text("mine")
    _refused(["plan", "--out", a_file], capsys, "is a file, not a directory")
    assert (notes / "REPORT.md").read_text() == "mine" and a_file.read_text() == "mine"


def test_plan_takes_a_new_or_empty_out_or_an_earlier_plans(no_work, tmp_path):
    new = tmp_path / "new"
    with pytest.raises(WorkStarted):
        main(["plan", "--out", str(new)])
    assert not new.exists()  # the checks create nothing
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(WorkStarted):
        main(["plan", "--out", str(empty)])
    earlier = tmp_path / "earlier"
    _manifest(earlier / "dataset", env_id="TapAffordanceGoal-v2", action="random", seed=2)
    with pytest.raises(WorkStarted):
        main(["plan", "--out", str(earlier), "--seed", "2"])
    (earlier / "results.json").write_text(json.dumps({"format": "tap-affordance-plan-results"}))
    (earlier / "REPORT.md").write_text("# plan")
    (earlier / "notes.txt").write_text("mine")
    with pytest.raises(WorkStarted):
        main(["plan", "--out", str(earlier), "--seed", "2"])


def test_plan_results_format_is_the_one_run_plan_writes():
    import affordance_learning.planning.experiment as plan_experiment
    from affordance_learning.cli import PLAN_DATASET, PLAN_RESULTS_FORMAT

    assert plan_experiment.RESULTS_FORMAT == PLAN_RESULTS_FORMAT and plan_experiment.DATASET_DIR == PLAN_DATASET


def test_collect_options_that_do_not_go_together_are_refused_before_collecting(no_work, tmp_path, capsys):
    out = tmp_path / "out"
    collect = ["collect", "--out", out, "--episodes", "3"]
    _refused([*collect, "--size-range", "0.1", "0.05"], capsys, "--size-range 0.1 0.05: expected LOW <= HIGH")
    _refused([*collect, "--scheduler", "joblib", "--dask-address", "tcp://x:1"], capsys, "--dask-address")
    _refused([*collect, "--env", "TapAffordanceGoal-v2", "--behavior", "push"], capsys, "drop --behavior push")
    _refused([*collect, "--object-types", "sphere", "cube"], capsys, "Unknown object type 'cube'")
    _refused([*collect, "--behavior", "juggle"], capsys, "Unknown behavior 'juggle'")
    assert not out.exists()
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    _refused(collect, capsys, f"--out {out} exists and is not a TapAffordance dataset")
    _refused(["collect", "--out", out / "notes.txt", "--episodes", "3"], capsys, "is a file, not a dataset")
    assert _listing(out) == ["notes.txt"]


def test_demo_names_are_checked_before_the_environment_is_made(no_work, capsys):
    _refused(["demo", "--behavior", "juggle"], capsys, "Unknown behavior 'juggle'")
    _refused(["demo", "--object", "cube"], capsys, "Unknown object type 'cube'")
    with pytest.raises(WorkStarted):
        main(["demo", "--episodes", "1"])


# --- Minari ids -------------------------------------------------------------------------------------------------
@pytest.mark.parametrize(("dataset_id", "why"), [
    ("a/b-v0", "its namespace 'a' is a single character, Minari's have at least 2"),
    ("tap-affordance/canonical-taps", "'canonical-taps' does not end in a version, -v and digits"),
    ("taps-vX", "'taps-vX' does not end in a version"),
    ("", "it is empty"),
    ("a//b-v0", "'//' before the name"),
    ("/taps-v0", "it starts with '/'"),
    ("my lab/taps-v0", "its namespace 'my lab' has ' '"),
    ("lab/taps.v2-v0", "its name 'taps.v2' has '.'"),
    ("lab/-v0", "it has no name before -v0"),
    ("lab/", "nothing follows the last '/'"),
])
def test_a_malformed_minari_id_says_the_form_and_what_breaks_it(dataset_id, why, no_work, tmp_path, capsys,
                                                                 monkeypatch):
    monkeypatch.setenv("MINARI_DATASETS_PATH", str(tmp_path / "minari"))
    _refused(["export", tmp_path / "taps", "--minari", dataset_id], capsys,
              f"Minari dataset id {dataset_id!r} is malformed: expected (namespace/)name-v(version)", why,
              "at least 2 characters")
    assert not (tmp_path / "minari").exists()


def test_the_id_rule_is_minaris_part_by_part():
    minari_dataset = pytest.importorskip("minari.dataset.minari_dataset")
    from affordance_env.dataset.minari_export import dataset_id_problem

    for length in range(7):
        for characters in itertools.product("ab/-v0.", repeat=length):
            dataset_id = "".join(characters)
            match = minari_dataset.DATASET_ID_RE.fullmatch(dataset_id)
            versioned = match is not None and match.group("version") is not None
            assert versioned == (dataset_id_problem(dataset_id) is None), dataset_id


def test_the_id_is_checked_without_minari(monkeypatch):
    from affordance_env.dataset.minari_export import check_dataset_id_form

    monkeypatch.setitem(sys.modules, "minari", None)  # as if it were not installed
    check_dataset_id_form("tap-affordance/taps-v0")
    with pytest.raises(ValueError, match="namespace 'a' is a single character"):
        check_dataset_id_form("a/b-v0")


# --- no heavy import before the arguments are checked -------------------------------------------------------
def test_a_command_line_mistake_imports_neither_the_simulator_nor_what_the_command_runs(tmp_path):
    collected = tmp_path / "taps"
    _manifest(collected)
    a_file = tmp_path / "notes.txt"
    a_file.write_text("mine")
    mistakes = [["plan", "--out", str(tmp_path / "p"), "--objects", "-2"], ["demo", "--episodes", "-1"],
                ["demo", "--object", "cube"], ["plan", "--out", str(collected)],
                ["collect", "--out", str(tmp_path / "c"), "--episodes", "3", "--size-range", "0.1", "0.05"],
                ["export", str(collected), "--minari", "a/b-v0"],
                # a path that cannot be written, refused before the command's modules load
                ["plan", "--out", str(a_file / "p")], ["train-default", "--out", str(a_file / "m.joblib")],
                ["train-default", "--action-conditioned", "--out", str(a_file / "models")],
                ["reproduce", "--out", str(a_file / "r")], ["collect", "--out", str(a_file / "c"), "--episodes", "3"]]
    # an import of one of these ends the process with status 3, naming it
    code = f"""
import importlib.abc, os, sys
HEAVY = {{"mujoco", "pinocchio", "minari", "sklearn", "scipy", "matplotlib", "affordance_env.tap_env",
         "affordance_learning.planning.experiment"}}
class Guard(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name in HEAVY:
            sys.stderr.write(f"imported {{name}}\\n")
            sys.stderr.flush()
            os._exit(3)
sys.meta_path.insert(0, Guard())
from affordance_learning.cli import main
for argv in {mistakes!r}:
    try:
        status = main(argv)
    except SystemExit as exc:
        status = exc.code
    print(status)
"""
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["2"] * len(mistakes)
    assert len(done.stderr.splitlines()) == len(mistakes)  # one line each
    assert not (tmp_path / "p").exists() and not (tmp_path / "c").exists()


@pytest.mark.parametrize(("item", "fragment"), [("kick=taps", "unknown behaviour 'kick'"),
                                                ("=taps", "no behaviour before ="), ("tap=", "no PATH after 'tap='")])
def test_reproduce_refuses_a_dataset_of_no_known_behaviour(item, fragment, tmp_path, capsys, monkeypatch):
    # --dataset kick=taps once collected into a folder named "kick=taps"
    import affordance_learning.paper.reproduce as reproduce

    def started(*args, **kwargs):
        raise WorkStarted(args, kwargs)

    monkeypatch.setattr(reproduce, "reproduce", started)
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "out"
    err = _refused(["reproduce", "--behavior", "tap", "--dataset", item, "--out", out], capsys, fragment)
    if "behaviour" in fragment:  # the valid ones named
        assert all(name in err for name in ("tap", "push", "grasp", "draw", "tap_back"))
    assert not out.exists() and not list(tmp_path.iterdir())
    with pytest.raises(WorkStarted) as accepted:  # a path that holds "=" is given as one
        main(["reproduce", "--behavior", "tap", "--dataset", "./kick=taps", "--out", str(out)])
    assert accepted.value.args[1]["datasets"] == {"tap": Path("kick=taps")}
    with pytest.raises(WorkStarted) as accepted:
        main(["reproduce", "--dataset", "tap=taps", "--dataset", "grasp=grasps", "--out", str(out)])
    assert accepted.value.args[1]["datasets"] == {"tap": Path("taps"), "grasp": Path("grasps")}
