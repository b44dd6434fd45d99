"""The ``affordance`` command line."""

import pytest

from affordance_learning.cli import main


def test_demo_prints_what_happened(capsys):
    assert main(["demo", "--episodes", "2", "--seed", "4", "--object", "sphere"]) == 0
    out = capsys.readouterr().out
    assert out.count("sphere") >= 2 and "rolled=True" in out and "per second" in out


def test_bad_option_is_a_clear_error_not_a_traceback(capsys):
    assert main(["demo", "--episodes", "1", "--object", "cube"]) == 2
    assert "Unknown object type 'cube'" in capsys.readouterr().err


def test_unknown_command_exits_with_usage():
    with pytest.raises(SystemExit):
        main(["fly"])


def test_reproduce_writes_results_figures_and_a_report_per_behaviour(tmp_path, capsys):
    import json

    out = tmp_path / "repro"
    assert main(["reproduce", "--behavior", "tap", "--behavior", "push", "--episodes", "40", "--trials", "2",
                 "--workers", "1", "--out", str(out), "--progress"]) == 0
    for behavior, success in (("tap", "rolled"), ("push", "moved")):
        results = json.loads((out / behavior / "results.json").read_text())
        assert set(results["uniformity"]) == {str(k) for k in range(2, 11)}
        assert set(results["svm_accuracy"]) == {"0.0", "0.2", "0.4", "0.6", "0.8"}
        config = results["config"]
        assert config["behavior"] == behavior and config["success_label"] == success
        assert config["episodes"] == 40 and config["dataset"] == "dataset"
        assert (out / behavior / "dataset" / "manifest.json").exists()
        pinned = json.loads((out / behavior / "fingerprint.json").read_text())  # its first 30 interactions
        assert pinned["settings"]["env_options"]["behavior"] == behavior
        assert len(pinned["interactions"]) + len(pinned["failures"]) == 30
        for name in ("uniformity.png", "selected_features.png", "case_study_k2.png", "case_study_k3.png",
                     "case_study_k4.png", "svm_accuracy.png", "size_success.png", "REPORT.md"):
            assert (out / behavior / name).stat().st_size > 1000, (behavior, name)
    overview = (out / "REPORT.md").read_text()
    assert "# Reproduction of Akgun et al. 2009: tap, push" in overview
    for link in ("[tap](tap/REPORT.md)", "[push](push/REPORT.md)", "(tap/uniformity.png)", "(push/size_success.png)"):
        assert link in overview, link
    assert "## tap" in overview and "## push" in overview and "tapping and grasping only" in overview
    printed = capsys.readouterr()
    assert "40 interactions, 0 failed" in printed.out and "[push 1/3] collecting 40 canonical push" in printed.out
    # progress bars for each stage, and the headline numbers of each behaviour at the end
    assert all(stage in printed.err for stage in ("dataset", "learning trials", "figures"))
    assert f"tap: {out / 'tap' / 'REPORT.md'}" in printed.out and f"push: {out / 'push' / 'REPORT.md'}" in printed.out
    assert printed.out.count("uniformity:") == 2 and printed.out.count("the paper's claims:") == 2
    assert "successes (rolled) whose object is seen" in printed.out
    assert f"All behaviours side by side: {out / 'REPORT.md'}" in printed.out
    # a second run of one behaviour reuses its dataset instead of collecting again (its chunk files are not
    # rewritten), and the overview still shows the other behaviour, from the earlier run
    chunks = {p: p.stat().st_mtime_ns for p in (out / "tap" / "dataset").glob("chunk-*.parquet")}
    assert main(["reproduce", "--behavior", "tap", "--episodes", "40", "--trials", "1", "--workers", "1", "--out",
                 str(out)]) == 0
    assert "40 interactions" in capsys.readouterr().out
    assert chunks and {p: p.stat().st_mtime_ns for p in chunks} == chunks
    overview = (out / "REPORT.md").read_text()
    assert "# Reproduction of Akgun et al. 2009: tap, push" in overview and "[push](push/REPORT.md)" in overview


