"""Goals, action-conditioned effect models and the planner, on outcomes made without the simulator."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
from scipy import sparse

from affordance_env.registry import BEHAVIOR_NAMES
from affordance_learning.planning.effect_model import ActionEffectModel
from affordance_learning.planning.goals import Lift, Move, Percept, Place, Roll, goal_from_dict
from affordance_learning.planning.outcomes import MOTION_COLUMNS
from affordance_learning.planning.planner import (
    MAX_CHECKS,
    PROBE_RADIUS,
    PROBES,
    RANKED_CHECKS,
    REFUSAL_RADIUS,
    SCENE_TABLE,
    Planner,
    candidate_params,
)


def synthetic(n: int = 600, seed: int = 0, push: float = 0.12) -> tuple[np.ndarray, pd.DataFrame]:
    """Objects at x on a line, seen through 3 features (x, round, noise); params (a0, a1, a2). The object moves
    dx = push * a0 (+ noise), and a round object rolls (and moves twice as far) when a1 > 0."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(-0.4, -0.2, n)
    round_ = rng.integers(0, 2, n).astype(float)
    params = rng.uniform(-1, 1, (n, 3))
    rolled = (round_ == 1) & (params[:, 1] > 0)
    dx = push * params[:, 0] * (1 + rolled) + rng.normal(0, 0.005, n)
    X = np.column_stack([x, round_, rng.normal(size=n), params])
    Y = pd.DataFrame({"dx": dx, "dy": np.zeros(n), "rolled": rolled.astype(float), "off_table": np.zeros(n),
                      "lifted": np.zeros(n), "effect_a": dx, "effect_b": round_})
    return X, Y


@pytest.fixture(scope="module")
def model():
    X, Y = synthetic()
    return ActionEffectModel(n_estimators=100, random_state=0).fit(X, Y)


def test_goals_round_trip_through_json_and_refuse_bad_fields():
    goals = [Roll(), Lift(), Move((0.0, -2.0), 0.05), Place((-0.3, 0.1), 0.03), Percept((0.1, -0.2), 0.5, (1.0, 2.0))]
    for goal in goals:
        assert goal_from_dict(json.loads(json.dumps(goal.to_dict()))) == goal
    assert Move((0.0, -2.0)).direction == (0.0, -1.0)  # normalised
    with pytest.raises(ValueError, match="kind"):
        goal_from_dict({"kind": "fly"})
    with pytest.raises(ValueError, match="non-zero"):
        Move((0.0, 0.0))
    with pytest.raises(ValueError, match="tolerance must be a distance in metres"):
        Place((-0.3, 0.0), -1.0)
    with pytest.raises(ValueError, match="start_xy"):
        Place((-0.3, 0.0)).reached({"dx": [0.0], "dy": [0.0], "off_table": [False]})


def test_goals_refuse_what_cannot_be_metres_on_the_table():
    """The table top is x in [-0.76, -0.16], y in [-0.5, 0.5] (1.17 m across): a distance, a place or a tolerance
    in centimetres, given as metres, is refused with the value and the unit expected."""
    from affordance_learning.planning.goals import MAX_TOLERANCE, table_diagonal

    assert table_diagonal() == pytest.approx(np.hypot(0.6, 1.0))
    with pytest.raises(ValueError, match=r"min_distance must be a distance in metres on the table, in \(0, 1.17\] m "
                                         r"\(the table's diagonal\), got 5"):
        Move((2, 0), 5)
    with pytest.raises(ValueError, match="min_distance must be a distance in metres"):
        Move((1, 0), 0.0)
    assert Move((1, 0), 1.1).min_distance == 1.1  # corner to corner, nearly
    with pytest.raises(ValueError, match=r"target_xy must be \(x, y\) \[m\] on the table top, x in \[-0.76, -0.16\] "
                                         r"and y in \[-0.50, 0.50\].*got \(-30, 10\)"):
        Place((-30, 10))
    with pytest.raises(ValueError, match="target_xy must be .* got \\(0.0, 0.0\\): 16 cm off the table"):
        Place((0.0, 0.0))
    assert Place((-0.14, 0.0), 0.03).target_xy == (-0.14, 0.0)  # 2 cm beyond the edge: within 3 cm of the rim
    with pytest.raises(ValueError, match="target_xy"):
        Place((-0.14, 0.0), 0.01)
    with pytest.raises(ValueError, match=r"tolerance must be a distance in metres, in \(0, 0.5\] m, got 3"):
        Place((-0.3, 0.0), 3)
    assert Place((-0.3, 0.0), MAX_TOLERANCE).tolerance == 0.5
    with pytest.raises(ValueError, match="min_distance must be a distance in metres"):
        goal_from_dict({"kind": "move", "direction": [1, 0], "min_distance": 5})


def test_goals_judge_outcomes():
    outcomes = pd.DataFrame({"dx": [0.06, 0.06, -0.10], "dy": [0.0, 0.0, 0.0], "rolled": [True, True, False],
                             "off_table": [False, True, False], "lifted": [False, False, True],
                             "effect_a": [0.0, 1.0, 3.0]})
    np.testing.assert_array_equal(Move((1, 0), 0.05).reached(outcomes), [True, False, False])  # off the table
    np.testing.assert_array_equal(Roll().reached(outcomes), [True, False, False])
    np.testing.assert_array_equal(Lift().reached(outcomes), [False, False, True])
    np.testing.assert_array_equal(Place((-0.2, 0.0), 0.03).reached(outcomes, (-0.26, 0.0)), [True, False, False])
    np.testing.assert_array_equal(Percept((1.0,), 0.5).reached(outcomes), [False, True, False])


