"""The ``robostrich_a1`` tasks: the arm on a walking A1-like quadruped (Sec. 4.2, 5.2).

The trunk frame.  Targets, head position and velocities are given in a frame that
walks with the quadruped: origin on the ground under the trunk centre, x along the
trunk's heading (projected on the ground), y to its left, z up.  A target
``(forward, up)`` is thus "this far ahead of the trunk centre, this high above the
ground": the same meaning while standing (lessons 1-3), while the trunk bobs and
changes height (lesson 4) and in ``head_stabilize``, where the target *is* ``(P_d,
height)``.  The head attitude is measured in the trunk's heading plane.  The default
targets are the ``robostrich`` level-head poses, moved from the frame's neck base to the
arm mount on the trunk at the standing height.

Observations (Table 2, then the goal and tendon state as in ``robostrich``):
``head_position`` (3), ``head_velocity`` (3), ``joint_angles`` (18),
``trunk_position`` (3: the trunk centre in the trunk frame, so (0, 0, height above ground)),
``trunk_velocity`` (3, trunk frame), ``target_position`` (2), ``to_target`` (2),
``attitude_error``, ``head_attitude``, ``tendon_contraction`` (9), ``tendon_tension`` (9).
The action is the 9 tendon contractions; the legs follow the gait, not the policy.

Timing: control step 0.008 s (the paper's) = 4 physics steps of 0.002 s; the
open-loop trot with the arm mounted is stable at 2 ms (implicitfast integrator).
Each episode starts with the quadruped standing still after ``SETTLE_TIME`` of
physics, so the servos' sag under the robot's weight is not part of the episode.
The legs' joint targets come from :mod:`robostrich_suite.tasks.gait` (default: replay of
the shipped gait file ``data/a1_trot.csv``), written to the leg servos in
``before_step``; the commanded trunk height is raised by the servos' measured sag
(``legs.SAG_COMPENSATION``) and a small steering loop keeps the walk on its start line
(``STEER_*``; ``steer=False`` gives the pure open-loop gait).

A fallen quadruped (trunk tilted past 60 deg) or a physics divergence ends the episode.

Run ``robostrich-walk`` to see the perturbation the arm gets.
"""
from __future__ import annotations

import collections
import math

import numpy as np

from robostrich_suite.model import legs
from robostrich_suite.model import quadruped as quad
from robostrich_suite import scenes
from robostrich_suite.tasks import gait as gait_lib
from robostrich_suite.tasks import options, perturbations, reach, target_samplers, track
from robostrich_suite import targets

SETTLE_TIME = 0.2  # s of standing physics before each fresh episode
LESSON4_TIME_LIMIT = 6.0  # s: stand-in, lowered/raised, back (one height change)
HEAD_STABILIZE_TIME_LIMIT = 12.0  # s (1500 steps, Fig. 9)
NARROW_GAP_STEPS_PER_TARGET = 150  # control steps = 1.2 s per sub-target
FALL_UPRIGHTNESS = 0.5  # trunk z-axis z component below this = fallen over
# Steering on top of the open-loop gait: an open-loop trot wanders 10-20 deg in yaw
# and drifts sideways.  Like the real A1's own controller, the task keeps the walk on
# the +x line through the start: the desired yaw leans back towards the line, and the
# stride of the left legs is lengthened (right legs shortened) in proportion to the
# yaw error.
STEER_YAW_GAIN = 1.0  # stride change (fraction) per rad of yaw error
STEER_LINE_GAIN = 1.5  # rad of desired yaw per m off the line
STEER_MAX_YAW = 0.3  # rad
STEER_MAX_STRIDE_CHANGE = 0.5  # fraction of the stride
GAP_STOP_DISTANCE = 0.16  # m, the quadruped stops when the arm's base is this close to the wall

# head_stabilize (Sec. 5.2.1): P_d and the head height above ground.  A level-head pose in the
# middle of the default layout's densest band of level poses, the neck reaching forward over the
# head (frame pose (0.45, 0.33) on the trunk), so holding its stored input alone keeps the head near level.
HEAD_STABILIZE_DISTANCE = 0.54  # m ahead of the trunk centre
HEAD_STABILIZE_HEIGHT = 0.62  # m above the ground
# Fig. 9A: trunk height lowered during steps 500-750 and raised back during 1000-1250.
HEAD_STABILIZE_HEIGHTS = gait_lib.TrunkHeightSchedule(
    times=(0.0, 4.0, 6.0, 8.0, 10.0),
    heights=(quad.STANDING_TRUNK_HEIGHT, quad.STANDING_TRUNK_HEIGHT, 0.22, 0.22,
             quad.STANDING_TRUNK_HEIGHT))
