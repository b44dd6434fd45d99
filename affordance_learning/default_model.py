"""``predict_effect(features, behavior)``: the effect of a behaviour predicted by the package's default model.

One default model per behaviour, as the paper proposes ("a separate SOM and SVM for each behavior"). Each is
an :class:`AffordanceModel` (1 x 4 map, r = 0.4: the paper's case-study setting and its best relevancy)
trained by :func:`train_default_model` on a dataset of that behaviour's canonical interactions (the command
``affordance train-default --behavior NAME`` builds it) and stored with the behaviour, the bundle format, this
package's version, scikit-learn's version and NumPy's major version. Bundles stored before the behaviour was
recorded are the tap's.

Where they are: the package ships the tap's and the grasp's in ``affordance_learning/data/`` (read only: an
installed package is not written to). A model built by ``affordance train-default`` goes to the user's data
directory (:func:`user_model_dir`: ``$TAP_AFFORDANCE_DATA``, else ``$XDG_DATA_HOME/tap-affordance``, else
``~/.local/share/tap-affordance``), and :func:`predict_effect` uses it there, before the package's
(:func:`model_path`).

:func:`load_default_model` refuses a file that is missing (:class:`DefaultModelMissingError`, a
``FileNotFoundError``), unreadable, not a bundle of the current :data:`FORMAT`, a model of another behaviour,
or stored under other versions (:class:`DefaultModelError`, a ``RuntimeError``), with a message that says how
to rebuild it; it never uses a model it could not check. :data:`FORMAT` is raised whenever the fitted layout of
:class:`AffordanceModel` changes, so that an older file is refused rather than half-used. A good load is
cached, keyed by the file's path, size and modification time, so a rebuilt file is used at the next call.

Action-conditioned: ``predict_effect(features, behavior, action=params)`` predicts what one action of the
behaviour does (:class:`ActionEffectPrediction`), from the behaviour's
:class:`~affordance_learning.planning.effect_model.ActionEffectModel` fitted on goal episodes with random actions
(:func:`train_action_models`; ``affordance train-default --action-conditioned`` collects the episodes and builds
every behaviour's at once). They are stored and found as the others (``BEHAVIOR_action_model.joblib``, the user's
before the package's: :func:`action_model_path`) and checked the same way on loading (:data:`ACTION_FORMAT`).
"""

from __future__ import annotations

import functools
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import joblib
import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from affordance_env.values import float_array
from affordance_learning.common.behaviors import check_behavior
from affordance_learning.common.exceptions import DefaultModelError, DefaultModelMissingError, InvalidValueError
from affordance_learning.common.schema import frame_behavior
from affordance_learning.common.validation import check_float32_range, first_non_finite
from affordance_learning.paper.model import AffordanceModel, EffectPrediction
from affordance_learning.planning.effect_model import ActionEffectModel, behavior_model
from affordance_learning.planning.outcomes import model_inputs, outcome_table
from affordance_learning.user_models import DATA_ENV, user_model_dir, user_model_path  # noqa: F401 (re-exported)

#: Where the package's own default models are, one file per behaviour (read only).
MODEL_DIR = Path(__file__).resolve().parent / "data"
#: The package's default tap model.
DEFAULT_MODEL_PATH = MODEL_DIR / "tap_model.joblib"
#: Map size and relevancy threshold of the default model.
DEFAULT_N_CLUSTERS = 4
DEFAULT_RELEVANCY = 0.4
#: Maps the default model trains (from seeds 0 to 9), of which it keeps the one of lowest quantization error
#: (:class:`~affordance_learning.paper.som.SOMClustering`'s ``n_init``). One map is a stochastic descent: on the 1000
#: canonical taps, the 1 x 4 maps of seeds 0-11 have quantization errors 3.73-4.74 (standardised effects), and the
#: lower the error, the cleaner their node of slides. The four lowest (3.73-3.97) hold 520-577 taps that moved
#: 1.8-2.5 cm along the tap; the three highest (4.29-4.74, seed 0's the highest) merge them with the shortest rolls,
#: in a node of 685-875 taps at 3.7-5.5 cm, which predicts a tapped box to move several centimetres instead of 1-2.
DEFAULT_SOM_N_INIT = 10
#: Layout of the stored bundle and of AffordanceModel's fitted attributes; raise it when either changes.
FORMAT = 3
#: The command that rebuilds the default tap model (see :func:`rebuild_command` for the others).
REBUILD_COMMAND = "affordance train-default"
_N_FEATURES = 49


