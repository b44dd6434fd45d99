"""Typed errors: each package raises its own, the CLI reports only those (and OSError) as a user's mistake."""

import ast
from pathlib import Path

import pytest

import affordance_env.exceptions as env_errors
import affordance_learning.common.exceptions as learning_errors
from affordance_learning import cli

ROOT = Path(__file__).resolve().parent.parent


def test_every_error_derives_from_its_package_base_and_the_builtin_callers_expect():
    assert issubclass(env_errors.InvalidValueError, env_errors.AffordanceEnvError)
    assert issubclass(env_errors.InvalidValueError, ValueError)
    assert issubclass(env_errors.DatasetError, env_errors.InvalidValueError)
    assert issubclass(env_errors.IncompatibleStateError, env_errors.InvalidValueError)
    assert issubclass(env_errors.MissingDependencyError, ImportError)
    assert issubclass(learning_errors.InvalidValueError, learning_errors.AffordanceLearningError)
    assert issubclass(learning_errors.InvalidValueError, ValueError)
    assert issubclass(learning_errors.DefaultModelMissingError, FileNotFoundError)
    from affordance_learning import DefaultModelMissingError

    assert DefaultModelMissingError is learning_errors.DefaultModelMissingError


def test_one_invalid_value_error_under_one_base_for_both_packages():
    assert learning_errors.InvalidValueError is env_errors.InvalidValueError
    assert learning_errors.AffordanceLearningError is env_errors.AffordanceLearningError
    for base in (env_errors.AffordanceEnvError, learning_errors.AffordanceLearningError):
        assert issubclass(base, env_errors.AffordanceError)
    assert issubclass(learning_errors.DefaultModelError, env_errors.AffordanceError)
    assert not issubclass(learning_errors.DefaultModelError, env_errors.AffordanceEnvError)
    assert not issubclass(env_errors.MissingDependencyError, learning_errors.AffordanceLearningError)


def test_the_packages_raise_no_untyped_value_error():
    untyped = [f"{path.relative_to(ROOT)}:{node.lineno}"
               for package in ("affordance_env", "affordance_learning")
               for path in sorted((ROOT / package).rglob("*.py"))
               for node in ast.walk(ast.parse(path.read_text()))
               if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call)
               and isinstance(node.exc.func, ast.Name) and node.exc.func.id == "ValueError"]
    assert untyped == [], "raise the package's InvalidValueError (its exceptions module)"


@pytest.mark.parametrize("error", [env_errors.InvalidValueError("bad --thing 3: expected 1 or 2"),
                                   learning_errors.InvalidValueError("bad --thing 3: expected 1 or 2"),
                                   FileNotFoundError(2, "No such file or directory", "nowhere")])
def test_a_users_mistake_is_one_line_and_status_2(error, monkeypatch, capsys):
    def fails(args):
        raise error

    parser = cli.build_parser
    monkeypatch.setattr(cli, "build_parser", lambda: _with_func(parser(), fails))
    assert cli.main(["compare", "a", "b"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("affordance: error: ")


@pytest.mark.parametrize("bug", [ValueError("a bug deep inside"), KeyError("x"), TypeError("y")])
def test_a_bug_keeps_its_traceback(bug, monkeypatch):
    def fails(args):
        raise bug

    parser = cli.build_parser
    monkeypatch.setattr(cli, "build_parser", lambda: _with_func(parser(), fails))
    with pytest.raises(type(bug)):
        cli.main(["compare", "a", "b"])


def _with_func(parser, func):
    parser.set_defaults(func=func)
    for action in parser._subparsers._group_actions:  # the subcommands' own defaults win over the parser's
        for sub in action.choices.values():
            sub.set_defaults(func=func)
    return parser


def test_the_lazy_package_still_reaches_its_submodules():
    import affordance_learning

    assert affordance_learning.paper.model.AffordanceModel is affordance_learning.AffordanceModel
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        affordance_learning.nothing  # noqa: B018