LESSON4_HEIGHT_RANGE = (0.21, 0.30)  # m, random trunk height of the middle of an episode

# The six sub-targets (x from the wall's near face, height above ground), Fig. 10.
# Heights stay within the level-head workspace: 0.1-0.24 m above the arm's base
# (0.37 m above ground when standing) and 0.15-0.45 m ahead of it.
GAP_TARGETS = np.array([
    [-0.06, 0.45],  # 1: down in front of the wall
    [0.08, 0.45],  # 2: under the overhang
    [scenes.GAP_SLOT_X, 0.45],  # 3: the bottom of the gap
    [scenes.GAP_SLOT_X, scenes.GAP_SHELF_BOTTOM + scenes.GAP_SHELF_THICKNESS / 2],  # 4: in the gap
    [scenes.GAP_SLOT_X, scenes.GAP_SHELF_BOTTOM + scenes.GAP_SHELF_THICKNESS + 0.03],  # 5: just through it
    [scenes.GAP_SLOT_X, scenes.GAP_SHELF_BOTTOM + scenes.GAP_SHELF_THICKNESS + 0.07],  # 6: the top target
])


def default_target_pool() -> np.ndarray:
    """``robostrich``'s level-head training targets, in the trunk frame (module doc)."""
    return frame_to_trunk(targets.training_targets())


# (x, z) on the frame -> (forward, up) on the standing A1: the arm's base moves from the
# frame's neck base to the mount on the trunk at the standing height.
FRAME_TO_TRUNK_OFFSET = np.array([scenes.MOUNT_OFFSET[0], scenes.NOMINAL_MOUNT_HEIGHT - scenes.FRAME_MOUNT_HEIGHT])


def frame_to_trunk(frame_targets) -> np.ndarray:
    """(x, z) head positions of the arm on its frame -> (forward, up) on the standing A1."""
    frame_targets = target_samplers.as_targets(frame_targets, "targets")
    return frame_targets + FRAME_TO_TRUNK_OFFSET


# The observations of these tasks in terms of ``robostrich``'s (the arm on its frame), for
# starting a1 training from an agent trained on the frame (agents/robostrich/train/transfer.py).  Per key,
# the frame's (key, component) that each component equals, None for an input the frame
# arm has not (the trunk's motion, the sideways 'left' component); keys not listed are the
# frame's own, component by component.  On a standing, level quadruped at the nominal
# height the arm is where the frame holds it, moved by FRAME_TO_TRUNK_OFFSET: the frame's
# FRAME_POSITION_KEYS add it, velocities, to_target and the rest are unchanged.
FRAME_OBSERVATION_SOURCES = {
    "head_position": (("head_position", 0), None, ("head_position", 1)),  # forward, left, up
    "head_velocity": (("head_velocity", 0), None, ("head_velocity", 1)),
    "trunk_position": (None, None, None),
    "trunk_velocity": (None, None, None),
}
FRAME_POSITION_KEYS = ("head_position", "target_position")


_STANDING = gait_lib.Standing()
_LEFT_SIGN = np.array([1.0 if leg.endswith("L") else -1.0 for leg in quad.LEGS])


