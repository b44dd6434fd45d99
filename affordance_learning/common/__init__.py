"""What the paper's experiment and the planner's share: errors, input checks, statistics, verdicts, the behaviours'
names for people and the dataset schema as learning reads it.

Nothing here imports :mod:`affordance_learning.paper` or :mod:`affordance_learning.planning`.
"""
