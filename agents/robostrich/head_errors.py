"""Reads the head's errors from an environment, for success and evaluation.

Success (paper, sec. 4.2): head within 0.05 m of the target and within 5 deg
of the desired attitude (90 deg = level) at the end of an episode.
"""
import numpy as np

# The paper's tolerances and desired attitude, defined once by the tasks.
from robostrich_suite.tasks.reach import ATTITUDE_TOLERANCE, POSITION_TOLERANCE  # noqa: F401
from robostrich_suite.tasks.reach import DESIRED_ATTITUDE as LEVEL_ATTITUDE  # noqa: F401


def head_errors(env):
    """(position error m, |attitude error| deg) of the current state; NaN where the env cannot tell.

    robostrich: the task's own `position_error(physics)` / `attitude_error(physics)`
    (robostrich_suite.tasks.reach.Reach). dm_control's point_mass is supported for
    development (attitude error 0).
    """
    physics, task = env.physics, env.task
    if hasattr(task, "position_error") and hasattr(task, "attitude_error"):
        return float(task.position_error(physics)), float(abs(task.attitude_error(physics)))
    if hasattr(physics, "mass_to_target_dist"):
        return float(physics.mass_to_target_dist()), 0.0
    return float("nan"), float("nan")


def head_xz(env):
    """The head position in the arm's plane (x, z), or None for other domains."""
    task = env.task
    if hasattr(task, "head_xz"):
        return np.asarray(task.head_xz(env.physics), np.float64)
    return None


def tolerances(env):
    """(position m, attitude deg) the task judges success with: the task's own, so a task built
    with `position_tolerance=0.02` is scored against 0.02; the paper's 0.05 m and 5 deg otherwise."""
    task = env.task
    return (float(getattr(task, "position_tolerance", POSITION_TOLERANCE)),
            float(getattr(task, "attitude_tolerance", ATTITUDE_TOLERANCE)))


def is_success(position_error, attitude_error, position_tolerance=POSITION_TOLERANCE,
               attitude_tolerance=ATTITUDE_TOLERANCE) -> bool:
    return bool(position_error <= position_tolerance and attitude_error <= attitude_tolerance)


def episode_metrics(env) -> dict:
    """What an episode's record in metrics.jsonl gets from its last state: the head's errors and
    whether they count as success (the curriculum loop's ``episode_probe``)."""
    position_error, attitude_error = head_errors(env)
    return {"position_error": position_error, "attitude_error": attitude_error,
            "success": is_success(position_error, attitude_error, *tolerances(env))}