class _QuadrupedTaskMixin:
    """What every ``robostrich_a1`` task shares: legs driven by a gait, tendon-only
    actions, Table 2 observations in the trunk frame, episodes starting from standing.

    Args:
      legs: ``"stand"`` or ``"walk"``.
      gait: for walking, a :class:`gait.TrotGait`, a :class:`gait.GaitReplay` or a gait
        file path (or any object with ``joint_targets(t, trunk_height, stride_scale)``);
        default: replay of the shipped file.
      trunk_heights: a :class:`gait.TrunkHeightSchedule` (or a dict of its fields), a callable
        ``random -> schedule`` (a new schedule each episode), or ``None`` (constant nominal height).
      steer: keep the walk on the start line (see ``STEER_*``); off = the pure open-loop gait.
      standing_share: for walking, the chance that an episode stands still at the nominal
        height instead (the standing lessons rehearsed, so that training to walk does not
        unlearn them); standing tasks always stand.
    """

    # The goal (forward, up) is compared with these components of the 3-D head position (the goal
    # spec's achieved_components, agents/goals.py); without them hindsight goals and recomputed
    # rewards were silently off.
    ACHIEVED_COMPONENTS = (0, 2)

    def __init__(self, *, legs: str = "stand", gait=None, trunk_heights=None, steer: bool = True,
                 standing_share: float = 0.0, **kwargs):
        if legs not in ("stand", "walk"):
            raise ValueError(f"unknown legs {legs!r}; use 'stand' or 'walk'")
        standing_share = options.share("standing_share", standing_share)
        steer = options.flag("steer", steer)
        if not callable(trunk_heights):  # a schedule, or a callable drawing one per episode
            trunk_heights = options.instance("trunk_heights", trunk_heights, gait_lib.TrunkHeightSchedule)
        if legs == "walk":
            if gait is None:
                gait = gait_lib.GaitReplay.from_file()
            elif not hasattr(gait, "joint_targets"):
                gait = gait_lib.GaitReplay.from_file(gait)
        elif gait is not None:
            raise ValueError("gait applies to the walking tasks (lesson4, head_stabilize, narrow_gap); "
                             "this task's quadruped stands")
        else:
            gait = gait_lib.Standing()
        self.legs = legs
        self.gait = gait
        self.steer = bool(steer)
        self.standing_share = float(standing_share)
        self.episode_legs = legs  # "stand" in a walking task's standing episode (standing_share)
        self._trunk_heights = trunk_heights
        self.height_schedule = gait_lib.TrunkHeightSchedule()
        self._episode_start_time = 0.0
        self._episode_start_xy = np.zeros(2)
        super().__init__(**kwargs)

    # Episode.
    def initialize_episode(self, physics):
        self.episode_legs = self.legs
        if self.legs == "walk" and self.standing_share > 0.0:  # no draw otherwise: streams as before
            self.episode_legs = "stand" if self.random.uniform() < self.standing_share else "walk"
        schedule = self._trunk_heights
        if callable(schedule) and not isinstance(schedule, gait_lib.TrunkHeightSchedule):
            schedule = schedule(self.random)
        if self.episode_legs != self.legs:
            schedule = None  # a standing episode holds the nominal height
        self.height_schedule = schedule or gait_lib.TrunkHeightSchedule()
        continuing = self.initial_state == "continue" and self._continuing_state(physics) is not None
        if isinstance(self.randomizer, perturbations.Perturber):
            self._begin_robot(physics)  # its trunk height is known before the quadruped stands
        if not continuing:
            physics.place_standing(trunk_height=float(self.height_schedule(0.0)) + self._trunk_height_error())
            physics.forward()
            physics.step(int(round(SETTLE_TIME / physics.model.opt.timestep)))
        super().initialize_episode(physics)
        self._episode_start_time = physics.data.time
        self._episode_start_xy = physics.trunk_position()[:2]
        self.update_target(physics)

    def checkpoint_state(self) -> dict:
        """The reaching task's episode variables plus the legs, the trunk height schedule and
        the episode's start (``reach.Reach.checkpoint_state``)."""
        schedule = self.height_schedule
        return {**super().checkpoint_state(), "episode_legs": self.episode_legs,
                "height_schedule": (schedule.times, schedule.heights),
                "episode_start_time": self._episode_start_time, "episode_start_xy": self._episode_start_xy}

    def restore_checkpoint_state(self, state: dict) -> None:
        super().restore_checkpoint_state(state)
        if state["episode_legs"] not in ("stand", "walk"):
            raise ValueError(f"unknown stored legs {state['episode_legs']!r}")
        self.episode_legs = state["episode_legs"]
        times, heights = state["height_schedule"]
        self.height_schedule = gait_lib.TrunkHeightSchedule(times, heights)
        self._episode_start_time = float(state["episode_start_time"])
        self._episode_start_xy = np.array(state["episode_start_xy"], np.float64)

    def episode_time(self, physics) -> float:
        return physics.data.time - self._episode_start_time

    def trunk_height_command(self, physics) -> float:
        return float(self.height_schedule(self.episode_time(physics)))

    def command_trunk_height(self, physics, height: float, ramp_time: float = 0.5) -> None:
        """From now on, move the trunk height command linearly to ``height`` (m) over
        ``ramp_time`` seconds and hold it (replaces the episode's schedule)."""
        now = self.episode_time(physics)
        self.height_schedule = gait_lib.TrunkHeightSchedule(
            (now, now + max(ramp_time, 1e-6)), (self.trunk_height_command(physics), height))

    def leg_targets(self, physics) -> np.ndarray:
        t = self.episode_time(physics)
        height = (float(self.height_schedule(t)) + legs.SAG_COMPENSATION[self.episode_legs]
                  + self._trunk_height_error())
        if self.episode_legs == "stand":
            return _STANDING.joint_targets(t, height)
        scale = self.stride_scale(physics) if self.steer else None
        if isinstance(self.randomizer, perturbations.Perturber):  # the gait's clock is off (gait_timing)
            t = self.randomizer.gait_rate * t + self.randomizer.gait_phase
        return self.gait.joint_targets(t, height, scale)

    def _trunk_height_error(self) -> float:
        """How much higher the trunk stands than commanded (tasks.perturbations' trunk_height)."""
        return self.randomizer.trunk_height_offset if isinstance(self.randomizer, perturbations.Perturber) else 0.0

    def stride_scale(self, physics) -> np.ndarray:
        """Per-leg scale of the fore-aft foot travel that turns back onto the walking line."""
        off_line = physics.trunk_position()[1] - self._episode_start_xy[1]
        desired = -min(max(STEER_LINE_GAIN * off_line, -STEER_MAX_YAW), STEER_MAX_YAW)
        hx, hy = physics.heading()
        error = math.atan2(hy, hx) - desired
        change = min(max(STEER_YAW_GAIN * error, -STEER_MAX_STRIDE_CHANGE),
                     STEER_MAX_STRIDE_CHANGE)
        return 1.0 + change * _LEFT_SIGN  # yawed left (error > 0): left legs step longer

    def before_step(self, action, physics):
        super().before_step(action, physics)  # tendons: NaN check, clipping (reach.Reach)
        physics.set_leg_targets(self.leg_targets(physics))

    def after_step(self, physics):
        super().after_step(physics)
        self.update_target(physics)

    def update_target(self, physics) -> None:
        """Hook for targets fixed in the world (``narrow_gap``); others live in the trunk frame."""

    def get_termination(self, physics):
        if physics.divergence is not None or physics.trunk_uprightness() < FALL_UPRIGHTNESS:
            return 0.0
        return None

    # Measurements in the trunk frame.
    def head_xz(self, physics) -> np.ndarray:
        return physics.to_trunk_frame(physics.head_position())[[0, 2]]

    def target_in_world(self, physics) -> np.ndarray:
        """The target (forward, up) in the trunk frame as a world point in the trunk's vertical plane."""
        return physics.from_trunk_frame(float(self.target_position[0]), float(self.target_position[1]))

    def get_observation(self, physics):
        """Table 2 (head, joints, trunk), then the goal and tendon state (module doc)."""
        shared = super().get_observation(physics)
        obs = collections.OrderedDict()
        obs["head_position"] = physics.to_trunk_frame(physics.head_position())
        obs["head_velocity"] = physics.to_trunk_frame(physics.head_velocity(), velocity=True)
        obs["joint_angles"] = shared["joint_angles"]
        # In the trunk frame, as every position here: (0, 0, height). The distance walked since
        # the episode start is no input: a policy trained on 6 s episodes (lesson 4) meets
        # distances it never saw in 12 s ones and lets the head drift
        # (docs/log/quadruped.md#2026-12-01-the-distance-walked-leaves-the-observation-lesson-4-in-its-own-run).
        obs["trunk_position"] = np.array([0.0, 0.0, physics.trunk_height()])
        obs["trunk_velocity"] = physics.to_trunk_frame(physics.trunk_velocity(), velocity=True)
        for key, value in shared.items():
            if key not in obs and key not in ("head_position", "head_velocity"):
                obs[key] = value
        return obs