def test_reproduce_refuses_what_it_cannot_run_before_collecting(tmp_path, capsys, monkeypatch):
    import affordance_env.behaviors as env_behaviors

    without_grasp = {name: b for name, b in env_behaviors.BEHAVIORS.items() if name != "grasp"}
    monkeypatch.setattr(env_behaviors, "BEHAVIORS", without_grasp)
    out = tmp_path / "repro"
    assert main(["reproduce", "--episodes", "40", "--out", str(out)]) == 2  # by default the tap and the grasp
    err = capsys.readouterr().err
    assert "the environment has no 'grasp' behaviour" in err and "affordance reproduce --behavior tap" in err
    assert not out.exists()  # refused before anything was collected
    assert main(["reproduce", "--behavior", "tap", "--behavior", "push", "--dataset", "d", "--out", str(out)]) == 2
    assert "as BEHAVIOR=PATH" in capsys.readouterr().err
    assert main(["reproduce", "--behavior", "tap", "--dataset", "push=d", "--out", str(out)]) == 2
    assert "datasets given for ['push'], which are not run" in capsys.readouterr().err and not out.exists()


def test_collect_command(tmp_path, capsys):
    out = tmp_path / "d"
    args = ["collect", "--episodes", "6", "--out", str(out), "--camera-width", "32", "--camera-height", "32",
            "--chunk-size", "3"]
    assert main(args) == 0
    assert "6 interactions" in capsys.readouterr().out
    assert main([*args[:5], "--seed", "9", *args[5:]]) == 2  # other settings: refused, not mixed in
    assert "other settings" in capsys.readouterr().err
    damaged = out / "chunk-00001.parquet"
    damaged.write_bytes(damaged.read_bytes()[:-100])
    assert main(args) == 0  # the damaged chunk is collected again, and said so in one line, not a raw warning
    said = [line for line in capsys.readouterr().err.splitlines() if not line.startswith("d: ")]  # no progress
    assert len(said) == 1 and said[0].startswith("affordance: warning: collecting chunk-00001.parquet again: "), said