def model_path(behavior: str = "tap") -> Path:
    """The default model of ``behavior`` that :func:`predict_effect` uses: the user's (rebuilt by ``affordance
    train-default``) if there is one, else the package's; where the user's would be if neither exists. Raises
    ValueError for an unknown behaviour, naming the valid ones."""
    user, packaged = user_model_path(behavior), MODEL_DIR / f"{check_behavior(behavior)}_model.joblib"
    return user if user.exists() or not packaged.exists() else packaged


def rebuild_command(behavior: str = "tap") -> str:
    """The command that rebuilds the default model of ``behavior``."""
    return REBUILD_COMMAND if behavior == "tap" else f"{REBUILD_COMMAND} --behavior {behavior}"


def _feature_names() -> list[str]:
    try:
        from affordance_env.features import FEATURE_NAMES
    except ImportError:
        return [f"f{i:02d}" for i in range(_N_FEATURES)]
    return list(FEATURE_NAMES)


def library_versions() -> dict[str, str]:
    """Versions that must match between storing and loading the default model.

    scikit-learn exactly (it guarantees its pickles only under the version that wrote them), NumPy's major
    version (pickled arrays are stable within one), and this package exactly (it defines the model).
    """
    import sklearn

    from affordance_learning import __version__

    return {
        "scikit-learn": sklearn.__version__,
        "numpy": np.__version__.split(".")[0],
        "tap-affordance": __version__,
    }


def train_default_model(
    df: pd.DataFrame,
    path: str | Path | None = None,
    *,
    behavior: str = "tap",
    n_clusters: int = DEFAULT_N_CLUSTERS,
    relevancy: float = DEFAULT_RELEVANCY,
    random_state: int = 0,
    som_n_init: int = DEFAULT_SOM_N_INIT,
) -> AffordanceModel:
    """Fit the default model of a behaviour on a dataset frame and store it with the library versions.

    Args:
        df: Interactions of ``behavior`` in the dataset schema: ``initial_<name>`` and ``effect_<name>`` for
            each of the 49 feature names (``affordance_env.features.FEATURE_NAMES``); its ``behavior`` column,
            if it has one, must name ``behavior`` only.
        path: Where to write the model (the directory is created; default: the user's file of the behaviour,
            :func:`user_model_path`, which :func:`predict_effect` then uses); written to a temporary file first
            and moved into place, so a reader never sees half a file.
        behavior: The behaviour of the interactions, one of :data:`affordance_env.registry.BEHAVIOR_NAMES`.
        n_clusters: Effect categories (map size), in [2, 10].
        relevancy: Relevancy threshold of the feature selection, in [0, 1].
        random_state: Seed of the first map (the others follow it:
            :class:`~affordance_learning.paper.som.SOMClustering`).
        som_n_init: Maps trained, of which the one of lowest quantization error is kept.

    Returns:
        The fitted model.

    Raises:
        ValueError: An unknown behaviour, a frame of another behaviour or of several, or missing columns.
    """
    path = user_model_path(behavior) if path is None else path
    frame_behavior(df, check_behavior(behavior))
    names = _feature_names()
    missing = [c for n in names for c in (f"initial_{n}", f"effect_{n}") if c not in df.columns]
    if missing:
        raise InvalidValueError(
            f"the dataset lacks {len(missing)} column(s) that the default model needs, e.g. {missing[:4]}; "
            "expected initial_<name> and effect_<name> for every name in affordance_env's FEATURE_NAMES."
        )
    X = pd.DataFrame(df[[f"initial_{n}" for n in names]].to_numpy(dtype=np.float64), columns=names)
    E = pd.DataFrame(df[[f"effect_{n}" for n in names]].to_numpy(dtype=np.float64), columns=names)
    model = AffordanceModel(n_clusters=n_clusters, relevancy=relevancy, som_n_init=som_n_init,
                            random_state=random_state).fit(X, E)
    bundle = {
        "format": FORMAT,
        "behavior": behavior,
        "model": model,
        "versions": library_versions(),
        "feature_names": names,
        "n_interactions": int(len(df)),
    }
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    partial = path.with_name(f"{path.name}.{os.getpid()}.partial")
    joblib.dump(bundle, partial, compress=3)
    partial.replace(path)
    _load.cache_clear()
    return model


