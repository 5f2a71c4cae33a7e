"""The quadruped's accessors beside the arm's: the trunk, the legs and the trunk frame, mixed
into the ``Physics`` of every domain with the arm on the A1-like quadruped."""
import math

import numpy as np

from robostrich_suite import physics as physics_lib
from robostrich_suite.model import legs
from robostrich_suite.model import quadruped as quad


class QuadrupedPhysicsMixin(physics_lib.ArmPhysicsMixin):
    """The arm's accessors (``ArmPhysicsMixin``) plus the quadruped's and the trunk frame:
    origin on the ground under the trunk centre, x along the trunk's heading (projected on
    the ground), y to its left, z up (see :mod:`robostrich_suite.tasks.quadruped_tasks`)."""

    def _robot(self):
        cache = self.__dict__.get("_robot_cache")
        if cache is None or cache["data"] is not self._data:  # a reload makes new data
            model = self.model
            legs = list(quad.JOINT_NAMES)
            cache = dict(
                data=self._data,
                trunk=model.name2id(quad.TRUNK_BODY, "body"),
                leg_actuators=np.array([model.name2id(n, "actuator") for n in legs]),
                leg_qpos=np.array([model.jnt_qposadr[model.name2id(n, "joint")] for n in legs]),
                # The arm's first (caudal) joint: the generator adds the chain caudal first.
                arm_base=int(model.jnt_bodyid[physics_lib.arm_ids(model, "joint")[0]]))
            self.__dict__["_robot_cache"] = cache
        return cache

    # Arm head.
    def head_attitude(self) -> float:
        """Head attitude (deg) in the trunk's heading plane: 0 up, 90 level, 180 down."""
        xmat, joint_angles = self._head_frame_and_joints()  # row-major: axis z = (2, 5, 8)
        hx, hy = self.heading()
        return physics_lib.one_pose_attitude_deg(math.atan2(xmat[2] * hx + xmat[5] * hy, xmat[8]), joint_angles)

    # Quadruped.
    def trunk_position(self) -> np.ndarray:
        """Trunk centre (x, y, z), world frame."""
        return self._raw_data.xpos[self._robot()["trunk"]].copy()

    def trunk_velocity(self) -> np.ndarray:
        """Trunk linear velocity, world frame (the free joint's linear velocity)."""
        return self._raw_data.qvel[:3].copy()

    def trunk_height(self) -> float:
        return float(self._raw_data.xpos[self._robot()["trunk"], 2])

    def trunk_uprightness(self) -> float:
        """z component of the trunk's up axis: 1 upright, 0 on its side."""
        return float(self._raw_data.xmat[self._robot()["trunk"]][8])

    def heading(self) -> np.ndarray:
        """Unit (x, y) of the trunk's forward axis projected on the ground."""
        xmat = self._raw_data.xmat[self._robot()["trunk"]]
        fx, fy = float(xmat[0]), float(xmat[3])
        norm = math.hypot(fx, fy)
        return (fx / norm, fy / norm) if norm > 1e-9 else (1.0, 0.0)

    def to_trunk_frame(self, point, velocity: bool = False) -> np.ndarray:
        """World point (or velocity) -> (forward, left, up) in the trunk frame (class doc)."""
        hx, hy = self.heading()
        x, y, z = (float(c) for c in point)
        if not velocity:
            trunk = self._raw_data.xpos[self._robot()["trunk"]]
            x, y = x - trunk[0], y - trunk[1]
        return np.array([hx * x + hy * y, -hy * x + hx * y, z])

    def from_trunk_frame(self, forward: float, up: float) -> np.ndarray:
        """(forward, up) in the trunk frame -> world point in the trunk's vertical plane."""
        hx, hy = self.heading()
        x, y, _ = self.trunk_position()
        return np.array([x + forward * hx, y + forward * hy, up])

    def arm_base_position(self) -> np.ndarray:
        """World position of the arm's first joint (C18) on the trunk."""
        return self._raw_data.xpos[self._robot()["arm_base"]].copy()

    def set_leg_targets(self, targets) -> None:
        self._raw_data.ctrl[self._robot()["leg_actuators"]] = targets

    def place_standing(self, trunk_xy=(0.0, 0.0), trunk_height=quad.STANDING_TRUNK_HEIGHT):
        """Put the quadruped in its standing pose, feet on the ground, arm straight, at rest."""
        targets = legs.standing_joint_targets(trunk_height + legs.SAG_COMPENSATION["stand"])
        _, foot_z = legs.leg_fk(targets[1], targets[2])
        self._raw_data.qpos[:] = 0.0
        self._raw_data.qpos[:3] = [trunk_xy[0], trunk_xy[1], -foot_z + quad.FOOT_RADIUS]
        self._raw_data.qpos[3:7] = [1, 0, 0, 0]
        self._raw_data.qpos[self._robot()["leg_qpos"]] = targets
        self._raw_data.qvel[:] = 0.0
        if self._raw_data.act.size:
            self._raw_data.act[:] = 0.0
        self.set_leg_targets(targets)
        self.set_arm_control(0.0)
