"""The paper's experiment (Akgun et al. 2009): the learning model (SOM of effects -> ReliefF -> SVM), its metrics,
the protocol over k and r, the paper's claims as verdicts, the report, the figures and ``affordance reproduce``.

Builds on :mod:`affordance_learning.common` only.
"""