def _problem(path: Path | str, problem: str, behavior: str) -> str:
    what = "taps" if behavior == "tap" else f"{behavior} interactions"
    return (
        f"The default {behavior} model {path} {problem}. Rebuild it with `{rebuild_command(behavior)}` (it "
        f"collects or reuses 1000 canonical {what}, trains the model and stores it in the user's data directory, "
        f"{user_model_path(behavior)}, where predict_effect finds it)."
    )


@functools.lru_cache(maxsize=4)
def _load(path: str, size: int, mtime_ns: int, behavior: str) -> tuple[AffordanceModel, tuple[str, ...]]:
    """Load and check a stored model of ``behavior``; ``size`` and ``mtime_ns`` only key the cache."""
    try:
        bundle: Any = joblib.load(path)
    except Exception as exc:  # unpickling a damaged file can raise almost anything
        raise DefaultModelError(
            _problem(path, f"could not be read ({type(exc).__name__}: {exc})", behavior)) from exc
    if not isinstance(bundle, dict) or bundle.get("format") != FORMAT:
        found = bundle.get("format") if isinstance(bundle, dict) else type(bundle).__name__
        raise DefaultModelError(
            _problem(path, f"is not a default model bundle of format {FORMAT} (found {found!r})", behavior)
        )
    stored_behavior = bundle.get("behavior", "tap")  # bundles stored before the behaviour was recorded: taps
    if stored_behavior != behavior:
        raise DefaultModelError(_problem(path, f"holds a {stored_behavior!r} model, not a {behavior!r} one",
                                         behavior))
    model = bundle.get("model")
    names = bundle.get("feature_names")
    if not isinstance(model, AffordanceModel) or not isinstance(names, list) or len(names) != _N_FEATURES:
        raise DefaultModelError(_problem(path, "does not hold an AffordanceModel over the 49 features", behavior))
    stored, installed = bundle.get("versions", {}), library_versions()
    changed = [
        f"{k} {stored.get(k)} (model) vs {v} (installed)" for k, v in installed.items() if stored.get(k) != v
    ]
    if changed:
        raise DefaultModelError(
            _problem(path, "was stored under other library versions: " + "; ".join(changed), behavior)
        )
    return model, tuple(names)


def _load_checked(path: Path, behavior: str) -> tuple[AffordanceModel, tuple[str, ...]]:
    try:
        stat = path.stat()
    except OSError as exc:
        raise DefaultModelMissingError(_problem(path, f"is missing ({exc.strerror})", behavior)) from exc
    return _load(str(path.resolve()), stat.st_size, stat.st_mtime_ns, behavior)


def load_default_model(path: str | Path | None = None, *, behavior: str = "tap") -> AffordanceModel:
    """The default model of a behaviour, checked against the installed library versions (cached).

    Args:
        path: The stored model (default: the user's model of the behaviour, else the package's:
            :func:`model_path`).
        behavior: The behaviour the model must be of, one of :data:`affordance_env.registry.BEHAVIOR_NAMES`.

    Raises:
        ValueError: An unknown behaviour.
        DefaultModelMissingError: The file does not exist (a ``FileNotFoundError``); the message gives the
            command that builds it.
        DefaultModelError: The file is unreadable, not a model bundle of the current format, a model of
            another behaviour, or was stored under other versions (a ``RuntimeError``).
    """
    path = model_path(behavior) if path is None else Path(path)
    return _load_checked(path, check_behavior(behavior))[0]


