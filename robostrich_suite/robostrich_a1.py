"""Domain ``robostrich_a1``: the Robostrich arm on a walking A1-like quadruped (Sec. 4.2, 5.2).

Tasks:

* ``lesson1``-``lesson3``: the lessons of ``robostrich`` with the quadruped standing
  (pre-training);
* ``lesson4``: the lesson-2 reward while the quadruped trots, its trunk height
  changing over the episode (a random height held in the middle third);
* ``head_stabilize`` (Sec. 5.2.1, Fig. 9): while walking, keep the head at a constant
  height above the ground, level, and a constant distance ``P_d`` ahead of the trunk;
  the trunk height dips at 4-6 s and recovers at 8-10 s, as in Fig. 9A;
* ``narrow_gap`` (Sec. 5.2.2, Fig. 10): the quadruped walks up to a wall and stops;
  the head tracks six sub-targets in order, under the wall's overhang to the bottom of
  a narrow slot, up through it and to the final target on top.  The obstacle: a wall
  taller than the head can reach, standing on a horizontal shelf (0.50-0.53 m high)
  that reaches back from it and is pierced by a 7 cm slot; below the shelf it is open.
  The planar neck fits the slot; the head must go under the shelf and up through the
  slot.  The arm collides with all of it (its geoms carry the arm's contact bit).

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
``trunk_position`` (3: x, y walked since the episode start, height above ground),
``trunk_velocity`` (3, trunk frame), ``target_position`` (2), ``to_target`` (2),
``attitude_error``, ``head_attitude``, ``tendon_contraction`` (9), ``tendon_tension`` (9).
The action is the 9 tendon contractions; the legs follow the gait, not the policy.

Timing: control step 0.008 s (the paper's) = 4 physics steps of 0.002 s; the
open-loop trot with the arm mounted is stable at 2 ms (implicitfast integrator).
Each episode starts with the quadruped standing still after ``SETTLE_TIME`` of
physics, so the servos' sag under the robot's weight is not part of the episode.
The legs' joint targets come from :mod:`robostrich_suite.gait` (default: replay of
the shipped gait file ``data/a1_trot.csv``), written to the leg servos in
``before_step``; the commanded trunk height is raised by the servos' measured sag
(``SAG_COMPENSATION``) and a small steering loop keeps the walk on its start line
(``STEER_*``; ``steer=False`` gives the pure open-loop gait).

A fallen quadruped (trunk tilted past 60 deg) or a physics divergence ends the episode.

Run ``robostrich-walk`` (:mod:`robostrich_suite.walk`) to see the perturbation the arm gets.
"""
from __future__ import annotations

import collections
import functools
import math

import numpy as np
from dm_control import mjcf, mujoco
from dm_control.rl import control
from dm_control.utils import containers

from robostrich_suite import arm as arm_lib
from robostrich_suite import arm_physics, reach
from robostrich_suite import gait as gait_lib
from robostrich_suite import quadruped as quad
from robostrich_suite.conventions import CONTROL_TIMESTEP, PHYSICS_TIMESTEP
SETTLE_TIME = 0.2  # s of standing physics before each fresh episode
LESSON_TIME_LIMIT = 2.0  # s, lessons 1-3 (as in ``robostrich``)
LESSON4_TIME_LIMIT = 6.0  # s: stand-in, lowered/raised, back (one height change)
HEAD_STABILIZE_TIME_LIMIT = 12.0  # s (1500 steps, Fig. 9)
NARROW_GAP_STEPS_PER_TARGET = 150  # control steps = 1.2 s per sub-target
# The leg servos (kp 100) sag under the robot's weight: measured trunk height minus
# command, at 0.22-0.28 m, is -0.010 m standing and -0.019 m on average while trotting.
# The tasks command the legs that much higher so the trunk's height matches the command.
SAG_COMPENSATION = {"stand": 0.010, "walk": 0.019}  # m
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
ARM_PREFIX = f"{arm_lib.ARM_MODEL_NAME}/"
TRUNK = quad.TRUNK_BODY