class QuadrupedReach(_QuadrupedTaskMixin, reach.Reach):
    """A ``robostrich`` lesson on the quadruped; targets in the trunk frame."""

    def __init__(self, target_pool=None, **kwargs):
        if target_pool is None:
            target_pool = default_target_pool()
        super().__init__(target_pool=target_pool, **kwargs)


class NarrowGap(_QuadrupedTaskMixin, track.Track):
    """Walk up to the wall, stop, track ``GAP_TARGETS`` (fixed in the world) in order.

    ``switch`` says when the next sub-target becomes active: ``"time"`` (default, as
    ``track``): every ``steps_per_target`` control steps, the same schedule for every
    policy; ``"reached"``: once the head is within ``position_tolerance`` of the current
    one (the order is enforced, a policy that misses one stays on it).  With the time
    schedule sub-targets 1-3 are active while the quadruped still walks towards the
    wall (it stops ~4 s in), farther ahead of the arm's base than the head reaches.
    """

    SWITCHES = ("time", "reached")

    def __init__(self, stop_distance: float = GAP_STOP_DISTANCE, switch: str = "time", **kwargs):
        if switch not in self.SWITCHES:
            raise ValueError(f"unknown switch {switch!r}; use one of {list(self.SWITCHES)}")
        most = target_samplers.MAX_TARGET_DISTANCE
        stop_distance = options.number("stop_distance", stop_distance, 0.0, most,
                                       f"a positive distance, at most {most:g} m", above=True)
        kwargs.setdefault("targets", GAP_TARGETS)
        kwargs.setdefault("steps_per_target", NARROW_GAP_STEPS_PER_TARGET)
        super().__init__(legs="walk", **kwargs)
        self.switch = switch
        self.stop_distance = stop_distance
        self.world_targets = np.asarray(self.targets, float) + [scenes.GAP_WALL_X, 0.0]
        self._stopped_at = None

    def initialize_episode(self, physics):
        self._stopped_at = None
        super().initialize_episode(physics)

    def checkpoint_state(self) -> dict:
        return {**super().checkpoint_state(), "stopped_at": self._stopped_at}

    def restore_checkpoint_state(self, state: dict) -> None:
        super().restore_checkpoint_state(state)
        stopped = state["stopped_at"]
        self._stopped_at = None if stopped is None else (float(stopped[0]), np.array(stopped[1], np.float64))

    def update_target(self, physics) -> None:
        x, z = self.world_targets[self.target_index]
        self.target_position = physics.to_trunk_frame([x, 0.0, z])[[0, 2]]

    def active_target_index(self, physics) -> int:
        if self.switch == "time":
            return super().active_target_index(physics)
        self.update_target(physics)  # the trunk moved this step
        reached = self.position_error(physics) <= self.position_tolerance
        return min(self.target_index + int(reached), len(self.targets) - 1)

    def leg_targets(self, physics) -> np.ndarray:
        """Trot until the arm's base is ``stop_distance`` from the wall, then stand
        (blending from the last trot targets to the standing pose over 0.3 s)."""
        t = self.episode_time(physics)
        if self._stopped_at is None and (
                scenes.GAP_WALL_X - physics.arm_base_position()[0] < self.stop_distance):
            self._stopped_at = (t, super().leg_targets(physics))
        if self._stopped_at is None:
            return super().leg_targets(physics)
        t_stop, last = self._stopped_at
        blend = min((t - t_stop) / 0.3, 1.0)
        standing = gait_lib.Standing().joint_targets(
            t, self.trunk_height_command(physics) + legs.SAG_COMPENSATION["stand"])
        return (1 - blend) * last + blend * standing

    def walking(self) -> bool:
        return self._stopped_at is None


def lesson4_heights(random, time_limit: float = LESSON4_TIME_LIMIT,
                    height_range=LESSON4_HEIGHT_RANGE) -> gait_lib.TrunkHeightSchedule:
    """Nominal height for the first sixth, ramp to a random height, hold, ramp back."""
    h0, h1 = quad.STANDING_TRUNK_HEIGHT, float(random.uniform(*height_range))
    knots = np.array([0.0, 1 / 6, 2 / 6, 4 / 6, 5 / 6]) * time_limit
    return gait_lib.TrunkHeightSchedule(tuple(knots), (h0, h0, h1, h1, h0))