def predict_effect(
    features: ArrayLike | pd.DataFrame, behavior: str = "tap", *, action: ArrayLike | None = None,
    path: str | Path | None = None
) -> EffectPrediction | ActionEffectPrediction:
    """Predict the effect category of a behaviour's canonical interaction with objects, and what the effect
    looks like, from their 49 features; given an ``action``, what that action of the behaviour does to them.

    Args:
        features: One (49,) or many (n, 49) feature vectors of objects before the interaction, in the order
            of ``affordance_env.features.FEATURE_NAMES`` (``obs["features"]`` of ``TapAffordance-v2``), or a
            DataFrame with those columns (in any order; other columns are ignored); finite.
        behavior: Whose default model predicts: ``"tap"`` (shipped), ``"grasp"``, ``"tap_back"`` or
            ``"push"`` (built by ``affordance train-default --behavior NAME``).
        action: The behaviour's 3 parameters in [-1, 1] (0: the canonical action), (3,) for every object or
            (n, 3) one per object. Then the behaviour's action-conditioned default model predicts
            (:func:`action_model_path`; ``affordance train-default --action-conditioned`` rebuilds them) and the
            result is an :class:`ActionEffectPrediction`: the mean perceptual effect, displacement [m] and
            P(rolled), P(off the table), P(lifted).
        path: The stored model (default: the user's model of the behaviour, else the package's:
            :func:`model_path`, or :func:`action_model_path` with an ``action``).

    Returns:
        Without ``action``, for a batch, (n, 49) or a DataFrame: ``category`` (n,) int and ``effect`` (n, 49)
        float, the category's prototype effect (final minus initial features, in each feature's unit). For one
        (49,) vector: one result, ``category`` an int and ``effect`` (49,).

    Raises:
        ValueError: An unknown behaviour, or ``features`` has another shape or lacks feature columns, or holds
            NaN or inf.
        DefaultModelMissingError: The behaviour's default model was not built (the message gives the command).
        DefaultModelError: The default model is broken, of another behaviour or stale (rebuild it with
            ``affordance train-default --behavior NAME``).
    """
    check_behavior(behavior)
    if action is None:
        path = model_path(behavior) if path is None else Path(path)
    if isinstance(features, pd.DataFrame):
        names = _feature_names()
        missing = [n for n in names if n not in features.columns]
        if missing:
            raise InvalidValueError(
                f"the features DataFrame lacks {len(missing)} feature column(s), e.g. {missing[:4]}; "
                "expected the names of affordance_env's FEATURE_NAMES."
            )
        features = features[names].to_numpy()
    X = float_array("features", features, finite=False, error=InvalidValueError,
                    expected=f"real numbers, ({_N_FEATURES},) or (n, {_N_FEATURES})")
    if X.ndim not in (1, 2) or X.shape[-1] != _N_FEATURES or (X.ndim == 2 and X.shape[0] == 0):
        raise InvalidValueError(
            f"features must have shape ({_N_FEATURES},) or (n, {_N_FEATURES}) with n >= 1, got {X.shape}."
        )
    single = X.ndim == 1
    X = np.atleast_2d(X)  # float64 (float_array)
    found = first_non_finite(X)
    if found:
        count, row, col, value = found
        raise InvalidValueError(
            f"features must be finite; row {row}, feature {col} is {value} ({count} non-finite value(s)).")
    check_float32_range("features", X)
    if action is not None:
        return _predict_action(X, behavior, action, path, single)
    model, names = _load_checked(path, behavior)
    prediction = model.predict_effect(pd.DataFrame(X, columns=list(names)))
    if single:  # one vector in, one result out
        return EffectPrediction(category=int(prediction.category[0]), effect=prediction.effect[0])
    return prediction


# --- the action-conditioned default models ---------------------------------------------------------------------
#: Layout of a stored action-conditioned bundle; raise it when the bundle or ActionEffectModel's fitted attributes
#: change.
ACTION_FORMAT = 1
#: Trees of each shipped action-conditioned model: 100 instead of the planner's 200 keep a file near 1.6 MB (200:
#: 3 MB), and a prediction averages over 100 trees' leaves, each of at least 3 training outcomes.
ACTION_TREES = 100
#: Training interactions per behaviour of an action-conditioned default model.
ACTION_INTERACTIONS = 1000
#: The command that rebuilds the action-conditioned default models, every behaviour's at once.
ACTION_REBUILD_COMMAND = "affordance train-default --action-conditioned"