def test_an_unreachable_dask_scheduler_is_one_line_and_leaves_nothing(tmp_path, capsys):
    pytest.importorskip("distributed")
    import dask

    out = tmp_path / "d"
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        assert main(["collect", "--episodes", "2", "--out", str(out), "--dask-address", "tcp://127.0.0.1:1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("affordance: error: ") and err.count("\n") == 1 and "tcp://127.0.0.1:1" in err, err
    assert not out.exists()


@pytest.mark.parametrize(("argv", "line"), [
    (["demo"], "affordance: interrupted"),
    (["export", "taps", "--minari", "tap-affordance/taps-v0"],
     "affordance: interrupted; an unfinished export leaves no Minari dataset"),
    (["compare", "a", "b"], "affordance: interrupted"),
    (["collect", "--episodes", "2", "--out", "taps"], "affordance: interrupted; what was finished is kept (the same "
     "command resumes a collection from its last finished chunk)"),
])
def test_ctrl_c_says_what_the_command_leaves(argv, line, tmp_path, capsys, monkeypatch):
    # export and demo once said that the same command resumes a collection, though they collect nothing
    import affordance_env.collect_cli as collect_cli
    import affordance_learning.cli as cli

    def interrupted(args):
        raise KeyboardInterrupt

    for module, name in ((cli, "_demo"), (cli, "_compare"), (collect_cli, "run_export"),
                         (collect_cli, "run_collect")):
        monkeypatch.setattr(module, name, interrupted)
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 130
    assert capsys.readouterr().err == line + "\n"


def test_train_default_checks_the_behaviour_before_collecting(tmp_path, capsys, monkeypatch):
    import json

    import affordance_env.behaviors as env_behaviors
    from affordance_env.dataset.format import FORMAT, MANIFEST, SCHEMA_VERSION

    assert main(["train-default", "--behavior", "juggle", "--dataset", str(tmp_path / "d")]) == 2
    assert "Unknown behavior 'juggle'. Valid behaviors: tap, tap_back, push, grasp" in capsys.readouterr().err
    taps = tmp_path / "taps"
    taps.mkdir()
    (taps / MANIFEST).write_text(json.dumps({"format": FORMAT, "schema_version": SCHEMA_VERSION, "episodes": 6,
                                             "settings": {"chunk_size": 3, "env_options": {"behavior": "tap"}}}))
    assert main(["train-default", "--behavior", "grasp", "--dataset", str(taps), "--out", str(tmp_path / "m")]) == 2
    assert "holds 'tap' interactions, not 'grasp' ones" in capsys.readouterr().err
    monkeypatch.setattr(env_behaviors, "BEHAVIORS", {n: b for n, b in env_behaviors.BEHAVIORS.items() if n != "grasp"})
    new = tmp_path / "grasps"
    assert main(["train-default", "--behavior", "grasp", "--dataset", str(new), "--out", str(tmp_path / "m")]) == 2
    assert "the environment has no 'grasp' behaviour" in capsys.readouterr().err
    assert not new.exists() and not (tmp_path / "m").exists()


def test_version(capsys):
    from affordance_learning import __version__

    with pytest.raises(SystemExit) as exit_:
        main(["--version"])
    assert exit_.value.code == 0 and capsys.readouterr().out == f"affordance (tap-affordance) {__version__}\n"


def _read_only(monkeypatch, directory):
    """Make creating anything under ``directory`` fail as on a read-only file system (the tests may run as
    root, whom file modes do not stop)."""
    import pathlib

    mkdir, open_ = pathlib.Path.mkdir, open

    def refused(path):
        return str(path).startswith(str(directory))

    def guarded_mkdir(self, *args, **kwargs):
        if refused(self):
            raise PermissionError(30, "Read-only file system", str(self))
        return mkdir(self, *args, **kwargs)

    monkeypatch.setattr(pathlib.Path, "mkdir", guarded_mkdir)
    monkeypatch.setattr("builtins.open", lambda file, *a, **k: (_ for _ in ()).throw(
        PermissionError(30, "Read-only file system", str(file))) if refused(file) and "w" in (a[:1] or (k.get(
            "mode", "r"),))[0] else open_(file, *a, **k))


def test_paths_that_cannot_be_used_are_one_line_errors(tmp_path, capsys, monkeypatch):
    a_file = tmp_path / "notes.txt"
    a_file.write_text("mine")
    small = ["--camera-width", "32", "--camera-height", "32"]
    # each names the option whose path it is
    for command in (["collect", "--episodes", "2"], ["plan"], ["reproduce"]):
        assert main([*command, "--out", str(a_file / "taps"), *(small if command[0] == "collect" else [])]) == 2
        assert capsys.readouterr().err == (f"affordance: error: --out {a_file / 'taps'} cannot be written: {a_file} "
                                           "is a file, not a directory.\n")
    assert main(["train-default", "--out", str(a_file / "m.joblib")]) == 2
    assert capsys.readouterr().err == (f"affordance: error: --out {a_file / 'm.joblib'} cannot be written: {a_file} "
                                       "is a file, not a directory.\n")
    read_only = tmp_path / "read-only"
    _read_only(monkeypatch, read_only)
    assert main(["collect", "--episodes", "2", "--out", str(read_only / "taps"), *small]) == 2
    assert capsys.readouterr().err == (f"affordance: error: --out {read_only / 'taps'} cannot be written: "
                                       f"{read_only / 'taps'} (Read-only file system).\n")
    assert main(["plan", "--out", str(read_only / "plan")]) == 2
    assert capsys.readouterr().err == (f"affordance: error: --out {read_only / 'plan'} cannot be written: "
                                       f"{read_only / 'plan'} (Read-only file system).\n")
    assert main(["reproduce", "--behavior", "tap", "--episodes", "20", "--out", str(read_only / "repro")]) == 2
    assert capsys.readouterr().err == (f"affordance: error: --out {read_only / 'repro'} cannot be written: "
                                       f"{read_only / 'repro'} (Read-only file system).\n")
    assert main(["reproduce", "--behavior", "tap", "--episodes", "20", "--out", str(a_file)]) == 2
    assert capsys.readouterr().err == f"affordance: error: --out {a_file} is a file, not a directory.\n"
    # the model's place is checked before 1000 interactions are collected for it
    assert main(["train-default", "--dataset", str(tmp_path / "taps"), "--out", str(read_only / "m.joblib")]) == 2
    assert capsys.readouterr().err == (f"affordance: error: --out {read_only / 'm.joblib'} cannot be written: "
                                       f"{read_only} (Read-only file system).\n")
    assert not (tmp_path / "taps").exists()
    assert main(["export", str(tmp_path / "missing"), "--minari", "tap-affordance/y-v0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "affordance: error:" in err and "missing" in err


@pytest.mark.slow
def test_ctrl_c_exits_130_in_one_line_and_keeps_the_finished_chunks(tmp_path):
    import json
    import os
    import signal
    import subprocess
    import sys
    import time

    out = tmp_path / "taps"
    command = [sys.executable, "-c", "from affordance_learning.cli import main; raise SystemExit(main())", "collect",
               "--episodes", "60", "--chunk-size", "2", "--out", str(out), "--camera-width", "32",
               "--camera-height", "32", "--workers", "2"]
    # a process group of its own with the default SIGINT handling, so that Ctrl-C reaches it and its workers as
    # from a terminal (a test runner may have been started with SIGINT ignored)
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               preexec_fn=lambda: (os.setpgrp(), signal.signal(signal.SIGINT, signal.SIG_DFL)))
    def recorded() -> int:  # chunks the manifest records as finished (a chunk file lands just before that)
        try:
            return len(json.loads((out / "manifest.json").read_text()).get("chunk_sha256", {}))
        except (OSError, ValueError):  # not written yet, or being replaced
            return 0

    deadline = time.time() + 120
    while time.time() < deadline and recorded() < 1:
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130
    lines = err.splitlines()  # progress lines (no terminal here), then one line about the interruption
    assert lines[-1].startswith("affordance: interrupted; what was finished is kept"), err
    assert all(line.startswith("taps: ") for line in lines[:-1]), err
    kept = json.loads((out / "manifest.json").read_text())["chunk_sha256"]
    assert 1 <= len(kept) < 30 and all((out / name).exists() for name in kept)
    from affordance_env.dataset import load_dataset

    assert len(load_dataset(out, allow_incomplete=True)) >= 1  # what was finished reads back, checked


@pytest.mark.parametrize("delay", [0.15, 0.4, 0.8, 1.5])
def test_ctrl_c_during_export_is_one_line_and_130_at_any_moment(delay, tmp_path):
    # Ctrl-C once gave a traceback while the command's modules were imported (mujoco's raised ImportError from it)
    import os
    import signal
    import subprocess
    import sys
    import time

    pytest.importorskip("minari")
    dataset = tmp_path / "taps"
    assert main(["collect", "--episodes", "2", "--out", str(dataset), "--camera-width", "32", "--camera-height",
                 "24"]) == 0
    env = {**os.environ, "MINARI_DATASETS_PATH": str(tmp_path / "minari")}
    command = [sys.executable, "-c", "from affordance_learning.cli import main; raise SystemExit(main())", "export",
               str(dataset), "--minari", "tap-affordance/interrupted-v0"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
                               preexec_fn=lambda: (os.setpgrp(), signal.signal(signal.SIGINT, signal.SIG_DFL)))
    time.sleep(delay)
    os.killpg(process.pid, signal.SIGINT)
    out, err = process.communicate(timeout=120)
    if process.returncode == 0:  # the export was over before Ctrl-C came
        assert err == "" and "Minari dataset" in out
    else:
        assert process.returncode == 130, err
        assert err.splitlines() == [err.strip()] and err.startswith("affordance: interrupted"), err
