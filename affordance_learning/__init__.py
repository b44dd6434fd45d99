"""Unsupervised affordance learning (Akgun et al. 2009): SOM of effects -> ReliefF -> SVM.

- :class:`AffordanceModel`: the learning model, a scikit-learn estimator, for any (initial features, effects).
- :func:`predict_effect`: the effect of a tap predicted from an object's 49 features, by the shipped model.
- :func:`run_protocol`: the paper's experiment on a dataset; ``affordance reproduce`` runs it end to end.
"""

__version__ = "0.1.0"

from affordance_learning.default_model import load_default_model, predict_effect, train_default_model  # noqa: E402
from affordance_learning.experiment import run_protocol  # noqa: E402
from affordance_learning.metrics import adjusted_rand, cluster_purity, uniformity  # noqa: E402
from affordance_learning.model import AffordanceModel, EffectPrediction  # noqa: E402
from affordance_learning.relieff import relieff_weights  # noqa: E402
from affordance_learning.som import SOMClustering  # noqa: E402

__all__ = [
    "AffordanceModel",
    "EffectPrediction",
    "SOMClustering",
    "adjusted_rand",
    "cluster_purity",
    "load_default_model",
    "predict_effect",
    "relieff_weights",
    "run_protocol",
    "train_default_model",
    "uniformity",
    "__version__",
]