@dataclass(frozen=True)
class ActionEffectPrediction:
    """What a behaviour's action-conditioned default model predicts for objects and an action: the mean of its
    predictive distribution (:class:`~affordance_learning.planning.effect_model.ActionEffectModel`).

    Attributes:
        effect: The perceptual effect, final minus initial features (n, 49), each in its feature's unit: the
            training neighbours' as they were.
        displacement: How far the object's centre moves on the table (n, 2) [m], root frame (+x toward the robot):
            the neighbours' moved to this action along the local slopes
            (:meth:`~affordance_learning.planning.effect_model.ActionEffectModel.predictive_outcomes`).
        rolled: P(the object rolls further than the roll threshold), (n,).
        off_table: P(it leaves the table), (n,).
        lifted: P(a grasp lifts and holds it), (n,) (0 for the other behaviours).

    For one (49,) feature vector: ``effect`` (49,), ``displacement`` (2,) and the probabilities floats.
    """

    effect: np.ndarray
    displacement: np.ndarray
    rolled: np.ndarray | float
    off_table: np.ndarray | float
    lifted: np.ndarray | float


def action_model_path(behavior: str = "tap") -> Path:
    """The action-conditioned default model of ``behavior`` that :func:`predict_effect` uses with an ``action``:
    the user's (rebuilt by ``affordance train-default --action-conditioned``) if there is one, else the package's;
    where the user's would be if neither exists."""
    name = f"{check_behavior(behavior)}_action_model.joblib"
    user, packaged = user_model_dir() / name, MODEL_DIR / name
    return user if user.exists() or not packaged.exists() else packaged


def train_action_models(frame: pd.DataFrame, out: str | Path | None = None, *,
                        max_per_behavior: int = ACTION_INTERACTIONS, n_estimators: int = ACTION_TREES,
                        random_state: int = 0, behaviors: list[str] | None = None) -> dict[str, Path]:
    """Fit the action-conditioned default model of every behaviour in a goal-episode frame and store each.

    Args:
        frame: Goal episodes with random actions (``affordance_env.load_dataset`` of a collection of the goal
            env, as ``affordance plan`` and ``affordance train-default --action-conditioned`` collect them).
        out: The directory the models go to (``BEHAVIOR_action_model.joblib``; default: the user's data directory,
            :func:`user_model_dir`, where :func:`predict_effect` finds them).
        max_per_behavior: The first interactions of each behaviour the model is fitted on.
        n_estimators: Trees of each model.
        random_state: Seed of the forests.
        behaviors: The behaviours to fit (default: every one the frame holds).

    Returns:
        Each behaviour's file.

    Raises:
        ValueError: A behaviour without interactions in the frame, or a frame without the goal dataset's columns.
    """
    out = user_model_dir() if out is None else Path(out)
    held = [str(b) for b in dict.fromkeys(frame["behavior"].astype(str))] if "behavior" in frame else []
    behaviors = [check_behavior(b) for b in (behaviors or held)]
    written = {}
    for behavior in behaviors:
        rows = frame[frame["behavior"].astype(str) == behavior]
        if "episode" in rows:
            rows = rows.sort_values([c for c in ("episode", "step") if c in rows])
        rows = rows.head(max_per_behavior)
        if rows.empty:
            raise InvalidValueError(f"the frame holds no {behavior!r} interactions to fit its action-conditioned "
                                    f"model on (it holds {', '.join(held) or 'none'}).")
        model = behavior_model(behavior, n_estimators=n_estimators, random_state=random_state).fit(
            model_inputs(rows), outcome_table(rows))
        bundle = {"format": ACTION_FORMAT, "behavior": behavior, "model": model, "versions": library_versions(),
                  "feature_names": _feature_names(), "n_interactions": int(len(rows))}
        path = out / f"{behavior}_action_model.joblib"
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_name(f"{path.name}.{os.getpid()}.partial")
        joblib.dump(bundle, partial, compress=3)
        partial.replace(path)
        written[behavior] = path
    _load_action.cache_clear()
    return written


def _action_problem(path: Path | str, problem: str) -> str:
    return (f"The action-conditioned default model {path} {problem}. Rebuild them with `{ACTION_REBUILD_COMMAND}` "
            f"(it collects or reuses goal episodes with random actions until every behaviour has "
            f"{ACTION_INTERACTIONS} interactions, fits a model per behaviour and stores them in the user's data "
            f"directory, {user_model_dir()}, where predict_effect finds them).")


