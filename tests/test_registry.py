"""One registry of names: every part of the package offers exactly the behaviours and environments it lists."""

import gymnasium as gym
import pytest

from affordance_env import registry
from affordance_env.behaviors import BEHAVIORS as ENV_BEHAVIORS
from affordance_env.dataset.format import ENV_IDS
from affordance_learning.common.behaviors import OUTCOME_WORDS, check_behavior


def test_every_part_offers_the_registrys_behaviours():
    names = registry.BEHAVIOR_NAMES
    assert tuple(ENV_BEHAVIORS) == names
    assert all(ENV_BEHAVIORS[name].name == name for name in names)  # each module defines what the registry names
    assert tuple(OUTCOME_WORDS) == names
    assert set(registry.BEHAVIOR_ARMS.values()) <= {"right", "left"}


def test_every_registered_id_is_a_gymnasium_env():
    import affordance_env  # noqa: F401  (registers them)

    assert ENV_IDS == registry.ENV_IDS and all(env_id in gym.registry for env_id in registry.ENV_IDS)


@pytest.mark.parametrize("check", [registry.check_behavior_name, check_behavior])
def test_an_unknown_name_is_refused_with_the_valid_ones(check):
    assert check("push") == "push"
    with pytest.raises(ValueError, match="Unknown behavior 'kick'. Valid behaviors: tap, tap_back, push, grasp"):
        check("kick")
    with pytest.raises(ValueError, match="Valid ids: TapAffordance-v2, TapAffordanceGoal-v2"):
        registry.check_env_id("TapAffordance-v0")


def test_collect_takes_every_env_option_as_a_flag():
    import argparse
    import dataclasses

    from affordance_env.collect_cli import add_collect_parser, env_options_from_args
    from affordance_env.options import EnvOptions

    parser = argparse.ArgumentParser()
    add_collect_parser(parser.add_subparsers())
    names = [f.name for f in dataclasses.fields(EnvOptions)]
    argv = ["collect", "--episodes", "1", "--out", "x"]
    assert set(names) <= set(vars(parser.parse_args(argv)))  # a flag for every option, unset by default
    assert env_options_from_args(parser.parse_args([*argv, "--camera-width", "40"])) == {"camera_width": 40}


@pytest.mark.parametrize("env_class", ["TapAffordanceEnv", "TapAffordanceGoalEnv"])
def test_every_env_takes_the_data_options_with_their_defaults(env_class):
    # The constructors spell their keyword arguments out (Gymnasium's style), but each data option is one of them
    # with EnvOptions' default: a new option, or a changed default, cannot be forgotten in an env.
    import dataclasses
    import inspect

    from affordance_env.goal_env import TapAffordanceGoalEnv
    from affordance_env.options import EnvOptions
    from affordance_env.tap_env import TapAffordanceEnv

    env = {"TapAffordanceEnv": TapAffordanceEnv, "TapAffordanceGoalEnv": TapAffordanceGoalEnv}[env_class]
    parameters = inspect.signature(env).parameters
    for field in dataclasses.fields(EnvOptions):
        if field.name in ("behavior", "two_arms") and env is TapAffordanceGoalEnv:  # every behaviour, both arms
            assert field.name not in parameters
            continue
        assert parameters[field.name].default == field.default, field.name