def test_goals_measure_their_own_progress_and_name_what_a_planner_needs():
    # The planner and the evaluation ask each goal, never which class it is.
    outcomes = {"dx": np.array([0.06, 0.06, -0.10]), "dy": np.array([0.0, 0.08, 0.0]),
                "off_table": np.array([False, True, False]), "rolled": np.zeros(3), "lifted": np.zeros(3)}
    np.testing.assert_allclose(Move((1, 0), 0.05).progress(outcomes), [0.06, -1.0, -0.10])  # off: a metre away
    np.testing.assert_allclose(Place((-0.2, 0.0), 0.03).progress(outcomes, (-0.26, 0.0)), [0.0, -1.0, -0.16],
                               atol=1e-12)
    with pytest.raises(ValueError, match="start_xy"):
        Place((-0.2, 0.0)).progress(outcomes)
    goals = [Roll(), Lift(), Move((1, 0)), Place((-0.2, 0.0)), Percept((1.0,))]
    for goal in goals:
        assert (goal.progress(outcomes, (-0.26, 0.0)) is not None) == goal.has_distance, goal
    assert [g.kind for g in goals if g.needs_start] == [g.kind for g in goals if g.ranks_by_progress] == ["place"]
    assert [g.positions() for g in goals] == [{}, {}, {}, {"target_xy": (-0.2, 0.0)}, {}]
    assert [g.placement_error((-0.2, 0.04)) for g in goals] == [None, None, None, pytest.approx(0.04), None]


def test_the_model_predicts_a_distribution_that_follows_the_action(model):
    X, Y = synthetic(400, seed=1)
    weights = model.predictive_weights(X)
    np.testing.assert_allclose(weights.sum(axis=1), 1.0)
    assert model.predict(X).shape == (400, Y.shape[1])
    goal = Move((1.0, 0.0), 0.05)
    p = model.goal_probability(X, goal)
    truth = goal.reached(Y)
    assert p[truth].mean() > 0.7 > 0.2 > p[~truth].mean()
    for lo, hi in ((0.0, 0.2), (0.8, 1.0)):  # calibrated where it is sure
        sure = (p >= lo) & (p <= hi)
        assert abs(truth[sure].mean() - p[sure].mean()) < 0.1
    samples = model.sample(X[:5], 50, random_state=0)
    assert samples.shape == (5, 50, Y.shape[1])
    assert set(np.unique(samples[:, :, 2])) <= {0.0, 1.0}  # whole training outcomes, not averages


def test_the_planner_chooses_the_action_that_makes_the_goal_likely(model):
    planner = Planner({"push": model}, n_candidates=32, threshold=0.5)
    features = np.array([-0.3, 1.0, 0.0])  # a round object
    choice = planner.choose(features, Move((1.0, 0.0), 0.15))  # only reached by rolling it: a0 > 0.6, a1 > 0
    assert not choice.abstained and choice.behavior == "push"
    assert choice.params[0] > 0.5 and choice.params[1] > 0 and choice.probability > 0.5
    flat = planner.choose(np.array([-0.3, 0.0, 0.0]), Move((1.0, 0.0), 0.15))  # a box cannot go that far
    assert flat.abstained and flat.probability < 0.5
    refused = planner.choose(features, Move((1.0, 0.0), 0.15), feasible=lambda name, params: params[1] <= 0)
    assert refused.params[1] <= 0 and refused.checked > 1  # the likely ones were out of reach
    toward = planner.toward(features, (-0.3, 0.0), (-0.2, 0.0), 0.03, steps_left=1, reachable=None)
    assert toward.params[0] > 0 and toward.expected_distance < 0.05


def _constant_mover(dx: float, n: int = 300, seed: int = 0) -> ActionEffectModel:
    """A behaviour that moves every object by ``dx`` [m] along x, whatever its 2 features and the 3 parameters;
    its perceptual effect is the motion of the first feature."""
    rng = np.random.default_rng(seed)
    X = np.column_stack([rng.uniform(-0.2, 0.2, n), rng.normal(size=n), rng.uniform(-1, 1, (n, 3))])
    move = dx + rng.normal(0, 1e-4, n)
    Y = pd.DataFrame({"dx": move, "dy": np.zeros(n), "rolled": np.zeros(n), "off_table": np.zeros(n),
                      "lifted": np.zeros(n), "effect_x": move, "effect_n": np.zeros(n)})
    return ActionEffectModel(n_estimators=30, random_state=seed).fit(X, Y)


def test_the_planner_keeps_its_models_in_the_registrys_order_whatever_the_order_given():
    tap, push = _constant_mover(0.05), _constant_mover(0.07, seed=1)
    planner = Planner({"push": push, "tap": tap}, n_candidates=8)
    assert list(planner.models) == [b for b in BEHAVIOR_NAMES if b in ("push", "tap")] == ["tap", "push"]
    features, goal = np.array([0.0, 0.0]), Move((-1.0, 0.0), 0.01)
    assert list(planner.scores(features, goal, (-0.5, 0.0))) == ["tap", "push"]
    given = Planner({"tap": tap, "push": push}, n_candidates=8).choose(features, goal, (-0.5, 0.0))
    reordered = planner.choose(features, goal, (-0.5, 0.0))
    assert (reordered.behavior, reordered.probability) == (given.behavior, given.probability)
    assert np.array_equal(reordered.params, given.params)