# Where the arm's first joint (C18) sits relative to the trunk centre, and the
# height it has when the quadruped stands at its nominal trunk height.
MOUNT_OFFSET = np.array([quad.MOUNT_X, 0.0, quad.TRUNK_SIZE[2] / 2 + quad.ARM_BASE_CLEARANCE])
NOMINAL_MOUNT_HEIGHT = quad.STANDING_TRUNK_HEIGHT + MOUNT_OFFSET[2]
FRAME_MOUNT_HEIGHT = arm_lib.FRAME_HEIGHT + arm_lib.ArmSpec.from_table1().anchor_depth  # build_frame_arm's C18

# head_stabilize (Sec. 5.2.1): P_d and the head height above ground.
# A level-head pose of the actuated workspace (frame pose (0.31, 0.27) on the trunk).
HEAD_STABILIZE_DISTANCE = 0.40  # m ahead of the trunk centre
HEAD_STABILIZE_HEIGHT = 0.56  # m above the ground
# Fig. 9A: trunk height lowered during steps 500-750 and raised back during 1000-1250.
HEAD_STABILIZE_HEIGHTS = gait_lib.TrunkHeightSchedule(
    times=(0.0, 4.0, 6.0, 8.0, 10.0),
    heights=(quad.STANDING_TRUNK_HEIGHT, quad.STANDING_TRUNK_HEIGHT, 0.22, 0.22,
             quad.STANDING_TRUNK_HEIGHT))
LESSON4_HEIGHT_RANGE = (0.21, 0.30)  # m, random trunk height of the middle of an episode

# narrow_gap scene (Fig. 10), x measured from the quadruped's start (trunk centre).
GAP_WALL_X = 1.0  # m, near face of the wall
GAP_WALL_TOP = 1.3  # m, the wall rises above anything the head reaches
GAP_SHELF_BOTTOM = 0.50  # m, underside of the overhang (a shelf behind the wall)
GAP_SHELF_THICKNESS = 0.03  # m
GAP_SLOT_X = 0.20  # m, slot centre behind the wall's near face
GAP_SLOT_WIDTH = 0.07  # m, along x: the neck is planar, so the slot is narrow in x only
GAP_SHELF_DEPTH = 0.45  # m, shelf extent behind the wall's near face
GAP_STOP_DISTANCE = 0.16  # m, the quadruped stops when the arm's base is this close to the wall
WALL_THICKNESS = 0.04  # m
# The six sub-targets (x from the wall's near face, height above ground), Fig. 10.
# Heights stay within the level-head workspace: 0.1-0.24 m above the arm's base
# (0.37 m above ground when standing) and 0.15-0.45 m ahead of it.
GAP_TARGETS = np.array([
    [-0.06, 0.45],  # 1: down in front of the wall
    [0.08, 0.45],  # 2: under the overhang
    [GAP_SLOT_X, 0.45],  # 3: the bottom of the gap
    [GAP_SLOT_X, GAP_SHELF_BOTTOM + GAP_SHELF_THICKNESS / 2],  # 4: in the gap
    [GAP_SLOT_X, GAP_SHELF_BOTTOM + GAP_SHELF_THICKNESS + 0.03],  # 5: just through it
    [GAP_SLOT_X, GAP_SHELF_BOTTOM + GAP_SHELF_THICKNESS + 0.07],  # 6: the top target
])

SUITE = containers.TaggedTasks()


