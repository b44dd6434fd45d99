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
  :class:`Planner` (``affordance plan`` measures them against baselines, :mod:`.plan_experiment`).
"""

import importlib.metadata as _metadata

try:  # the version has one source, the package's metadata (pyproject.toml)
    __version__ = _metadata.version("tap-affordance")
except _metadata.PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"

from affordance_learning.default_model import (  # noqa: E402 (after __version__, which it reads)
    DefaultModelError,
    DefaultModelMissingError,
    load_default_model,
    predict_effect,
    train_default_model,
)
from affordance_learning.effect_model import ActionEffectModel
from affordance_learning.goals import Lift, Move, Percept, Place, Roll, goal_from_dict
from affordance_learning.metrics import adjusted_rand, cluster_purity, svm_cv_accuracy, uniformity
from affordance_learning.model import AffordanceModel, EffectPrediction, select_features
from affordance_learning.planner import Planner
from affordance_learning.relieff import ReliefF, ReliefFScorer, relieff_weights
from affordance_learning.som import SOMClustering

#: Names loaded on first use, so that ``import affordance_learning`` stays light (no matplotlib).
_LAZY = {
    "make_synthetic_frame": "affordance_learning.synthetic",
    "run_protocol": "affordance_learning.protocol",
    "write_figures": "affordance_learning.figures",
    "write_report": "affordance_learning.report",
}


def __getattr__(name: str) -> object:
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'affordance_learning' has no attribute {name!r}")


__all__ = [
    "ActionEffectModel",
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