def test_toward_searches_over_two_interactions_where_the_nearest_first_step_is_a_dead_end():
    # tap moves 5 cm, push 7 cm; the target is 10 cm away, the tolerance 1.5 cm. Pushing ends nearest (3 cm)
    # but no second interaction finishes from there; two taps do.
    planner = Planner({"tap": _constant_mover(0.05), "push": _constant_mover(0.07, seed=1)}, n_candidates=8)
    features, start, target = np.array([0.0, 0.0]), (-0.5, 0.0), (-0.4, 0.0)
    greedy = planner.toward(features, start, target, 0.015, steps_left=1)
    assert greedy.behavior == "push" and greedy.probability == 0.0
    ahead = planner.toward(features, start, target, 0.015, steps_left=2)
    assert ahead.behavior == "tap" and ahead.value > 0.9 and ahead.probability == 0.0
    # Where tap cannot act after the first interaction, the sequence is worth nothing; the nearest end after two
    # interactions decides: a tap then a push ends 2 cm away, a push then anything 3 cm or more.
    blocked = planner.toward(features, start, target, 0.015, steps_left=2,
                             reachable=lambda name, xy: np.full(len(xy), name != "tap"))
    assert blocked.behavior == "tap" and blocked.value == 0.0 and blocked.expected_distance < 0.025
    with pytest.raises(ValueError, match="steps_left"):
        planner.toward(features, start, target, 0.015, steps_left=0)
    # By default toward looks ahead (more interactions may follow), as a multi-step episode wants.
    default = planner.toward(features, start, target, 0.015, reachable=None)
    assert default.behavior == "tap" and default.value == ahead.value


def test_toward_by_default_looks_ahead_within_the_workspaces():
    import inspect

    from affordance_learning.planning.planner import in_workspace

    parameters = inspect.signature(Planner.toward).parameters
    assert parameters["steps_left"].default is None and parameters["reachable"].default is in_workspace
    np.testing.assert_array_equal(in_workspace("tap", np.array([[-0.3, 0.0], [-0.7, 0.4]])), [True, False])


def test_the_planner_never_chooses_again_an_action_that_failed_where_the_object_still_is(model):
    planner = Planner({"push": model}, n_candidates=32)
    features, start, goal = np.array([-0.3, 1.0, 0.0]), np.array([-0.45, 0.0]), Move((1.0, 0.0), 0.15)
    first = planner.choose(features, goal, start)
    planner.note_failure(first.behavior, first.params, start)
    second = planner.choose(features, goal, start + 0.004)  # moved 4 mm by the failed reach: the same situation
    assert second.behavior and not np.array_equal(second.params, first.params)
    planner.note_failure(second.behavior, second.params, start)
    third = planner.choose(features, goal, start)
    assert not any(np.array_equal(third.params, c.params) for c in (first, second))
    # elsewhere, the action may work: it is a candidate again; and a new object forgets every failure
    assert np.array_equal(planner.choose(features, goal, start + 0.05).params, first.params)
    toward = planner.toward(features, start, (-0.35, 0.0), 0.03, steps_left=1, reachable=None)
    planner.note_failure(toward.behavior, toward.params, start)
    again = planner.toward(features, start, (-0.35, 0.0), 0.03, steps_left=1, reachable=None)
    assert not np.array_equal(again.params, toward.params)
    planner.forget_failures()
    assert np.array_equal(planner.choose(features, goal, start).params, first.params)


def test_a_behaviour_that_failed_whatever_its_parameters_is_left_out_where_the_object_still_is(model):
    """note_failure with params None (a grasp that held nothing): no action of that behaviour is chosen again on
    the object there, by choose or toward; the other behaviours still are, and elsewhere it is again."""
    planner = Planner({"push": model, "tap": model}, n_candidates=32)
    features, start, goal = np.array([-0.3, 1.0, 0.0]), np.array([-0.45, 0.0]), Move((1.0, 0.0), 0.15)
    assert planner.choose(features, goal, start).behavior == "tap"  # the same model: the registry's first
    planner.note_failure("tap", None, start)
    assert planner.choose(features, goal, start).behavior == "push"
    assert planner.toward(features, start, (-0.35, 0.0), 0.03, steps_left=1, reachable=None).behavior == "push"
    assert planner.choose(features, goal, start + 0.05).behavior == "tap"


def test_a_decision_asks_feasible_at_most_max_checks_times_and_breaks_ties_by_progress(model):
    calls = []

    def never(name, params):
        calls.append(params)
        return False

    planner = Planner({"push": model, "tap": model, "draw": model}, n_candidates=64, max_checks=5)
    features = np.array([-0.3, 0.0, 0.0])  # a box: moving it 40 cm is out of reach, P = 0 for every candidate
    goal = Move((1.0, 0.0), 0.40)
    none = planner.choose(features, goal, feasible=never)
    assert none.behavior is None and none.checked == 5 == len(calls)
    calls.clear()
    assert planner.toward(features, (-0.3, 0.0), (-0.2, 0.0), 0.03, feasible=never, steps_left=1,
                          reachable=None).behavior is None
    assert len(calls) == 5
    # no ranked candidate near one refused is asked in the same decision: the checks go to other regions and
    # behaviours; the canonical action, kept for last, is asked whatever was refused near it
    calls.clear()
    alone = Planner({"push": model}, n_candidates=64, max_checks=12)
    assert alone.choose(features, goal, feasible=never).checked == len(calls) == 12
    first = next(i for i, c in enumerate(calls) if np.all(c == 0.0))  # the canonical action ends the ranked ones
    ranked, probes = calls[:first], calls[first + 1:]
    assert 0 < first < 12 and probes
    assert all(np.linalg.norm(a - b) >= REFUSAL_RADIUS for i, a in enumerate(ranked) for b in ranked[:i])
    # then actions spread over the parameters, each far from every one refused before it
    assert all(any(np.array_equal(p, q) for q in PROBES) for p in probes)
    assert all(min(np.linalg.norm(p - q) for q in calls[: first + 1 + i]) >= PROBE_RADIUS
               for i, p in enumerate(probes))
    names = []
    assert planner.choose(features, goal, feasible=lambda name, params: names.append(name) or name == "draw"
                          ).behavior == "draw"
    # every P is 0: the tie goes to the candidate that moves the object furthest along the goal's direction
    best = planner.choose(features, goal)
    assert best.probability == 0.0 and best.params[0] > 0.8
    with pytest.raises(ValueError, match="max_checks"):
        Planner({"push": model}, max_checks=0)


