"""Using the affordances: goals, action-conditioned effect models, the planner, and ``affordance plan``'s experiment
with its results and report.

Builds on :mod:`affordance_learning.common` and, for the baseline of the paper's effect categories, on
:mod:`affordance_learning.paper`.
"""
