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
"""

from __future__ import annotations

import functools
import os
from pathlib import Path
from typing import Any

import joblib
import numpy as np
import pandas as pd
from numpy.typing import ArrayLike

from affordance_learning.behaviors import check_behavior
from affordance_learning.exceptions import DefaultModelError, DefaultModelMissingError, InvalidValueError
from affordance_learning.model import AffordanceModel, EffectPrediction
from affordance_learning.validation import first_non_finite

#: Where the package's own default models are, one file per behaviour (read only).
MODEL_DIR = Path(__file__).resolve().parent / "data"
#: The package's default tap model.
DEFAULT_MODEL_PATH = MODEL_DIR / "tap_model.joblib"
#: Environment variable naming the user's data directory, where rebuilt default models go.
DATA_ENV = "TAP_AFFORDANCE_DATA"
#: Map size and relevancy threshold of the default model.
DEFAULT_N_CLUSTERS = 4
DEFAULT_RELEVANCY = 0.4
#: Maps the default model trains (from seeds 0 to 9), of which it keeps the one of lowest quantization error
#: (:class:`~affordance_learning.som.SOMClustering`'s ``n_init``). One map is a stochastic descent: on the 1000
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


def user_model_dir() -> Path:
    """The user's directory of default models: ``$TAP_AFFORDANCE_DATA``, else ``$XDG_DATA_HOME/tap-affordance``,
    else ``~/.local/share/tap-affordance`` (the XDG convention for a user's application data)."""
    setting = os.environ.get(DATA_ENV)
    if setting:
        return Path(setting).expanduser()
    base = os.environ.get("XDG_DATA_HOME") or Path.home() / ".local" / "share"
    return Path(base) / "tap-affordance"


def user_model_path(behavior: str = "tap") -> Path:
    """Where ``affordance train-default`` stores the default model of ``behavior`` (:func:`user_model_dir`)."""
    return user_model_dir() / f"{check_behavior(behavior)}_model.joblib"


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
        behavior: The behaviour of the interactions, one of :data:`affordance_learning.behaviors.BEHAVIORS`.
        n_clusters: Effect categories (map size), in [2, 10].
        relevancy: Relevancy threshold of the feature selection, in [0, 1].
        random_state: Seed of the first map (the others follow it: :class:`~affordance_learning.som.SOMClustering`).
        som_n_init: Maps trained, of which the one of lowest quantization error is kept.

    Returns:
        The fitted model.

    Raises:
        ValueError: An unknown behaviour, a frame of another behaviour or of several, or missing columns.
    """
    from affordance_learning.schema import frame_behavior

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
        behavior: The behaviour the model must be of, one of :data:`affordance_learning.behaviors.BEHAVIORS`.

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
    features: ArrayLike | pd.DataFrame, behavior: str = "tap", *, path: str | Path | None = None
) -> EffectPrediction:
    """Predict the effect category of a behaviour's canonical interaction with objects, and what the effect
    looks like, from their 49 features.

    Args:
        features: One (49,) or many (n, 49) feature vectors of objects before the interaction, in the order
            of ``affordance_env.features.FEATURE_NAMES`` (``obs["features"]`` of ``TapAffordance-v2``), or a
            DataFrame with those columns (in any order; other columns are ignored); finite.
        behavior: Whose default model predicts: ``"tap"`` (shipped), ``"grasp"``, ``"tap_back"`` or
            ``"push"`` (built by ``affordance train-default --behavior NAME``).
        path: The stored model (default: the user's model of the behaviour, else the package's:
            :func:`model_path`).

    Returns:
        For a batch, (n, 49) or a DataFrame: ``category`` (n,) int and ``effect`` (n, 49) float, the category's
        prototype effect (final minus initial features, in each feature's unit). For one (49,) vector: one
        result, ``category`` an int and ``effect`` (49,).

    Raises:
        ValueError: An unknown behaviour, or ``features`` has another shape or lacks feature columns, or holds
            NaN or inf.
        DefaultModelMissingError: The behaviour's default model was not built (the message gives the command).
        DefaultModelError: The default model is broken, of another behaviour or stale (rebuild it with
            ``affordance train-default --behavior NAME``).
    """
    path = model_path(behavior) if path is None else Path(path)
    check_behavior(behavior)
    if isinstance(features, pd.DataFrame):
        names = _feature_names()
        missing = [n for n in names if n not in features.columns]
        if missing:
            raise InvalidValueError(
                f"the features DataFrame lacks {len(missing)} feature column(s), e.g. {missing[:4]}; "
                "expected the names of affordance_env's FEATURE_NAMES."
            )
        features = features[names].to_numpy()
    X = np.asarray(features)
    if X.dtype == object or not (np.issubdtype(X.dtype, np.number) or X.dtype == bool) or np.iscomplexobj(X):
        raise InvalidValueError(f"features must be real numbers, got dtype {X.dtype}.")
    if X.ndim not in (1, 2) or X.shape[-1] != _N_FEATURES or (X.ndim == 2 and X.shape[0] == 0):
        raise InvalidValueError(
            f"features must have shape ({_N_FEATURES},) or (n, {_N_FEATURES}) with n >= 1, got {X.shape}."
        )
    single = X.ndim == 1
    X = np.atleast_2d(X).astype(np.float64)
    found = first_non_finite(X)
    if found:
        count, row, col, value = found
        raise InvalidValueError(
            f"features must be finite; row {row}, feature {col} is {value} ({count} non-finite value(s)).")
    model, names = _load_checked(path, behavior)
    prediction = model.predict_effect(pd.DataFrame(X, columns=list(names)))
    if single:  # one vector in, one result out
        return EffectPrediction(category=int(prediction.category[0]), effect=prediction.effect[0])
    return prediction