# --- model ---------------------------------------------------------------------------
def build_model(arm_spec=None, tendon_layout=None, scene: str = "flat") -> mjcf.RootElement:
    """Quadruped (free joint) + arm on the trunk + floor; ``scene`` "flat" or "narrow_gap".

    Built in the order ``dm_control.mjcf`` allows: the arm is attached to the trunk's
    mount site of a quadruped without a free joint, and only then is the free joint
    added.  The quadruped is the root model and the arena (floor, light, camera,
    obstacles) is added into it, rather than attaching the quadruped to an arena
    through a frame: that way the arm keeps its ``arm/`` names, which the shared arm
    accessors (``ArmPhysicsMixin``) and domain randomisation look up, instead of
    becoming ``a1/arm/...``.
    """
    if scene not in ("flat", "narrow_gap"):
        raise ValueError(f"unknown scene {scene!r}; use 'flat' or 'narrow_gap'")
    model = quad.build_quadruped()
    model.model = "robostrich_a1"
    model.find("site", quad.MOUNT_SITE).attach(arm_lib.build_arm(arm_spec, tendon_layout))
    trunk = model.find("body", quad.TRUNK_BODY)
    trunk.pos = [0, 0, quad.standing_hip_height()]
    trunk.insert("freejoint", 0, name="root")

    model.option.timestep = PHYSICS_TIMESTEP
    model.option.integrator = "implicitfast"
    model.visual.headlight.set_attributes(ambient=[0.4, 0.4, 0.4], diffuse=[0.6, 0.6, 0.6])
    model.asset.add("texture", name="grid", type="2d", builtin="checker", width=256, height=256,
                    rgb1=[0.2, 0.3, 0.4], rgb2=[0.25, 0.35, 0.45])
    model.asset.add("material", name="grid", texture="grid", texrepeat=[20, 20], reflectance=0.1)
    model.worldbody.insert("light", 0, pos=[0, -1, 3], dir=[0, 0.3, -1])
    model.worldbody.insert("geom", 1, name="floor", type="plane", size=[10, 10, 0.1],
                           material="grid", friction=[1.0, 0.005, 0.0001])
    model.worldbody.add("camera", name="side", pos=[0.3, -2.0, 0.6], xyaxes=[1, 0, 0, 0, 0.2, 1],
                        mode="trackcom")
    if scene == "narrow_gap":
        _add_narrow_gap(model)
    _add_standing_keyframe(model)
    return model


def _add_standing_keyframe(arena: mjcf.RootElement) -> None:
    """Keyframe ``stand``: the standing pose with its servo targets, for plain MuJoCo users
    of the exported XML (at ``qpos0`` the knees are outside their range)."""
    physics = Physics.from_xml_string(arena.to_xml_string())
    physics.place_standing()
    arena.keyframe.add("key", name="stand", qpos=np.round(physics.data.qpos, 6),
                       ctrl=np.round(physics.data.ctrl, 6))


def _add_narrow_gap(arena: mjcf.RootElement) -> None:
    """A wall taller than the head reaches, with a shelf behind it pierced by a narrow slot.

    Every obstacle geom has the arm's collision bit in ``conaffinity``: the arm touches it.
    """
    contact = dict(contype=1, conaffinity=1 | arm_lib.COLLISION_TYPE, rgba=[0.7, 0.5, 0.3, 1])
    wall_bottom = GAP_SHELF_BOTTOM + GAP_SHELF_THICKNESS
    x0, half_y = GAP_WALL_X, 0.6
    arena.worldbody.add("geom", name="gap_wall", type="box",
                        size=[WALL_THICKNESS / 2, half_y, (GAP_WALL_TOP - wall_bottom) / 2],
                        pos=[x0 - WALL_THICKNESS / 2, 0, (GAP_WALL_TOP + wall_bottom) / 2],
                        **contact)
    z = GAP_SHELF_BOTTOM + GAP_SHELF_THICKNESS / 2
    slot_near = GAP_SLOT_X - GAP_SLOT_WIDTH / 2
    slot_far = GAP_SLOT_X + GAP_SLOT_WIDTH / 2
    for name, start, end in (("gap_shelf_near", -WALL_THICKNESS, slot_near),
                             ("gap_shelf_far", slot_far, GAP_SHELF_DEPTH)):
        arena.worldbody.add("geom", name=name, type="box",
                            size=[(end - start) / 2, half_y, GAP_SHELF_THICKNESS / 2],
                            pos=[x0 + (start + end) / 2, 0, z], **contact)
    for side in (-1, 1):  # legs holding the shelf up, clear of the robot's path
        arena.worldbody.add("geom", name=f"gap_post_{'left' if side > 0 else 'right'}",
                            type="box", size=[0.02, 0.02, GAP_SHELF_BOTTOM / 2],
                            pos=[x0 + GAP_SHELF_DEPTH - 0.02, side * (half_y - 0.02),
                                 GAP_SHELF_BOTTOM / 2], **contact)