def test_where_a_behaviour_reaches_one_corner_of_its_parameters_the_probes_find_it(model):
    """A tap feasible only with its first parameter below -0.6 and its second above 0.6 (an object at the edge of
    its reach): the ranked actions and the canonical ones miss it, the probes spread over the parameters find it;
    without checks left for them the planner names no action."""
    def corner(name, params):
        return name == "tap" and params[0] < -0.6 and params[1] > 0.6

    features, start, target = np.array([-0.3, 0.0, 0.0]), (-0.3, 0.0), (-0.2, 0.0)
    models = {"push": model, "tap": model, "draw": model}
    found = Planner(models).toward(features, start, target, 0.03, feasible=corner, reachable=None)
    assert found.behavior == "tap" and corner("tap", found.params) and found.checked <= MAX_CHECKS
    chosen = Planner(models).choose(features, Move((1.0, 0.0), 0.40), feasible=corner)
    assert chosen.behavior == "tap" and corner("tap", chosen.params) and chosen.checked <= MAX_CHECKS
    # where nothing is feasible: every behaviour's probes in turn, every one not near one refused, never more
    calls = []
    nothing = Planner(models).toward(features, start, target, 0.03, reachable=None,
                                     feasible=lambda name, params: calls.append(name) and False)
    assert nothing.behavior is None and nothing.checked == len(calls) <= MAX_CHECKS
    assert set(calls[RANKED_CHECKS:]) == set(models) and len(calls) > RANKED_CHECKS + 2 * len(PROBES)
    few = Planner(models, max_checks=RANKED_CHECKS).toward(features, start, target, 0.03, feasible=corner,
                                                           reachable=None)
    assert few.behavior is None and few.checked == RANKED_CHECKS and "spread over its parameters" in few.reason


def test_goal_probabilities_from_sparse_weights_equal_the_dense_ones():
    X, Y = synthetic()
    model = ActionEffectModel(n_estimators=100, random_state=0, action_inputs=0).fit(X, Y)  # outcomes as they were
    X, _ = synthetic(50, seed=2)
    dense = model.predictive_weights(X)
    np.testing.assert_allclose(model.predictive_weights(X, as_sparse=True).toarray(), dense)
    starts = np.column_stack([np.random.default_rng(0).uniform(-0.38, -0.22, 50), np.zeros(50)])
    goal = Place((-0.3, 0.0), 0.03)
    expected = [w @ goal.reached(model.outcome_frame(), s) for w, s in zip(dense, starts, strict=True)]
    assert 0.1 < np.mean(expected) < 0.9  # a goal some reach and some miss
    np.testing.assert_allclose(model.goal_probability(X, goal, starts), expected)
    np.testing.assert_allclose(model.goal_probability(X, goal, starts[0]),
                               dense @ goal.reached(model.outcome_frame(), starts[0]))
    # each training outcome once per query, its weights summed: the same matrix as scipy's sum_duplicates
    summed = model.predictive_outcomes(X).weights
    reference = model.predictive_weights(X, as_sparse=True)
    reference.sum_duplicates()
    assert np.array_equal(summed.indptr, reference.indptr) and np.array_equal(summed.indices, reference.indices)
    np.testing.assert_allclose(summed.data, reference.data)


def _pick_and_place(n: int = 800, seed: int = 0) -> tuple[np.ndarray, pd.DataFrame]:
    """Objects seen through 2 features (size, noise); a small one (size < 0) is lifted and put down 0.2 m times
    the first two parameters away (+- 1 mm), a large one stays where it is."""
    rng = np.random.default_rng(seed)
    size, params = rng.uniform(-1, 1, n), rng.uniform(-1, 1, (n, 3))
    lifted = size < 0
    move = np.where(lifted[:, None], 0.2 * params[:, :2], 0.0) + rng.normal(0, 0.001, (n, 2))
    X = np.column_stack([size, rng.normal(size=n), params])
    Y = pd.DataFrame({"dx": move[:, 0], "dy": move[:, 1], "rolled": np.zeros(n), "off_table": np.zeros(n),
                      "lifted": lifted.astype(float), "effect_a": move[:, 0]})
    return X, Y


def test_predictive_outcomes_move_each_neighbour_to_the_query_action():
    X, Y = _pick_and_place()
    moved = ActionEffectModel(n_estimators=50, random_state=0).fit(X, Y)
    as_were = ActionEffectModel(n_estimators=50, random_state=0, action_inputs=0).fit(X, Y)
    Xq, Yq = _pick_and_place(40, seed=1)
    small = Yq["lifted"].to_numpy() > 0
    for model, within in ((moved, 0.004), (as_were, None)):
        outcomes = model.predictive_outcomes(Xq)
        lifted = outcomes["lifted"] > 0.5
        error = np.linalg.norm(outcomes.displacement - 0.2 * Xq[outcomes.query, 2:4], axis=1)
        if within is not None:  # the held objects' neighbours land where the query's action puts them
            assert np.median(error[lifted]) < within
            # the neighbours that were not lifted stay where they were: each kind of outcome has its own slope
            assert np.abs(outcomes.displacement[~lifted]).max() < 0.005
        else:  # as they were, the neighbours' actions blur the place by centimetres
            assert np.median(error[lifted]) > 0.01
    on_table = np.array([-0.46, 0.0])  # a place is on the table: 20 cm around its middle
    place = [Place(tuple(on_table + 0.2 * x[2:4]), 0.01) for x in Xq[small]]
    p_moved, p_as_were = ([model.goal_probability(x[None], goal, on_table)[0]
                           for x, goal in zip(Xq[small], place, strict=True)] for model in (moved, as_were))
    assert np.mean(p_moved) > 0.8 > 0.5 > np.mean(p_as_were)
    np.testing.assert_allclose(moved.predict(Xq)[:, 0], moved.predictive_outcomes(Xq).share(
        moved.predictive_outcomes(Xq)["dx"]))
    with pytest.raises(ValueError, match="action_inputs"):
        ActionEffectModel(action_inputs=9).fit(X, Y)
    with pytest.raises(ValueError, match="flag_weight"):
        ActionEffectModel(flag_weight=0).fit(X, Y)