@functools.lru_cache(maxsize=8)
def _load_action(path: str, size: int, mtime_ns: int, behavior: str):
    """Load and check a stored action-conditioned model of ``behavior``; ``size`` and ``mtime_ns`` key the cache."""
    try:
        bundle: Any = joblib.load(path)
    except Exception as exc:  # unpickling a damaged file can raise almost anything
        raise DefaultModelError(_action_problem(path, f"could not be read ({type(exc).__name__}: {exc})")) from exc
    if not isinstance(bundle, dict) or bundle.get("format") != ACTION_FORMAT:
        found = bundle.get("format") if isinstance(bundle, dict) else type(bundle).__name__
        raise DefaultModelError(_action_problem(path, f"is not an action-conditioned bundle of format "
                                                      f"{ACTION_FORMAT} (found {found!r})"))
    if bundle.get("behavior") != behavior:
        raise DefaultModelError(_action_problem(path, f"holds a {bundle.get('behavior')!r} model, not a "
                                                      f"{behavior!r} one"))
    model = bundle.get("model")
    if not isinstance(model, ActionEffectModel) or model.n_features_in_ != _N_FEATURES + 3:
        raise DefaultModelError(_action_problem(path, "does not hold an ActionEffectModel of the 49 features and "
                                                      "3 parameters"))
    stored, installed = bundle.get("versions", {}), library_versions()
    changed = [f"{k} {stored.get(k)} (model) vs {v} (installed)" for k, v in installed.items() if stored.get(k) != v]
    if changed:
        raise DefaultModelError(_action_problem(path, "was stored under other library versions: "
                                                + "; ".join(changed)))
    if not hasattr(model, "kinds_"):  # fitted before the model moved its neighbours to the query's action
        raise DefaultModelError(_action_problem(path, "was fitted by an earlier ActionEffectModel, without the "
                                                      "local slopes of its displacements"))
    return model


def load_action_model(behavior: str = "tap", path: str | Path | None = None):
    """The action-conditioned default model of ``behavior`` (an
    :class:`~.planning.effect_model.ActionEffectModel`), checked against the installed library versions
    (cached). Raises DefaultModelMissingError (with the command that builds it) or DefaultModelError as
    :func:`load_default_model`."""
    behavior = check_behavior(behavior)
    path = action_model_path(behavior) if path is None else Path(path)
    try:
        stat = path.stat()
    except OSError as exc:
        raise DefaultModelMissingError(_action_problem(path, f"is missing ({exc.strerror})")) from exc
    return _load_action(str(path.resolve()), stat.st_size, stat.st_mtime_ns, behavior)


def _predict_action(X: np.ndarray, behavior: str, action: ArrayLike, path: str | Path | None,
                    single: bool) -> ActionEffectPrediction:
    """:func:`predict_effect` with an ``action``: the action-conditioned model's mean outcome."""
    a = float_array("action", action, finite=False, error=InvalidValueError,
                    expected="the behaviour's 3 parameters in [-1, 1], (3,) or (n, 3)")
    if a.ndim not in (1, 2) or a.shape[-1] != 3 or not np.all(np.isfinite(a)) or np.any(np.abs(a) > 1):
        raise InvalidValueError(f"action must be the behaviour's 3 parameters in [-1, 1], (3,) or (n, 3), got "
                                f"{action!r}.")
    a = np.broadcast_to(np.atleast_2d(a), (len(X), 3)) if a.ndim == 1 or len(a) == 1 else a
    if len(a) != len(X):
        raise InvalidValueError(f"action must be one (3,) for every object or one per object, got {len(a)} actions "
                                f"for {len(X)} objects.")
    model = load_action_model(behavior, path)
    mean = model.predict(np.hstack([X, a]))
    column = {name: j for j, name in enumerate(model.outcome_names_)}
    effect = mean[:, model.effect_columns_]
    displacement = mean[:, [column["dx"], column["dy"]]]
    probs = {k: mean[:, column[k]] for k in ("rolled", "off_table", "lifted")}
    if single:
        return ActionEffectPrediction(effect[0], displacement[0], *(float(v[0]) for v in probs.values()))
    return ActionEffectPrediction(effect, displacement, probs["rolled"], probs["off_table"], probs["lifted"])