@functools.lru_cache(maxsize=4)
def _default_xml(scene: str) -> str:
    return build_model(scene=scene).to_xml_string()


def get_model_and_assets(arm_spec=None, tendon_layout=None, scene: str = "flat"):
    """The MJCF of the arm on the quadruped on a floor (no assets); the default model is
    what ``xml/robostrich_a1.xml`` holds."""
    if arm_spec is None and tendon_layout is None:
        return _default_xml(scene), {}
    return build_model(arm_spec, tendon_layout, scene).to_xml_string(), {}


# --- physics -------------------------------------------------------------------------
class Physics(arm_physics.ArmPhysicsMixin, mujoco.Physics):
    """The arm's accessors (``ArmPhysicsMixin``) plus the quadruped's and the trunk frame."""

    def _robot(self):
        cache = self.__dict__.get("_robot_cache")
        if cache is None or cache["data"] is not self._data:  # a reload makes new data
            model = self.model
            legs = list(quad.JOINT_NAMES)
            cache = dict(
                data=self._data,
                trunk=model.name2id(TRUNK, "body"),
                leg_actuators=np.array([model.name2id(n, "actuator") for n in legs]),
                leg_qpos=np.array([model.jnt_qposadr[model.name2id(n, "joint")] for n in legs]),
                # The arm's first (caudal) joint: the generator adds the chain caudal first.
                arm_base=int(model.jnt_bodyid[arm_lib.arm_ids(model, "joint")[0]]))
            self.__dict__["_robot_cache"] = cache
        return cache

    # Arm head.
    def head_attitude(self) -> float:
        """Head attitude (deg) in the trunk's heading plane: 0 up, 90 level, 180 down."""
        xmat = self.data.xmat[self._arm_indices().head_body]  # head body; row-major: axis z = (2, 5, 8)
        hx, hy = self.heading()
        return float(arm_lib.continuous_attitude_deg(
            math.degrees(math.atan2(xmat[2] * hx + xmat[5] * hy, xmat[8])),
            self.data.qpos[self._arm_indices().qpos]))

    # Quadruped.
    def trunk_position(self) -> np.ndarray:
        """Trunk centre (x, y, z), world frame."""
        return self.data.xpos[self._robot()["trunk"]].copy()

    def trunk_velocity(self) -> np.ndarray:
        """Trunk linear velocity, world frame (the free joint's linear velocity)."""
        return self.data.qvel[:3].copy()

    def trunk_height(self) -> float:
        return float(self.data.xpos[self._robot()["trunk"], 2])

    def trunk_uprightness(self) -> float:
        """z component of the trunk's up axis: 1 upright, 0 on its side."""
        return float(self.data.xmat[self._robot()["trunk"]][8])

    def heading(self) -> np.ndarray:
        """Unit (x, y) of the trunk's forward axis projected on the ground."""
        xmat = self.data.xmat[self._robot()["trunk"]]
        fx, fy = float(xmat[0]), float(xmat[3])
        norm = math.hypot(fx, fy)
        return (fx / norm, fy / norm) if norm > 1e-9 else (1.0, 0.0)

    def to_trunk_frame(self, point, velocity: bool = False) -> np.ndarray:
        """World point (or velocity) -> (forward, left, up) in the trunk frame (module doc)."""
        hx, hy = self.heading()
        x, y, z = (float(c) for c in point)
        if not velocity:
            trunk = self.data.xpos[self._robot()["trunk"]]
            x, y = x - trunk[0], y - trunk[1]
        return np.array([hx * x + hy * y, -hy * x + hx * y, z])

    def from_trunk_frame(self, forward: float, up: float) -> np.ndarray:
        """(forward, up) in the trunk frame -> world point in the trunk's vertical plane."""
        hx, hy = self.heading()
        x, y, _ = self.trunk_position()
        return np.array([x + forward * hx, y + forward * hy, up])

    def arm_base_position(self) -> np.ndarray:
        """World position of the arm's first joint (C18) on the trunk."""
        return self.data.xpos[self._robot()["arm_base"]].copy()

    def leg_joint_angles(self) -> np.ndarray:
        return self.data.qpos[self._robot()["leg_qpos"]].copy()

    def set_leg_targets(self, targets) -> None:
        self.data.ctrl[self._robot()["leg_actuators"]] = targets

    def place_standing(self, trunk_xy=(0.0, 0.0), trunk_height=quad.STANDING_TRUNK_HEIGHT):
        """Put the quadruped in its standing pose, feet on the ground, arm straight, at rest."""
        targets = gait_lib.Standing().joint_targets(0.0, trunk_height + SAG_COMPENSATION["stand"])
        _, foot_z = gait_lib.leg_fk(targets[1], targets[2])
        self.data.qpos[:] = 0.0
        self.data.qpos[:3] = [trunk_xy[0], trunk_xy[1], -foot_z + quad.FOOT_RADIUS]
        self.data.qpos[3:7] = [1, 0, 0, 0]
        self.data.qpos[self._robot()["leg_qpos"]] = targets
        self.data.qvel[:] = 0.0
        if self.data.act.size:
            self.data.act[:] = 0.0
        self.set_leg_targets(targets)
        self.set_arm_control(0.0)


