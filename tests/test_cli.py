"""The ``affordance`` command line."""

import pytest

from affordance_env.cli import main


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
