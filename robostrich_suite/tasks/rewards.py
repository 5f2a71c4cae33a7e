"""The curriculum's reward functions (paper eqs. 9 and 10), as plain functions.

The ``*_rewards`` variants take arrays: the agent recomputes rewards for
relabelled goals (hindsight) with them, exactly as the task would have given.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from robostrich_suite.tasks import options
from robostrich_suite.tasks.target_samplers import MAX_TARGET_DISTANCE


@dataclasses.dataclass(frozen=True)
class RewardWeights:
    """lambda_1..lambda_4 of eq. 10.

    ``position_miss`` and ``attitude_miss`` weigh the indicator terms (being
    outside the tolerance); ``position_error`` (per metre) and
    ``attitude_error`` (per degree) weigh the shaping terms.  The defaults make
    a 0.1 m miss and a 10 deg miss cost about the same.

    ``position_precision`` and ``attitude_precision`` are not in the paper (0, the
    default, recovers eq. 10): each weighs a Gaussian term ``1 - exp(-e^2 / (2 s^2))``
    of the position error (``s = precision_scale``, m) or the attitude error
    (``s = attitude_precision_scale``, deg), which keeps paying for precision inside
    the tolerance, where eq. 10 pays only its shaping (2 per metre, 0.02 per degree).

    ``action_change`` (per metre, not in the paper; 0 by default) weighs the mean absolute change
    of the tendon inputs from one control step to the next in eq. 10's reward: a policy that
    shakes its inputs at the control rate (as lesson 4 taught on the quadruped:
    docs/log/quadruped.md#2026-12-01-the-distance-walked-leaves-the-observation-lesson-4-in-its-own-run)
    pays for it.  It depends on the action, not on the goal: the replay keeps it as the part of a
    stored reward no goal changes (``Reach.has_goal_free_reward``, agents/goals.py) and adds it to
    the rewards it recomputes for other goals (hindsight, ``relabel_rewards``).

    ``head_vertical_speed`` (per m/s, not in the paper; 0 by default) weighs the head's vertical
    speed in the world while the head is within the position tolerance of its target: on the
    walking quadruped, the bobbing Sec. 5.2.1 asks the arm to cancel once it holds the target
    (charged on the way there too, it taught the head not to move:
    docs/log/quadruped.md#2026-12-03-hindsight-goals-were-off-lesson-4-after-them-the-head-speed-term).
    Unlike ``action_change`` it depends on the goal (its tolerance) in a way ``goal_reward`` does not
    compute, so the agent refuses it with hindsight goals or ``relabel_rewards`` on.
    """
    position_miss: float = 1.0
    attitude_miss: float = 1.0
    position_error: float = 2.0
    attitude_error: float = 0.02
    position_precision: float = 0.0
    precision_scale: float = 0.01
    attitude_precision: float = 0.0
    attitude_precision_scale: float = 1.0
    action_change: float = 0.0
    head_vertical_speed: float = 0.0

    def __post_init__(self):
        scales = {"precision_scale": (MAX_TARGET_DISTANCE, "m"), "attitude_precision_scale": (180.0, "deg")}
        for field in dataclasses.fields(self):
            value = getattr(self, field.name)
            if field.name in scales:
                most, unit = scales[field.name]
                options.number(field.name, value, 0.0, most, f"> 0 and at most {most:g} {unit}", above=True)
            else:
                options.number(f"reward weight {field.name}", value, 0.0, options.MAX_WEIGHT,
                               f"a finite number from 0 to {options.MAX_WEIGHT:g}")

    @property
    def has_precision_terms(self) -> bool:
        return bool(self.position_precision or self.attitude_precision)

    def precision_penalty(self, position_error, attitude_error_deg=0.0):
        """The Gaussian precision terms: 0 on target and level, ``position_precision +
        attitude_precision`` far off."""
        position_error = np.asarray(position_error, np.float64)
        attitude_error_deg = np.asarray(attitude_error_deg, np.float64)
        return (self.position_precision
                * (1.0 - np.exp(-0.5 * (position_error / self.precision_scale) ** 2))
                + self.attitude_precision
                * (1.0 - np.exp(-0.5 * (attitude_error_deg / self.attitude_precision_scale) ** 2)))

    def precision_penalty_of_reading(self, position_error: float, attitude_error_deg: float) -> float:
        """``precision_penalty`` of one step's reading, as a float and bit for bit the same (the
        per-step reward): one numpy ``exp`` of both arguments instead of a dozen 0-d array
        operations.  Each operation is the one ``precision_penalty`` does on numpy scalars:
        ``** 2`` (libm's pow, not ``x * x``) and numpy's exp (not ``math.exp``); either swap
        changes the last bit now and then, and a run would no longer repeat its rewards."""
        position_scaled = position_error / self.precision_scale
        attitude_scaled = attitude_error_deg / self.attitude_precision_scale
        position_gauss, attitude_gauss = np.exp(
            [-0.5 * position_scaled ** 2,
             -0.5 * attitude_scaled ** 2]).tolist()
        return (self.position_precision * (1.0 - position_gauss)
                + self.attitude_precision * (1.0 - attitude_gauss))

    @property
    def largest_penalty(self) -> float:
        """The most a step can lose when both are missed far off (a diverged step costs twice this),
        not counting ``action_change``: a divergence is charged on the head, whatever the inputs did."""
        return self.position_miss + self.attitude_miss + self.position_precision + self.attitude_precision


def lesson1_reward(position_error: float, position_tolerance: float) -> float:
    """Eq. 9: -1 while the head is farther than ``d`` from the target, else 0."""
    return -float(position_error > position_tolerance)


def lesson2_reward(position_error: float, attitude_error_deg: float, position_tolerance: float,
                   attitude_tolerance_deg: float, weights: RewardWeights = RewardWeights()
                   ) -> float:
    """Eq. 10: r_m2 + r_a2, indicator misses plus weighted absolute errors."""
    attitude_error_deg = abs(attitude_error_deg)
    r_m2 = (-weights.position_miss * float(position_error > position_tolerance)
            - weights.attitude_miss * float(attitude_error_deg > attitude_tolerance_deg))
    r_a2 = -weights.position_error * position_error - weights.attitude_error * attitude_error_deg
    if weights.has_precision_terms:
        r_a2 -= weights.precision_penalty_of_reading(float(position_error), attitude_error_deg)
    return r_m2 + r_a2


def lesson1_rewards(position_error, position_tolerance: float) -> np.ndarray:
    """Eq. 9 on arrays of position errors."""
    return -(np.asarray(position_error) > position_tolerance).astype(np.float64)


def lesson2_rewards(position_error, attitude_error_deg, position_tolerance: float,
                    attitude_tolerance_deg: float, weights: RewardWeights = RewardWeights()
                    ) -> np.ndarray:
    """Eq. 10 on arrays of position and attitude errors (same result as ``lesson2_reward``)."""
    position_error = np.asarray(position_error, np.float64)
    attitude_error_deg = np.abs(np.asarray(attitude_error_deg, np.float64))
    return (-weights.position_miss * (position_error > position_tolerance)
            - weights.attitude_miss * (attitude_error_deg > attitude_tolerance_deg)
            - weights.position_error * position_error - weights.attitude_error * attitude_error_deg
            - weights.precision_penalty(position_error, attitude_error_deg))
