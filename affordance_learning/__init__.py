"""Unsupervised affordance learning after Akgun et al. 2009: SOM of effects -> ReliefF -> SVM.

- :class:`AffordanceModel`: the learning model for one behaviour, a scikit-learn estimator
  (``fit(initial_features, effects)``, ``predict``, ``predict_effect``).
- :class:`SOMClustering`: a 1 x k self-organising map (minisom) as a scikit-learn clusterer.
- :func:`relieff_weights`: ReliefF feature weights equal to skrebate's, vectorised.
- :func:`uniformity`, :func:`cluster_purity`, :func:`adjusted_rand`, :func:`svm_cv_accuracy`: the metrics.
- :func:`predict_effect`: the effect of a behaviour's interaction predicted from an object's 49 features by
  that behaviour's default model (the tap's is shipped; ``affordance train-default --behavior`` builds others).
- :func:`run_protocol`, :func:`write_figures`, :func:`write_report`: the paper's experiment on one behaviour
  and its outputs (``affordance reproduce`` runs them end to end for the tap and the grasp).
- Using the affordances: :class:`ActionEffectModel` ([features, action] -> outcome, with a predictive
  distribution), the goals (:class:`Roll`, :class:`Lift`, :class:`Move`, :class:`Place`, :class:`Percept`) and
  :class:`Planner` (``affordance plan`` measures them against baselines, :mod:`.planning.experiment`).
"""

import importlib
import importlib.util


def _version() -> str:
    """The version, from its one source, the package's metadata (pyproject.toml). Read when first asked for:
    importlib.metadata takes a tenth of a second to load, which ``import affordance_learning`` (and so the
    command, before it can say anything of a Ctrl-C) does not wait for."""
    import importlib.metadata as metadata

    try:
        return metadata.version("tap-affordance")
    except metadata.PackageNotFoundError:  # a source tree that was never installed
        return "0+unknown"


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY, "__version__"})

#: The public names, each loaded from its module on first use: ``import affordance_learning`` (and so the
#: ``affordance`` command, which checks its arguments before any work) stays light, with no scikit-learn, SciPy,
#: pandas or matplotlib until a name is used.
_LAZY = {
    **dict.fromkeys(("ActionEffectPrediction", "DefaultModelError", "DefaultModelMissingError", "load_action_model",
                     "load_default_model", "predict_effect", "train_default_model"),
                    "affordance_learning.default_model"),
    "ActionEffectModel": "affordance_learning.planning.effect_model",
    **dict.fromkeys(("Lift", "Move", "Percept", "Place", "Roll", "goal_from_dict"),
                    "affordance_learning.planning.goals"),
    **dict.fromkeys(("adjusted_rand", "cluster_purity", "svm_cv_accuracy", "uniformity"),
                    "affordance_learning.paper.metrics"),
    **dict.fromkeys(("AffordanceModel", "EffectPrediction", "select_features"), "affordance_learning.paper.model"),
    "Planner": "affordance_learning.planning.planner",
    **dict.fromkeys(("ReliefF", "ReliefFScorer", "relieff_weights"), "affordance_learning.paper.relieff"),
    "SOMClustering": "affordance_learning.paper.som",
    "make_synthetic_frame": "affordance_learning.paper.synthetic",
    "run_protocol": "affordance_learning.paper.protocol",
    "write_figures": "affordance_learning.paper.figures",
    "write_report": "affordance_learning.paper.report",
}


def __getattr__(name: str) -> object:
    if name == "__version__":
        globals()[name] = value = _version()
        return value
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value  # found directly from now on
        return value
    if importlib.util.find_spec(f"{__name__}.{name}") is not None:  # a submodule: affordance_learning.paper.model, ...
        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'affordance_learning' has no attribute {name!r}")


__all__ = [
    "ActionEffectModel",
    "ActionEffectPrediction",
    "AffordanceModel",
    "Lift",
    "Move",
    "Percept",
    "Place",
    "Planner",
    "Roll",
    "goal_from_dict",
    "DefaultModelError",
    "DefaultModelMissingError",
    "EffectPrediction",
    "ReliefF",
    "ReliefFScorer",
    "SOMClustering",
    "adjusted_rand",
    "cluster_purity",
    "load_action_model",
    "load_default_model",
    "make_synthetic_frame",
    "predict_effect",
    "relieff_weights",
    "run_protocol",
    "select_features",
    "svm_cv_accuracy",
    "train_default_model",
    "uniformity",
    "write_figures",
    "write_report",
    "__version__",
]