def test_choose_refines_a_place_between_its_candidates():
    X, Y = _pick_and_place()
    planner = Planner({"grasp": ActionEffectModel(n_estimators=50, random_state=0).fit(X, Y)})
    rng = np.random.default_rng(3)
    start = np.array([-0.45, 0.0])  # on the table, 29 cm from its nearest edge
    errors = []
    for _ in range(20):
        shift = rng.uniform(-0.15, 0.15, 2)
        choice = planner.choose(np.array([-0.5, 0.0]), Place(tuple(start + shift), 0.03), start)
        errors.append(np.linalg.norm(0.2 * choice.params[:2] - shift))  # where this action puts the object
    # the 64 candidates lie about 0.25 apart, 5 cm of the place (a median 1.9 cm off and up to 3.1 cm without the
    # refinement): the actions scored around the best one bring it within a centimetre
    assert np.median(errors) < 0.012 and max(errors) < 0.025


def test_an_outcome_that_ends_beyond_the_table_edge_counts_as_off_the_table():
    X, Y = _pick_and_place()
    model = ActionEffectModel(n_estimators=50, random_state=0).fit(X, Y)
    (_, y_low), (x_edge, y_high) = SCENE_TABLE
    start = np.array([x_edge - 0.09, 0.0])  # a held object put down more than 9 cm toward the robot falls off
    goal, small = Move((1.0, 0.0), 0.05), np.array([-0.5, 0.0])
    for table, on_table in ((None, False), (SCENE_TABLE, True)):
        choice = Planner({"grasp": model}, table=table).choose(small, goal, start)
        end = start[0] + 0.2 * choice.params[0]  # where the chosen action puts the object
        # without the table the furthest move ranks first, over the edge; with it, one that stays on the table
        assert choice.probability > 0.8 and (end <= x_edge - 0.005) == on_table, (table, end)
    actions = np.array([[0.2, 0.0, 0.0], [0.5, 0.0, 0.0]])  # 4 cm and 10 cm toward the robot
    outcomes = model.predictive_outcomes(np.column_stack([np.repeat(small[None], 2, axis=0), actions]))
    bounded = outcomes.off_beyond(start, (-0.76, y_low), (x_edge, y_high))
    beyond = start[0] + outcomes.displacement[:, 0] > x_edge
    assert beyond.any() and not outcomes["off_table"].any()
    np.testing.assert_array_equal(bounded["off_table"], beyond)
    np.testing.assert_array_equal(bounded.values()[:, model.outcome_names_.index("off_table")], beyond)
    there = Place((x_edge + 0.01, 0.0), 0.03)  # 1 cm beyond the edge: within 3 cm of it only on the table's rim
    assert outcomes.probability(there, start)[1] > 0.5 and bounded.probability(there, start)[1] < 0.05
    bounded["off_table"][:] = False  # a copy: what a caller does with it leaves the outcomes as they are
    np.testing.assert_array_equal(bounded["off_table"], beyond)
    with pytest.raises(ValueError, match="start_xy"):  # one start per query, or one for all
        outcomes.off_beyond(np.zeros((3, 2)), (-0.76, y_low), (x_edge, y_high))
    with pytest.raises(ValueError, match="table"):
        Planner({"grasp": model}, table=((0.0, 0.0), (-1.0, 1.0)))
    # toward's start is checked against the planner's table (a place's target against the scene's, Place): a start
    # 6 cm beyond the scene table's edge is refused by default, taken on a larger table
    with pytest.raises(ValueError, match="on the table top"):
        Planner({"grasp": model}).toward(small, (-0.1, 0.0), (-0.2, 0.0), 0.03, steps_left=1, reachable=None)
    assert Planner({"grasp": model}, table=((-1.0, -1.0), (1.0, 1.0))).toward(
        small, (-0.1, 0.0), (-0.2, 0.0), 0.03, steps_left=1, reachable=None).behavior == "grasp"


def test_place_goals_lie_on_the_table_where_the_goal_env_puts_its_goals():
    from affordance_env.goal_env import GOAL_TABLE_MARGIN
    from affordance_env.workspace import in_any_workspace
    from affordance_learning.planning.experiment import PLACE_DISTANCE, draw_goal

    rng = np.random.default_rng(0)
    low, high = np.array(SCENE_TABLE[0]) + GOAL_TABLE_MARGIN, np.array(SCENE_TABLE[1]) - GOAL_TABLE_MARGIN
    # objects at the placement region's near corners and centre: a uniform place 5-15 cm away falls off the table
    # (x above -0.16) from the near ones a fifth of the time
    for start in ([-0.21, -0.2], [-0.21, 0.2], [-0.33, 0.0]):
        targets = np.array([draw_goal("place", np.array(start), rng).target_xy for _ in range(200)])
        distance = np.linalg.norm(targets - start, axis=1)
        assert np.all(targets >= low) and np.all(targets <= high) and np.all(in_any_workspace(targets))
        assert PLACE_DISTANCE[0] <= distance.min() and distance.max() <= PLACE_DISTANCE[1]
        assert np.ptp(np.arctan2(*(targets - start).T[::-1])) > np.pi  # still spread over directions