# --- tasks ---------------------------------------------------------------------------
def default_target_pool() -> np.ndarray:
    """``robostrich``'s level-head training targets, in the trunk frame (module doc)."""
    from robostrich_suite import targets
    return frame_to_trunk(targets.training_targets())


def frame_to_trunk(frame_targets) -> np.ndarray:
    """(x, z) head positions of the arm on its frame -> (forward, up) on the standing A1."""
    frame_targets = reach.as_targets(frame_targets, "targets")
    return frame_targets + [MOUNT_OFFSET[0], NOMINAL_MOUNT_HEIGHT - FRAME_MOUNT_HEIGHT]


_LEFT_SIGN = np.array([1.0 if leg.endswith("L") else -1.0 for leg in quad.LEGS])


class _QuadrupedTaskMixin:
    """What every ``robostrich_a1`` task shares: legs driven by a gait, tendon-only
    actions, Table 2 observations in the trunk frame, episodes starting from standing.

    Args:
      legs: ``"stand"`` or ``"walk"``.
      gait: for walking, a :class:`gait.TrotGait`, a :class:`gait.GaitReplay` or a gait
        file path (or any object with ``joint_targets(t, trunk_height, stride_scale)``);
        default: replay of the shipped file.
      trunk_heights: a :class:`gait.TrunkHeightSchedule`, a callable ``random ->
        schedule`` (a new schedule each episode), or ``None`` (constant nominal height).
      steer: keep the walk on the start line (see ``STEER_*``); off = the pure open-loop gait.
    """

    def __init__(self, *, legs: str = "stand", gait=None, trunk_heights=None, steer: bool = True,
                 **kwargs):
        if legs not in ("stand", "walk"):
            raise ValueError(f"unknown legs {legs!r}; use 'stand' or 'walk'")
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
        self._trunk_heights = trunk_heights
        self.height_schedule = gait_lib.TrunkHeightSchedule()
        self._episode_start_time = 0.0
        self._episode_start_xy = np.zeros(2)
        super().__init__(**kwargs)

    # Episode.
    def initialize_episode(self, physics):
        schedule = self._trunk_heights
        if callable(schedule) and not isinstance(schedule, gait_lib.TrunkHeightSchedule):
            schedule = schedule(self.random)
        self.height_schedule = schedule or gait_lib.TrunkHeightSchedule()
        continuing = self.initial_state == "continue" and self._last_state is not None
        if not continuing:
            physics.place_standing(trunk_height=float(self.height_schedule(0.0)))
            physics.forward()
            physics.step(int(round(SETTLE_TIME / physics.model.opt.timestep)))
        super().initialize_episode(physics)
        self._episode_start_time = physics.data.time
        self._episode_start_xy = physics.trunk_position()[:2]
        self.update_target(physics)

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
        height = float(self.height_schedule(t)) + SAG_COMPENSATION[self.legs]
        scale = self.stride_scale(physics) if self.legs == "walk" and self.steer else None
        return self.gait.joint_targets(t, height, scale)

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

    def get_observation(self, physics):
        """Table 2 (head, joints, trunk), then the goal and tendon state (module doc)."""
        shared = super().get_observation(physics)
        obs = collections.OrderedDict()
        obs["head_position"] = physics.to_trunk_frame(physics.head_position())
        obs["head_velocity"] = physics.to_trunk_frame(physics.head_velocity(), velocity=True)
        obs["joint_angles"] = shared["joint_angles"]
        trunk = physics.trunk_position()
        obs["trunk_position"] = np.array([*(trunk[:2] - self._episode_start_xy), trunk[2]])
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


