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


def test_reproduce_writes_results_figures_and_report(tmp_path, capsys):
    import json

    out = tmp_path / "repro"
    assert main(["reproduce", "--episodes", "40", "--trials", "2", "--workers", "1", "--out", str(out),
                 "--progress"]) == 0
    results = json.loads((out / "results.json").read_text())
    assert set(results["uniformity"]) == {str(k) for k in range(2, 11)}
    assert set(results["svm_accuracy"]) == {"0.0", "0.2", "0.4", "0.6", "0.8"}
    assert results["config"]["episodes"] == 40
    for name in ("uniformity.png", "selected_features.png", "case_study_k2.png", "case_study_k4.png",
                 "svm_accuracy.png", "REPORT.md"):
        assert (out / name).stat().st_size > 1000
    printed = capsys.readouterr()
    assert "40 interactions, 0 failed" in printed.out
    # progress bars for each stage, and the headline numbers at the end
    assert all(stage in printed.err for stage in ("dataset", "learning trials", "figures"))
    assert f"Report: {out / 'REPORT.md'}" in printed.out and "uniformity:" in printed.out
    assert "the paper's claims:" in printed.out and "successes (rolled) whose object is seen" in printed.out
    # a second run reuses the dataset instead of collecting again: its chunk files are not rewritten
    chunks = {p: p.stat().st_mtime_ns for p in (out / "dataset").glob("chunk-*.parquet")}
    assert main(["reproduce", "--episodes", "40", "--trials", "1", "--workers", "1", "--out", str(out)]) == 0
    assert "40 interactions" in capsys.readouterr().out
    assert chunks and {p: p.stat().st_mtime_ns for p in chunks} == chunks


def test_collect_command(tmp_path, capsys):
    out = tmp_path / "d"
    args = ["collect", "--episodes", "6", "--out", str(out), "--camera-width", "32", "--camera-height", "32",
            "--chunk-size", "3"]
    assert main(args) == 0
    assert "6 interactions" in capsys.readouterr().out
    assert main([*args[:5], "--seed", "9", *args[5:]]) == 2  # other settings: refused, not mixed in
    assert "other settings" in capsys.readouterr().err