def test_step_reach_and_within_reach_bound_what_a_few_interactions_can_do():
    from affordance_learning.planning.experiment import step_reach, within_reach

    n = 100
    moves = np.linspace(0.0, 0.05, n)  # boxes pushed away (-x) by up to 5 cm, never towards the robot
    frame = pd.DataFrame({"true_initial_x": np.zeros(n), "true_initial_y": np.zeros(n), "true_final_x": -moves,
                          "true_final_y": np.zeros(n), "outcome": ["rest"] * n, "type": ["box"] * n})
    reach = step_reach(frame)["box"]
    assert reach["+x"] == 0.0 and reach["-x"] == pytest.approx(0.045, abs=1e-3) and reach["+y"] == 0.0
    assert within_reach((0.0, 0.0), (-0.20, 0.0), reach, 0.03, 5)  # 17 cm to go away: 5 x 4.5 cm suffice
    assert not within_reach((0.0, 0.0), (-0.30, 0.0), reach, 0.03, 5)
    assert not within_reach((0.0, 0.0), (0.10, 0.0), reach, 0.03, 5)  # towards the robot: nothing brings it
    assert within_reach((0.0, 0.0), (0.02, 0.02), reach, 0.03, 5)  # already within the tolerance


def test_candidates_and_errors():
    params = candidate_params(16, 3)
    assert params.shape == (16, 3) and np.all(params[0] == 0) and np.all(np.abs(params) <= 1)
    np.testing.assert_array_equal(params, candidate_params(16, 3))
    with pytest.raises(ValueError, match="threshold"):
        Planner({"push": None}, threshold=2.0)
    with pytest.raises(ValueError, match="at least one behaviour"):
        Planner({})
    assert set(MOTION_COLUMNS) == {"dx", "dy", "rolled", "off_table", "lifted"}


def test_the_oracle_tries_a_fixed_set_of_at_least_64_actions_per_behaviour():
    from affordance_learning.planning.experiment import oracle_params

    params = oracle_params()
    assert params.shape[0] >= 64 + 1 and params.shape[1] == 3 and np.all(np.abs(params) <= 1)
    assert np.all(params[0] == 0)  # the canonical action first: the fixed baselines read it
    assert len(np.unique(params, axis=0)) == len(params)  # distinct actions
    np.testing.assert_array_equal(params, oracle_params())  # the same for every object and run
    for j in range(3):  # each parameter's range covered evenly
        np.testing.assert_array_equal(np.unique(params[1:, j]), [-0.75, -0.25, 0.25, 0.75])


def test_calibration_is_measured_on_the_chosen_actions_with_pooled_beside_it():
    from affordance_learning.planning.experiment import calibrations

    # The planner picks actions it believes at 0.9 and half of them reach the goal; every other action tried is at
    # P near 0 and never reaches it: pooled, the 0.4-point miscalibration is drowned in the many right zeros.
    records = [{"planner_behavior": "tap", "planner_p": 0.9, "planner": i % 2 == 0,
                "pooled": (np.r_[0.9, np.full(99, 0.01)], np.r_[i % 2 == 0, np.zeros(99, bool)])} for i in range(40)]
    records.append({"planner_behavior": None, "planner_p": 0.0, "planner": False,
                    "pooled": (np.full(100, 0.01), np.zeros(100, bool))})  # abstained: not a chosen action
    cal = calibrations(records)
    assert cal.n == 40 and cal.ece == pytest.approx(0.4) and cal.basis == "the planner's chosen actions"
    assert cal.pooled.n == 4100 and cal.pooled.ece < 0.02


def test_success_is_reported_on_feasible_goals_and_on_those_the_oracle_or_the_planner_reached():
    from affordance_learning.planning.experiment import seconds_summary, summarize

    records = ([{"oracle": True, "planner": True}] * 6 + [{"oracle": True, "planner": False}] * 2
               + [{"oracle": False, "planner": True}] * 2 + [{"oracle": False, "planner": False}] * 10)
    planner = summarize(records, ("planner",))["planner"]
    assert (planner.n, planner.n_feasible, planner.n_reached) == (20, 8, 10)
    assert planner.success_feasible == 0.75 and planner.success_reached == 0.8
    times = seconds_summary([0.01] * 98 + [0.5, 2.0])
    assert times.median == 0.01 and times.n == 100 and 0.5 < times.p99 < 2.0 and times.max == 2.0
    assert seconds_summary([]).median is None


def test_calibration_and_wilson_intervals():
    from affordance_learning.planning.experiment import calibration, wilson

    rng = np.random.default_rng(0)
    p = rng.uniform(0, 1, 4000)
    y = rng.uniform(0, 1, 4000) < p  # calibrated by construction
    good = calibration(p, y)
    assert good["ece"] < 0.03 and 0.7 < good["auroc"] < 0.9
    bad = calibration(np.clip(p + 0.3, 0, 1), y)  # over-confident
    assert bad["ece"] > 0.15
    low, high = wilson(45, 50)
    assert low < 0.9 < high and 0.75 < low and high < 0.97
    assert wilson(8, 10) == pytest.approx((0.4902, 0.9433), abs=1e-4)  # Wilson's 95 % interval, z = 1.96
    assert wilson(0, 0) == (0.0, 1.0)