class NarrowGap(_QuadrupedTaskMixin, reach.Track):
    """Walk up to the wall, stop, track ``GAP_TARGETS`` (fixed in the world) in order."""

    def __init__(self, stop_distance: float = GAP_STOP_DISTANCE, **kwargs):
        kwargs.setdefault("targets", GAP_TARGETS)
        kwargs.setdefault("steps_per_target", NARROW_GAP_STEPS_PER_TARGET)
        super().__init__(legs="walk", **kwargs)
        self.stop_distance = float(stop_distance)
        self.world_targets = np.asarray(self.targets, float) + [GAP_WALL_X, 0.0]
        self._stopped_at = None

    def initialize_episode(self, physics):
        self._stopped_at = None
        super().initialize_episode(physics)

    def update_target(self, physics) -> None:
        x, z = self.world_targets[self.target_index]
        self.target_position = physics.to_trunk_frame([x, 0.0, z])[[0, 2]]

    def leg_targets(self, physics) -> np.ndarray:
        """Trot until the arm's base is ``stop_distance`` from the wall, then stand
        (blending from the last trot targets to the standing pose over 0.3 s)."""
        t = self.episode_time(physics)
        if self._stopped_at is None and (
                GAP_WALL_X - physics.arm_base_position()[0] < self.stop_distance):
            self._stopped_at = (t, super().leg_targets(physics))
        if self._stopped_at is None:
            return super().leg_targets(physics)
        t_stop, last = self._stopped_at
        blend = min((t - t_stop) / 0.3, 1.0)
        standing = gait_lib.Standing().joint_targets(
            t, self.trunk_height_command(physics) + SAG_COMPENSATION["stand"])
        return (1 - blend) * last + blend * standing

    def walking(self) -> bool:
        return self._stopped_at is None


# --- environments --------------------------------------------------------------------
def _environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs,
                 scene="flat"):
    time_limit = reach.check_time_limit(time_limit)
    physics = Physics.from_xml_string(*get_model_and_assets(arm_spec, tendon_layout, scene))
    environment_kwargs = dict(environment_kwargs or {})
    environment_kwargs.setdefault("control_timestep", CONTROL_TIMESTEP)
    return control.Environment(physics, task, time_limit=time_limit, **environment_kwargs)


def lesson4_heights(random, time_limit: float = LESSON4_TIME_LIMIT,
                    height_range=LESSON4_HEIGHT_RANGE) -> gait_lib.TrunkHeightSchedule:
    """Nominal height for the first sixth, ramp to a random height, hold, ramp back."""
    h0, h1 = quad.STANDING_TRUNK_HEIGHT, float(random.uniform(*height_range))
    knots = np.array([0.0, 1 / 6, 2 / 6, 4 / 6, 5 / 6]) * time_limit
    return gait_lib.TrunkHeightSchedule(tuple(knots), (h0, h0, h1, h1, h0))


