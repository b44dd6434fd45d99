"""The planner's search over the action, the effect model's per-leaf sums it scores with, and what a decision
asks of ``feasible``: on synthetic models whose answer is known, without the simulator."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from affordance_env.registry import BEHAVIOR_NAMES
from affordance_learning.planning.effect_model import ActionEffectModel
from affordance_learning.planning.goals import Move, Place, Roll
from affordance_learning.planning.planner import EVALUATIONS, Planner


def _pick_and_place(n: int = 800, seed: int = 0, rolls: float = 0.1) -> tuple[np.ndarray, pd.DataFrame]:
    """Objects seen through 2 features (size, noise); a small one (size < 0) is put down 0.2 m times the first two
    parameters away (+- 1 mm), a large one stays; a share ``rolls`` of the small ones roll away 10 cm along +y
    instead."""
    rng = np.random.default_rng(seed)
    size, params = rng.uniform(-1, 1, n), rng.uniform(-1, 1, (n, 3))
    lifted = size < 0
    rolled = lifted & (rng.uniform(size=n) < rolls)
    move = np.where(lifted[:, None], 0.2 * params[:, :2], 0.0) + rng.normal(0, 0.001, (n, 2))
    move[rolled] = [0.0, 0.1]
    X = np.column_stack([size, rng.normal(size=n), params])
    Y = pd.DataFrame({"dx": move[:, 0], "dy": move[:, 1], "rolled": rolled.astype(float), "off_table": np.zeros(n),
                      "lifted": lifted.astype(float), "effect_a": np.zeros(n), "effect_b": np.zeros(n)})
    return X, Y


@pytest.fixture(scope="module")
def placing():
    X, Y = _pick_and_place()
    return ActionEffectModel(n_estimators=50, random_state=0).fit(X, Y)


def test_kind_moments_are_the_moments_of_the_predictive_outcomes(placing):
    Xq, _ = _pick_and_place(40, seed=1)
    outcomes, moments = placing.predictive_outcomes(Xq), placing.kind_moments(Xq)
    kinds, w, query = placing.kinds_[outcomes.weights.indices], outcomes.weights.data, outcomes.query
    np.testing.assert_allclose(moments.mass.sum(axis=1), 1.0)
    for c in range(len(moments.flags)):
        sel = kinds == c
        mass = np.bincount(query[sel], weights=w[sel], minlength=len(Xq))
        np.testing.assert_allclose(moments.mass[:, c], mass, atol=1e-12)
        some = mass > 0.05
        mean = np.column_stack([np.bincount(query[sel], weights=w[sel] * outcomes.displacement[sel, j],
                                            minlength=len(Xq)) for j in range(2)])[some] / mass[some, None]
        np.testing.assert_allclose(moments.mean[some, c], mean, atol=1e-4)  # to 0.1 mm
        d = outcomes.displacement[sel] - np.column_stack(
            [np.bincount(query[sel], weights=w[sel] * outcomes.displacement[sel, j], minlength=len(Xq))
             for j in range(2)])[query[sel]] / np.maximum(mass[query[sel], None], 1e-300)
        variance = np.bincount(query[sel], weights=w[sel] * (d**2).sum(axis=1), minlength=len(Xq))[some]
        np.testing.assert_allclose(np.trace(moments.covariance[some, c], axis1=1, axis2=2),
                                   variance / mass[some], atol=1e-6)
    lifted = moments.flag("lifted")
    assert lifted.any() and not lifted.all()
    # a value that does not follow the action: its share from the leaves is the share of the outcomes
    rolled = placing.outcomes_[:, placing.outcome_names_.index("rolled")]
    np.testing.assert_allclose(placing.leaf_share(Xq, rolled), outcomes.share(outcomes["rolled"]), atol=1e-12)
    with pytest.raises(ValueError, match="one number per training outcome"):
        placing.leaf_share(Xq, rolled[:-1])


def test_the_search_places_nearer_than_the_grid_where_the_answer_is_known():
    placing = ActionEffectModel(n_estimators=50, random_state=0).fit(*_pick_and_place(rolls=0.0))
    start = np.array([-0.45, 0.0])
    rng = np.random.default_rng(3)
    shifts = rng.uniform(-0.15, 0.15, (16, 2))
    errors = {}
    for optimizer in ("cem", "grid"):
        planner = Planner({"grasp": placing}, optimizer=optimizer)
        chosen = [planner.choose(np.array([-0.5, 0.0]), Place(tuple(start + shift), 0.03), start).params
                  for shift in shifts]
        errors[optimizer] = np.linalg.norm(0.2 * np.array(chosen)[:, :2] - shifts, axis=1)
    # where the chosen action puts the object: the search a median 2.5 mm off (the model's own error), the grid
    # (refined around its best candidate) 7.9 mm
    assert np.median(errors["cem"]) < 0.004 and errors["cem"].max() < 0.015
    assert np.median(errors["cem"]) < np.median(errors["grid"]) / 2


def test_the_search_spends_its_budget_and_is_the_same_for_a_seed(placing):
    models = dict.fromkeys(BEHAVIOR_NAMES, placing)
    goal, start, features = Place((-0.4, 0.05), 0.03), np.array([-0.45, 0.0]), np.array([-0.5, 0.0])
    first = Planner(models, random_state=4).choose(features, goal, start)
    again = Planner(models, random_state=4).choose(features, goal, start)
    other = Planner(models, random_state=5).choose(features, goal, start)
    assert first.evaluations == again.evaluations == EVALUATIONS >= 1000
    assert first.behavior == again.behavior and np.array_equal(first.params, again.params)
    assert not np.array_equal(first.params, other.params)  # another seed draws other actions
    grid = Planner(models, optimizer="grid").choose(features, goal, start)
    assert grid.evaluations == len(BEHAVIOR_NAMES) * 64 + 16
    roll = Planner(models).choose(features, Roll(), start)  # a goal without a distance: P from the leaves
    grid_roll = Planner(models, optimizer="grid").choose(features, Roll(), start)
    assert roll.evaluations == EVALUATIONS and roll.probability >= grid_roll.probability > 0


def test_toward_and_choose_name_an_action_while_any_behaviour_has_a_feasible_one(placing):
    models = dict.fromkeys(BEHAVIOR_NAMES, placing)
    features, start = np.array([-0.5, 0.0]), np.array([-0.45, 0.0])
    asked = []

    planner = Planner(models, max_checks=6)
    for behavior in BEHAVIOR_NAMES:  # whichever behaviour the ranking puts where
        def only_near_canonical(name, params, behavior=behavior):  # every other behaviour and region out of reach
            asked.append(name)
            return name == behavior and np.linalg.norm(params) < 0.3

        decisions = [lambda: planner.toward(features, start, (-0.35, 0.05), 0.03, feasible=only_near_canonical)]
        if behavior in ("tap", "draw"):
            decisions += [lambda: planner.choose(features, Place((-0.35, 0.05), 0.03), start,
                                                 feasible=only_near_canonical),
                          lambda: planner.choose(features, Move((1.0, 0.0), 0.1), start, feasible=only_near_canonical)]
        for decide in decisions:
            asked.clear()
            choice = decide()
            assert choice.behavior == behavior and np.linalg.norm(choice.params) < 0.3, (behavior, choice)
            assert choice.checked == len(asked) <= 6
    # with fewer checks than behaviours: never more than max_checks
    few = Planner(models, max_checks=2).toward(features, start, (-0.35, 0.05), 0.03, feasible=only_near_canonical)
    assert few.checked <= 2


def test_a_choice_without_an_action_has_none_and_says_why_and_checks_stay_within_max_checks(placing):
    models = dict.fromkeys(BEHAVIOR_NAMES, placing)
    features, start, goal = np.array([-0.5, 0.0]), np.array([-0.45, 0.0]), Place((-0.35, 0.05), 0.03)
    for optimizer in ("cem", "grid"):
        planner = Planner(models, max_checks=4, optimizer=optimizer)
        none = planner.choose(features, goal, start, feasible=lambda name, params: False)
        assert none.behavior is None and none.params is None and none.abstained and "feasible" in none.reason
        assert none.checked == 4
        far = planner.toward(features, start, (-0.35, 0.05), 0.03, feasible=lambda name, params: False)
        assert far.params is None and far.checked == 4 and far.reason
    # the grid's refinement asks within max_checks: one check, accepted, leaves none to refine with
    one = Planner({"grasp": placing}, max_checks=1, optimizer="grid")
    calls = []
    choice = one.choose(features, goal, start, feasible=lambda name, params: calls.append(name) or True)
    assert choice.checked == len(calls) == 1 and choice.probability > 0.5 and not choice.reason
    # below the threshold the choice still names its action, and says why it abstains
    unlikely = Planner({"grasp": placing}).choose(np.array([0.5, 0.0]), goal, start)  # a large object stays
    assert unlikely.abstained and unlikely.params is not None and "threshold" in unlikely.reason
    with pytest.raises(ValueError, match="optimizer"):
        Planner(models, optimizer="annealing")


def _mover(dx: float, dy: float, n: int = 300, seed: int = 0) -> ActionEffectModel:
    """A behaviour that moves every object by (dx, dy) [m], whatever its 2 features and the 3 parameters."""
    rng = np.random.default_rng(seed)
    X = np.column_stack([rng.uniform(-0.2, 0.2, n), rng.normal(size=n), rng.uniform(-1, 1, (n, 3))])
    Y = pd.DataFrame({"dx": dx + rng.normal(0, 1e-4, n), "dy": dy + rng.normal(0, 1e-4, n), "rolled": np.zeros(n),
                      "off_table": np.zeros(n), "lifted": np.zeros(n), "effect_x": np.zeros(n),
                      "effect_n": np.zeros(n)})
    return ActionEffectModel(n_estimators=30, random_state=seed).fit(X, Y)


def test_toward_first_moves_the_object_where_a_behaviour_can_act_toward_the_target():
    # The target lies 15 cm toward the robot; only the draw brings an object that way, and it acts only on objects
    # right of y = 0.03 (not where this one is). A tap moves it 5 cm right, where the draw can; a push 2 cm
    # toward the robot (nearer the target after one interaction, 13 cm, but where nothing can draw it further).
    planner = Planner({"tap": _mover(0.0, 0.05), "push": _mover(0.02, 0.0, seed=1),
                       "draw": _mover(0.15, 0.0, seed=2)})
    features, start, target = np.array([0.0, 0.0]), (-0.45, 0.0), (-0.30, 0.0)

    def reachable(name, xy):
        return xy[:, 1] > 0.03 if name == "draw" else np.ones(len(xy), bool)

    def feasible(name, params):  # the draw cannot reach the object where it is
        return name != "draw"

    greedy = planner.toward(features, start, target, 0.03, feasible=feasible, steps_left=1, reachable=reachable)
    assert greedy.behavior == "push"  # the nearest after one interaction
    ahead = planner.toward(features, start, target, 0.03, feasible=feasible, reachable=reachable)
    assert ahead.behavior == "tap" and ahead.expected_distance < 0.06  # a tap then a draw: 5 cm off
    assert planner.toward(features, start, target, 0.03, feasible=feasible, steps_left=3,
                          reachable=reachable).behavior == "tap"  # the horizon follows steps_left


def test_refused_actions_leave_a_near_feasible_one_of_the_search_asked_before_a_worse_behaviour(placing):
    # The search's best grasps are refused (a place beyond the arm's reach); a feasible one lies 0.54 from the
    # first refused, nearer than REFUSAL_RADIUS: the search asks it before falling to a worse behaviour, the
    # grid (whose candidates lie far apart) does not.
    candidates = {"grasp": np.array([[0.5, -0.85, 1.0], [0.54, -0.89, -0.26], [0.29, -0.76, 0.51], [0.0, 0.0, 0.0]]),
                  "tap": np.zeros((1, 3))}
    likely = [(1.0, "grasp", 0), (0.9, "grasp", 1), (0.8, "grasp", 2)]  # as toward's sequences, then the nearest
    rankings = [likely, [*likely, (0.1, "tap", 0), (0.0, "grasp", 3)]]
    refused = {(0.5, -0.85, 1.0), (0.54, -0.89, -0.26)}

    def feasible(name, params):
        return tuple(np.round(params, 2)) not in refused

    models = {"grasp": placing, "tap": placing}
    found, checked = Planner(models)._search(rankings, feasible, set(), candidates)
    assert found[-2:] == ("grasp", 2) and checked == 3
    found, _ = Planner(models, optimizer="grid")._search(rankings, feasible, set(), candidates)
    assert found[-2:] == ("tap", 0)


def test_a_behaviour_refused_again_and_again_leaves_the_checks_to_the_others(placing):
    far = np.array([[-0.9, -0.9, -0.9], [0.9, 0.9, 0.9], [-0.9, 0.9, 0.9], [0.9, -0.9, -0.9], [0.9, 0.9, -0.9],
                    [-0.9, -0.9, 0.9], [0.0, 0.0, 0.0]])
    candidates = {"draw": far, "tap": np.array([[0.5, 0.5, 0.5], [0.0, 0.0, 0.0]])}
    ranked = [*((1.0 - 0.01 * k, "draw", k) for k in range(6)), (0.2, "tap", 0), (0.0, "draw", 6), (0.0, "tap", 1)]
    asked = []

    def feasible(name, params):  # the object is out of the draw's reach
        asked.append(name)
        return name != "draw"

    found, checked = Planner({"draw": placing, "tap": placing})._search([ranked], feasible, set(), candidates)
    assert found[-2:] == ("tap", 0) and asked.count("draw") == 3 and checked == 4
