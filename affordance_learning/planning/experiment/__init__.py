"""``affordance plan``: learn what the behaviours do, then use it to reach goals, against baselines in one run.

1. Collect goal episodes of the goal env (:data:`affordance_env.registry.GOAL_ENV_ID`) with random actions,
   objects spread over the workspaces (:func:`affordance_env.dataset.collect`, resumable), extending the dataset
   in rounds until every behaviour has ``max_per_behavior`` interactions (or ``max_episodes`` were collected), and
   keep the first ``max_per_behavior`` of each behaviour for training.
2. Fit an :class:`~.effect_model.ActionEffectModel` per behaviour, the same without each shape
   (step 4), and the paper's model (:class:`~affordance_learning.paper.model.AffordanceModel`, its effect categories)
   per behaviour for the ``som_categories`` baseline.
3. Single step, on held-out objects (reset seeds disjoint from the training episodes, ``objects`` of them, the
   shapes in turn). On each object every behaviour's :func:`oracle_params` (the canonical action and a 4 x 4 x 4
   grid, 65 per behaviour, the same for every object) is run from the same snapshot (``get_state`` /
   ``set_state``), once; then :data:`GOALS_PER_OBJECT` goals (:mod:`affordance_learning.planning.goals`: roll,
   lift, move 5 cm in each of 8 directions, and places within 3 cm of points 5-15 cm away, on the table as the goal
   env's targets are: :func:`place_target`) are each judged against those outcomes. Policies, all from that snapshot
   (an action run once is not run again: the env repeats an interaction bit for bit from a snapshot):

   - ``planner``: :meth:`~affordance_learning.planning.planner.Planner.choose`, with ``feasible`` ruling out reach
     failures, remembering the actions that failed on this object (:meth:`~affordance_learning.planning.planner.Planner.
     note_failure`); the time of each decision is measured, ``feasible``'s calls included;
   - ``random``: a uniform behaviour and a uniform action of the oracle's set;
   - ``best_fixed``: per goal kind, the behaviour whose canonical action reached that kind most often (chosen
     after the fact over all objects: an upper bound for a fixed choice);
   - ``canonical_choice``: the planner's choice of behaviour with the canonical action only;
   - ``som_categories``: the paper's categories as a planner: the behaviour whose predicted effect category
     reached the goal most often in training, at the canonical action;
   - ``oracle``: whether any action of the oracle's set reached the goal. A goal it reaches is *feasible*.

   Success is reported on every goal, on the feasible goals, and on the goals the oracle or the planner reached;
   for the place goals also within 1, 3 and 5 cm of the target (the planner's action, and any of the oracle's).
4. Leaving each shape out: on the goals of step 3 whose object is of that shape, the planner of the models fitted
   without it, from the same snapshot (the oracle's verdict says which goals are feasible).
5. Multi-step: episodes of the goal env (its targets, its tolerance, at most ``GOAL_MAX_EPISODE_STEPS``
   interactions), re-planning after each interaction with :meth:`~affordance_learning.planning.planner.Planner.toward`'s
   defaults (a search over two interactions, the behaviours' workspaces saying where a second one can act),
   against random actions and a direction heuristic. Where no candidate is feasible the planner stops
   (``gave_up``) rather than run an interaction it knows would fail; an action that failed to reach is not chosen
   again from where it failed. Targets toward the robot (within 45 degrees of +x from the object) are counted
   apart; every ``TOWARD_ROBOT_EVERY``-th episode has one, on an object that leaves room for it
   (:func:`~.goal_drawing.episode_start`). Each policy's share of episodes that ended within 1, 3 and 5 cm of the
   target is reported beside it (5 cm: FetchPush's and Meta-World's threshold).
6. Calibration of P(goal) on the planner's chosen actions of step 3 (expected calibration error over 10 bins,
   AUROC), and, beside it, pooled over every action of the oracle's set for every goal.

:data:`QUICK` (``affordance plan --quick``) runs all of it on few data, its verdicts then on too few.

The goals of one object are judged against the same outcomes, so they are not independent: the Wilson intervals
treat them as if they were, and the report gives the number of objects beside them. Every number is measured in
this run; fractions are in [0, 1], distances in metres, times in seconds.

The package, one module per job: :mod:`.settings` (sizes, goals per object, the oracle's actions, the items'
seeds), :mod:`.goal_drawing` (the goals set), :mod:`.training` (data and effect models), :mod:`.baselines`,
:mod:`.simulation` (what the simulator says, each object's interactions run once), :mod:`.single_step`,
:mod:`.multi_step`, :mod:`.statistics` and :mod:`.run` (the stages of :func:`run_plan`).
"""

from affordance_learning.common.statistics import calibration, share_text
from affordance_learning.planning.experiment.baselines import SomBaseline, best_fixed, direction_heuristic
from affordance_learning.planning.experiment.goal_drawing import (
    TOWARD_ROBOT_EVERY,
    TOWARD_ROBOT_OBJECTS,
    draw_goal,
    draw_goals,
    episode_start,
    goal_toward_robot,
    place_target,
    toward_robot,
)
from affordance_learning.planning.experiment.multi_step import (
    DIRECTIONS,
    PULLING,
    evaluate_episode,
    step_reach,
    within_reach,
)
from affordance_learning.planning.experiment.run import DATASET_DIR, RESULTS_FORMAT, record_episode, run_plan
from affordance_learning.planning.experiment.settings import (
    EVAL_STREAM,
    GOAL_KINDS,
    GOALS_PER_OBJECT,
    MOVE_DISTANCE,
    MULTI_POLICIES,
    ORACLE_LEVELS,
    PLACE_DISTANCE,
    PLACE_TOLERANCE,
    POLICIES,
    QUICK,
    PlanSettings,
    evaluation_items,
    oracle_params,
)
from affordance_learning.planning.experiment.simulation import (
    Outcomes,
    evaluation_env,
    feasible_at,
    measured_outcome,
    reach_failure,
    reached,
)
from affordance_learning.planning.experiment.single_step import evaluate_object
from affordance_learning.planning.experiment.statistics import (
    calibrations,
    seconds_summary,
    summarize,
    wilson,
    within_shares,
)
from affordance_learning.planning.experiment.training import (
    TOP_UP_EPISODES,
    TOP_UP_MARGIN,
    collect_training,
    fit_models,
    load_training,
    top_up_path,
    training_frames,
)

__all__ = ["DATASET_DIR", "DIRECTIONS", "EVAL_STREAM", "GOALS_PER_OBJECT", "GOAL_KINDS", "MOVE_DISTANCE",
           "MULTI_POLICIES", "ORACLE_LEVELS", "Outcomes", "PLACE_DISTANCE", "PLACE_TOLERANCE", "POLICIES", "PULLING",
           "PlanSettings", "QUICK",
           "RESULTS_FORMAT", "SomBaseline", "TOP_UP_EPISODES", "TOP_UP_MARGIN", "TOWARD_ROBOT_EVERY",
           "TOWARD_ROBOT_OBJECTS", "best_fixed", "calibration", "calibrations", "collect_training",
           "direction_heuristic", "draw_goal", "draw_goals", "episode_start", "evaluate_episode", "evaluate_object",
           "evaluation_env", "evaluation_items", "feasible_at", "fit_models", "goal_toward_robot", "load_training",
           "measured_outcome", "oracle_params", "place_target", "reach_failure", "reached", "record_episode",
           "run_plan", "seconds_summary", "share_text", "step_reach", "summarize", "top_up_path", "toward_robot",
           "training_frames", "wilson", "within_reach", "within_shares"]