def _lesson(reward, initial_state, time_limit, random, environment_kwargs, arm_spec,
            tendon_layout, task_kwargs, legs="stand", trunk_heights=None):
    if "target_pool" not in task_kwargs:
        from robostrich_suite import targets  # here, not at import: see robostrich._warn_if_other_arm
        targets.warn_if_other_arm(arm_spec, tendon_layout)
    task = QuadrupedReach(reward=reward, initial_state=initial_state, random=random, legs=legs,
                          trunk_heights=trunk_heights, **task_kwargs)
    return _environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs)


@SUITE.add("curriculum")
def lesson1(time_limit=LESSON_TIME_LIMIT, random=None, environment_kwargs=None, arm_spec=None,
            tendon_layout=None, **task_kwargs):
    """Lesson 1 (eq. 9) with the quadruped standing."""
    return _lesson("lesson1", "fixed", time_limit, random, environment_kwargs, arm_spec,
                   tendon_layout, task_kwargs)


@SUITE.add("curriculum")
def lesson2(time_limit=LESSON_TIME_LIMIT, random=None, environment_kwargs=None, arm_spec=None,
            tendon_layout=None, **task_kwargs):
    """Lesson 2 (eq. 10) with the quadruped standing."""
    return _lesson("lesson2", "fixed", time_limit, random, environment_kwargs, arm_spec,
                   tendon_layout, task_kwargs)


@SUITE.add("curriculum")
def lesson3(time_limit=LESSON_TIME_LIMIT, random=None, environment_kwargs=None, arm_spec=None,
            tendon_layout=None, **task_kwargs):
    """Lesson 3 (eq. 10, episodes continue) with the quadruped standing."""
    return _lesson("lesson2", "continue", time_limit, random, environment_kwargs, arm_spec,
                   tendon_layout, task_kwargs)


@SUITE.add("curriculum")
def lesson4(time_limit=LESSON4_TIME_LIMIT, random=None, environment_kwargs=None, arm_spec=None,
            tendon_layout=None, height_range=LESSON4_HEIGHT_RANGE, **task_kwargs):
    """Lesson 4: eq. 10 while the quadruped trots, trunk height changing (random per episode)."""
    heights = functools.partial(lesson4_heights, time_limit=time_limit, height_range=height_range)
    return _lesson("lesson2", "fixed", time_limit, random, environment_kwargs, arm_spec,
                   tendon_layout, task_kwargs, legs="walk", trunk_heights=heights)


@SUITE.add("evaluation")
def head_stabilize(time_limit=HEAD_STABILIZE_TIME_LIMIT, random=None, environment_kwargs=None,
                   arm_spec=None, tendon_layout=None, distance=HEAD_STABILIZE_DISTANCE,
                   height=HEAD_STABILIZE_HEIGHT, trunk_heights=HEAD_STABILIZE_HEIGHTS,
                   **task_kwargs):
    """Sec. 5.2.1: hold the head ``height`` above ground, level, ``distance`` (P_d) ahead of
    the trunk, while walking with the trunk height of Fig. 9A."""
    task = QuadrupedReach(reward="lesson2", initial_state="fixed", random=random, legs="walk",
                          trunk_heights=trunk_heights, target_pool=[[distance, height]],
                          **task_kwargs)
    return _environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs)


@SUITE.add("evaluation")
def narrow_gap(time_limit=None, random=None, environment_kwargs=None, arm_spec=None,
               tendon_layout=None, steps_per_target=NARROW_GAP_STEPS_PER_TARGET, **task_kwargs):
    """Sec. 5.2.2: walk to the wall, then the head tracks the six sub-targets of Fig. 10."""
    task = NarrowGap(steps_per_target=steps_per_target, random=random, reward="lesson2",
                     **task_kwargs)
    if time_limit is None:
        time_limit = len(task.targets) * steps_per_target * CONTROL_TIMESTEP
    return _environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs,
                        scene="narrow_gap")