def test_goals_are_judged_on_what_the_simulator_measured():
    from affordance_learning.planning.experiment import draw_goal, reached

    info = {"failure": None, "rolled": True, "outcome": "rest", "behavior": "tap", "success": True,
            "effect": np.zeros(49), "object": {"initial_pose": np.array([-0.3, 0.0, 0.0, 1, 0, 0, 0]),
                                               "final_pose": np.array([-0.3, -0.08, 0.0, 1, 0, 0, 0])}}
    assert reached(Roll(), info) and not reached(Lift(), info)
    assert reached(Move((0, -1), 0.05), info) and not reached(Move((0, 1), 0.05), info)
    assert reached(Place((-0.3, -0.09), 0.03), info)
    assert not reached(Roll(), {**info, "failure": "reach: ..."})  # a failed interaction reaches nothing
    rng = np.random.default_rng(0)
    place = draw_goal("place", np.array([-0.3, 0.0]), rng)
    assert 0.05 <= np.hypot(place.target_xy[0] + 0.3, place.target_xy[1]) <= 0.15
    assert draw_goal("move", np.zeros(2), rng).min_distance == 0.05


def _sleep_then_pid(seconds: float, scale: float = 1.0) -> tuple[float, int]:
    import os
    import time

    time.sleep(seconds * scale)
    return seconds, os.getpid()


@pytest.mark.slow
def test_the_evaluation_hands_each_item_to_the_first_free_process_and_keeps_the_order():
    from affordance_env.workers import map_in_processes

    items = [1.5] + [0.01] * 9  # the first item is slow: the other process does the rest meanwhile
    results = map_in_processes(_sleep_then_pid, items, 2, scale=1.0)
    assert [r[0] for r in results] == items  # in the items' order
    slow = results[0][1]
    assert [pid for _, pid in results[1:]].count(slow) <= 1  # not every other item, as fixed halves would give
    assert map_in_processes(_sleep_then_pid, items[1:3], 1, scale=0.0)[0][0] == 0.01


def test_the_evaluation_takes_new_processes_not_those_joblib_kept_from_the_collection():
    """joblib restarts, with a warning, a kept process that holds 300 MB more than after its first call: the
    planners, read by a process that served the collection first."""
    import os

    from joblib import Parallel, delayed

    from affordance_env.workers import map_in_processes

    kept = set(Parallel(n_jobs=2, batch_size=1)(delayed(os.getpid)() for _ in range(4)))
    fresh = {pid for _, pid in map_in_processes(_sleep_then_pid, [0.2, 0.2, 0.2], 2, scale=1.0)}
    assert fresh and not fresh & kept


def test_the_goal_episodes_are_counted_without_the_top_ups():
    from affordance_learning.planning.experiment import TOP_UP_EPISODES
    from affordance_learning.planning.experiment.run import _goal_episodes

    # 3 goal episodes of 2 steps, then two behaviours' top-ups, each numbered from TOP_UP_EPISODES
    frame = pd.DataFrame({"episode": [0, 0, 1, 1, 2, 2] + [TOP_UP_EPISODES + i for i in (0, 1, 2, 0, 1)]})
    assert _goal_episodes(frame) == 3


@pytest.mark.slow
def test_affordance_plan_end_to_end_writes_results_report_and_figures(tmp_path):
    from dataclasses import replace

    from affordance_learning.planning.experiment import QUICK, oracle_params, run_plan
    from affordance_learning.planning.report import write_plan_figures, write_plan_report
    from affordance_learning.planning.results import PlanResults
    from affordance_learning.planning.targets import TARGETS

    # the quick run's data (60 goal episodes, each behaviour topped up to 60 interactions, 25 trees), fewer objects
    settings = replace(QUICK, objects=2, multi_episodes=2, candidates=8, som_clusters=2)
    plan = run_plan(tmp_path, seed=1, workers=1, settings=settings, camera=(40, 30), say=lambda text: None)
    results = json.loads((tmp_path / "results.json").read_text())
    assert PlanResults.from_dict(results) == plan  # the file reads back as the results it was written from
    for policy in ("planner", "random", "best_fixed", "som_categories", "oracle"):
        entry = results["single_step"][policy]
        assert 0 <= entry["success"] <= 1 and entry["n"] >= 1
        assert entry["n_reached"] >= entry["n_feasible"]
    assert results["single_step"]["planner"]["n"] == settings.goals == 40  # 20 goals on each of the 2 objects
    assert results["single_step"]["oracle"]["success"] == results["single_step"]["oracle"]["success_feasible"] or \
        results["single_step"]["oracle"]["n_feasible"] < 40
    assert results["calibration"]["basis"] == "the planner's chosen actions"
    assert results["calibration"]["n"] <= 40 < results["calibration"]["pooled"]["n"]
    times = results["decision_seconds"]
    assert times["n"] >= 40 and 0 < times["median"] <= times["p99"]
    assert "success_toward_robot" in results["multi_step"]["planner"]
    # an episode toward the robot says what could pull the object from where it started; no other does
    assert all((e["pulls_at_start"] is not None) == e["toward_robot"]
               for e in results["multi_step"]["planner"]["episodes"])
    assert set(results["leave_one_shape_out"]) == {"sphere", "box", "horizontal_cylinder", "vertical_cylinder"}
    for policy in ("planner", "direction", "random"):
        assert 0 <= results["multi_step"][policy]["reach_failures"] <= 1
        within = results["multi_step"][policy]["success_within"]  # 1, 3 and 5 cm: nested, as the distances are
        assert [w["distance_m"] for w in within] == [0.01, 0.03, 0.05] and all(w["n"] == 2 for w in within)
        assert within[0]["success"] <= within[1]["success"] <= within[2]["success"]
        assert within[1]["success"] == results["multi_step"][policy]["success"]  # the goal env's own 3 cm
    places = sum(g["kind"] == "place" for g in results["goals"])
    for policy in ("planner", "oracle"):
        within = results["place_success_within"][policy]
        assert [w["n"] for w in within] == [places] * 3 and within[0]["success"] <= within[2]["success"]
    assert plan.place_within("planner", 0.03).value == sum(  # the place goals' own tolerance: the same verdicts
        g["planner"] for g in results["goals"] if g["kind"] == "place") / places
    assert {"collect_goal_episodes", "collect_top_up_tap", "evaluate_single_step_cpu"} <= set(results["timings_s"])
    assert {"ece", "auroc"} <= set(results["calibration"])
    actions = len(BEHAVIOR_NAMES) * len(oracle_params())  # every goal: how many of the oracle's actions reached it
    for goal in results["goals"]:
        assert goal["oracle"] == (0 < goal["oracle_hits"] <= actions)
        assert 0.03 <= goal["size"] <= 0.1 and isinstance(goal["planner_left_out"], bool)
    assert json.loads((tmp_path / "results.json").read_text())["seed"] == 1
    write_plan_figures(results, tmp_path)
    report = write_plan_report(results, tmp_path).read_text()
    assert all(name in report for name in TARGETS)
    assert (tmp_path / "success.png").stat().st_size > 1000 and (tmp_path / "reliability.png").exists()


