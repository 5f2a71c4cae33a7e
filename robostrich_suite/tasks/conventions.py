"""Conventions every task and study shares, each stated once here and imported.

The level head (the tasks' desired attitude and the workspace's blue region),
the tasks' success tolerances (and the precise reach evaluations report) and the timesteps (paper Sec. 4.2).
"""
from robostrich_suite.model.timesteps import CONTROL_TIMESTEP, PHYSICS_TIMESTEP  # noqa: F401 (the model's)

LEVEL_ATTITUDE_DEG = 90.0  # deg: head parallel to the ground (paper Fig. 2B)
LEVEL_TOLERANCE_DEG = 5.0  # deg: a head within this of level counts as level
POSITION_TOLERANCE = 0.05  # m (paper Sec. 4.2)
# A precise reach: the accuracy the project aims for (median final errors <= 1 cm, 2 deg).
# Evaluations report the share of episodes within it beside the paper's success, because
# the paper's 5 cm / 5 deg also counts the lookup baseline's nearest stored pose a success.
PRECISE_POSITION_TOLERANCE = 0.01  # m
PRECISE_ATTITUDE_TOLERANCE_DEG = 2.0  # deg

