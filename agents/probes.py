"""Reads the head's errors from an environment, for success and evaluation.

Success (paper, sec. 4.2): head within 0.05 m of the target and within 5 deg
of the desired attitude (90 deg = level) at the end of an episode.
"""
import numpy as np

POSITION_TOLERANCE = 0.05  # m
ATTITUDE_TOLERANCE = 5.0  # deg
LEVEL_ATTITUDE = 90.0  # deg


def head_errors(env):
    """(position error m, attitude error deg) of the current state; NaN where the env cannot tell.

    robostrich: physics.head_position()/head_attitude() against task.target_position
    (and task.target_attitude if the task has one, else 90 deg). dm_control's point_mass
    is supported for development (attitude error 0).
    """
    physics, task = env.physics, env.task
    if hasattr(physics, "head_position") and hasattr(task, "target_position"):
        pos = np.asarray(physics.head_position(), np.float64)
        target = np.asarray(task.target_position, np.float64)
        position_error = float(np.linalg.norm(pos - target))
        attitude_target = float(getattr(task, "target_attitude", LEVEL_ATTITUDE))
        attitude_error = float(abs(float(physics.head_attitude()) - attitude_target))
        return position_error, attitude_error
    if hasattr(physics, "mass_to_target_dist"):
        return float(physics.mass_to_target_dist()), 0.0
    return float("nan"), float("nan")


def is_success(position_error, attitude_error) -> bool:
    return bool(position_error <= POSITION_TOLERANCE and attitude_error <= ATTITUDE_TOLERANCE)