@pytest.mark.slow
def test_a_multi_step_action_that_left_the_object_where_it_was_is_noted_as_failed():
    """A 10 cm box, which the hand cannot hold, grasped again and again: every grasp leaves it where it was, and
    the episode notes each as failed, so that a planner does not choose it again from there."""
    from affordance_learning.planning import experiment as plan_experiment
    from affordance_learning.planning.planner import Choice

    class Grasping:  # a planner that grasps whatever the situation, recording what it is told
        def __init__(self) -> None:
            self.noted: list[tuple[str, np.ndarray, np.ndarray]] = []

        def forget_failures(self) -> None:
            self.noted.clear()

        def toward(self, features, start_xy, target_xy, tolerance, **kwargs) -> Choice:
            return Choice("grasp", np.zeros(3), 0.5, False)

        def note_failure(self, behavior, params, start_xy=None, features=None) -> None:
            self.noted.append((behavior, np.asarray(params), np.asarray(start_xy)))

    env = plan_experiment.evaluation_env((40, 30))
    reset = env.reset
    env.reset = lambda seed=None, options=None: reset(seed=seed, options={
        **(options or {}), "object_type": "box", "size": 0.1, "position": (-0.3, 0.1)})
    planner = Grasping()
    try:
        episode = plan_experiment.evaluate_episode({"seed": 5, "rng": 5, "index": 1}, planner, "planner", (40, 30))
    finally:
        env.reset = reset
    assert not episode["success"] and episode["steps"] >= 2
    assert len(planner.noted) == episode["steps"]  # every grasp left the box where it was
    assert all(behavior == "grasp" for behavior, _, _ in planner.noted)


def test_an_episode_toward_the_robot_takes_an_object_the_table_leaves_room_for_such_a_target():
    """An object 22 cm from the robot leaves no room for a target 10 cm or more toward it 5 cm inside the table's
    near edge: the episode draws another object, and its target lies toward the robot."""
    from affordance_env.goal_env import GOAL_DISTANCE, GOAL_TABLE_MARGIN
    from affordance_learning.planning import experiment as plan_experiment

    env = plan_experiment.evaluation_env((40, 30))
    reset = env.reset
    near_edge = 7

    room = 8

    def reset_near_edge(seed=None, options=None):  # the item's own object lies near the table's near edge
        extra = {"position": (-0.22, 0.0)} if seed == near_edge else {"position": (-0.42, 0.0)} if seed == room else {}
        return reset(seed=seed, options={**(options or {}), **extra})

    env.reset = reset_near_edge
    try:
        starts = {index: plan_experiment.episode_start(env, {"seed": near_edge, "rng": 3, "index": index},
                                                       np.random.default_rng(3))
                  for index in (0, 1)}
        roomy, _ = plan_experiment.episode_start(env, {"seed": room, "rng": 3, "index": 4}, np.random.default_rng(3))
    finally:
        env.reset = reset
    # an object with room in front of it keeps its place and gets a target toward the robot
    np.testing.assert_allclose(roomy["achieved_goal"][0], -0.42, atol=0.01)
    assert plan_experiment.toward_robot(roomy["achieved_goal"], roomy["desired_goal"])
    (obs, _), (obs_kept, _) = starts[0], starts[1]
    start, target = np.asarray(obs["achieved_goal"]), np.asarray(obs["desired_goal"])
    assert start[0] < -0.22 - 0.05  # another object, further out
    assert plan_experiment.toward_robot(start, target)
    assert GOAL_DISTANCE[0] - 1e-9 <= np.linalg.norm(target - start) <= GOAL_DISTANCE[1] + 1e-9
    assert target[0] <= SCENE_TABLE[1][0] - GOAL_TABLE_MARGIN + 1e-9
    # an episode that is not one toward the robot keeps the goal env's object and target
    np.testing.assert_allclose(obs_kept["achieved_goal"][0], -0.22, atol=0.01)


def test_a_weighted_share_is_at_most_one():
    # weights that sum to 1 may add up to an ulp more in floating point; a probability may not
    w = np.array([0.18620170802956595, 0.1387585731752892, 0.23867430191277866, 0.2082440595395123,
                  0.0006989935750115445, 0.21884975106272195, 0.008572612705120415])
    assert np.add.reduceat(np.append(w, 0.0), [0])[0] > 1.0  # the sum, as the share adds it
    weights = sparse.csr_matrix(w[None, :])
    share = ActionEffectModel.weighted_share(weights, np.ones(w.size))
    assert share.tolist() == [1.0]
