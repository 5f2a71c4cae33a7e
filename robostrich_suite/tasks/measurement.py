"""What a reaching task measures at one control step: the one reading that evaluation, Rerun
recordings, the training's episode records and gymnasium's ``info`` all take.

Why one type: each of them used to ask the task and the physics for the head's errors, its
position, the target and the tolerances on its own; now the task answers once per step
(``Reach.measure``), with the functions its reward uses, so no reader can disagree with the reward.
:func:`measure` also answers for environments that are not reaching tasks: dm_control's
``point_mass`` (its distance to the target, attitude error 0; for developing the agent) and any
other (NaN errors, no head, no target), judged with the paper's tolerances.
"""
from __future__ import annotations

import dataclasses
import math
from typing import Optional

import numpy as np

from robostrich_suite.tasks.conventions import LEVEL_TOLERANCE_DEG, POSITION_TOLERANCE


def _frozen(vector) -> Optional[np.ndarray]:
    """A float64 copy nobody can change under the measurement (None stays None)."""
    if vector is None:
        return None
    vector = np.array(vector, np.float64)
    vector.flags.writeable = False
    return vector


@dataclasses.dataclass(frozen=True)
class Measurement:
    """One step's reading. position_error (m): the head's distance to the target; attitude_error
    (deg, signed, in [-180, 180): positive = head pitched down); is_success: both within the
    task's own tolerances (position_tolerance m, attitude_tolerance deg); target and
    head_position: (2,) in the task's frame (world (x, z) on the frame, (forward, up) in the
    trunk frame on the quadruped); head_attitude (deg, 90 = level); target_in_world and
    head_in_world: (3,) world points, for drawing. The head's and target's fields are None
    (head_attitude NaN) where the environment has no head or target."""
    position_error: float
    attitude_error: float
    is_success: bool
    position_tolerance: float = POSITION_TOLERANCE
    attitude_tolerance: float = LEVEL_TOLERANCE_DEG
    target: Optional[np.ndarray] = None
    head_position: Optional[np.ndarray] = None
    head_attitude: float = math.nan
    target_in_world: Optional[np.ndarray] = None
    head_in_world: Optional[np.ndarray] = None

    def __post_init__(self):
        for name in ("target", "head_position", "target_in_world", "head_in_world"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))

    def as_dict(self) -> dict:
        """Every field by name (arrays as fresh copies a caller may change): gymnasium's ``info``."""
        return {field.name: (np.array(value) if isinstance(value, np.ndarray) else value)
                for field in dataclasses.fields(self) for value in (getattr(self, field.name),)}


def without_head(position_error: float, attitude_error: float) -> Measurement:
    """The reading of an environment with no head to measure, judged with the paper's tolerances."""
    return Measurement(position_error, attitude_error,
                       is_success=bool(position_error <= POSITION_TOLERANCE
                                       and abs(attitude_error) <= LEVEL_TOLERANCE_DEG))


def measure(env) -> Measurement:
    """``env``'s measurement now: its task's own where the task measures (every reaching task),
    else the module doc's fallbacks."""
    task, physics = env.task, env.physics
    if hasattr(task, "measure"):
        return task.measure(physics)
    if hasattr(physics, "mass_to_target_dist"):  # dm_control's point_mass
        return without_head(float(physics.mass_to_target_dist()), 0.0)
    return without_head(math.nan, math.nan)


def errors(env) -> tuple:
    """(position_error, attitude_error) of :func:`measure`, read without the rest of the reading:
    for evaluation loops that keep only the errors of each step."""
    task = env.task
    if hasattr(task, "measure") and hasattr(task, "position_error"):
        return task.position_error(env.physics), task.attitude_error(env.physics)
    measured = measure(env)
    return measured.position_error, measured.attitude_error
