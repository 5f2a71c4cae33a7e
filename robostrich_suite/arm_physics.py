"""Named accessors for an attached Robostrich arm, shared by every domain.

Mixed into each domain's ``Physics`` so tasks read the head, joints and
tendons by meaning rather than by index.  Joint angles come in Table 1 order
(atlas first, C18 last); tendons in actuator (= action) order.
"""
from __future__ import annotations

import logging

import mujoco as mujoco_lib
import numpy as np
from dm_control.rl import control

from robostrich_suite import arm as arm_lib

_log = logging.getLogger(__name__)


class _MujocoWarningCapture(logging.Filter):
    """Holds back MuJoCo's own warning lines (dm_control sends them to the ``absl``
    logger) while an arm steps, so that a divergence is reported in one line that
    quotes them, instead of one line per MuJoCo warning plus ours."""

    def __init__(self):
        super().__init__()
        self.active = False
        self.messages: list[str] = []

    def filter(self, record):
        if not self.active:
            return True
        self.messages.append(record.getMessage())
        return False


_MUJOCO_WARNINGS = _MujocoWarningCapture()
logging.getLogger("absl").addFilter(_MUJOCO_WARNINGS)


class ArmPhysicsMixin:
    """Accessors for the arm's head, joints and tendons, plus divergence capture."""

    divergence: str | None = None
    # Episodes started and episodes that diverged, for the one log line per divergence.
    episodes_started: int = 0
    episodes_diverged: int = 0

    # Indices are looked up once per model; the model never changes under a Physics.
    def _arm_indices(self) -> arm_lib.ArmIndices:
        cache = self.__dict__.get("_arm_index_cache")
        if cache is None or cache[0] is not self.model.ptr:
            cache = (self.model.ptr, arm_lib.arm_indices(self.model))
            self.__dict__["_arm_index_cache"] = cache
        return cache[1]

    def arm_joint_names(self) -> list[str]:
        return [self.model.id2name(int(j), "joint") for j in self._arm_indices().joints]

    def tendon_names(self) -> list[str]:
        return [self.model.id2name(int(i), "actuator") for i in self._arm_indices().actuators]

    def head_position(self) -> np.ndarray:
        """Head site position (x, y, z) in metres, world frame."""
        return self.data.site_xpos[self._arm_indices().head_site].copy()

    def head_velocity(self) -> np.ndarray:
        """Head site linear velocity (x, y, z) in m/s, world frame."""
        adr = self._arm_indices().head_velocity
        return self.data.sensordata[adr:adr + 3].copy()

    def head_attitude(self) -> float:
        """Head attitude in degrees: 90 = head parallel to the ground (paper Fig. 2B); continuous
        past 180 (no wrap), see :func:`arm.continuous_attitude_deg`."""
        xmat = self.data.xmat[self._arm_indices().head_body]  # row-major 3x3; column 2 = head axis
        return float(arm_lib.continuous_attitude_deg(np.degrees(np.arctan2(xmat[2], xmat[8])),
                                                     self.data.qpos[self._arm_indices().qpos]))

    def joint_angles(self) -> np.ndarray:
        """The 18 joint angles (rad), atlas first; positive = ventral flexion."""
        return self.data.qpos[self._arm_indices().qpos].copy()

    def joint_velocities(self) -> np.ndarray:
        return self.data.qvel[self._arm_indices().dofs].copy()

    def tendon_lengths(self) -> np.ndarray:
        """Current length of each actuated tendon (m), in action order."""
        return self.data.ten_length[self._arm_indices().tendons].copy()

    def tendon_rest_lengths(self) -> np.ndarray:
        """Length of each tendon in the straight pose (m): the servo's zero contraction."""
        return self._arm_indices().rest_lengths

    def tendon_contractions(self) -> np.ndarray:
        """How much each tendon is shorter than at rest (m)."""
        return self.tendon_rest_lengths() - self.tendon_lengths()

    def tendon_forces(self) -> np.ndarray:
        """Pull in each tendon (N, >= 0), in action order."""
        return -self.data.actuator_force[self._arm_indices().actuators].copy()

    def tendon_max_forces(self) -> np.ndarray:
        """Largest pull of each tendon's actuator (N, > 0), in action order."""
        return -self.model.actuator_forcerange[self._arm_indices().actuators, 0]

    def arm_control(self) -> np.ndarray:
        return self.data.ctrl[self._arm_indices().actuators].copy()

    def arm_control_range(self) -> np.ndarray:
        """(9, 2) low/high tendon contractions (m): the action spec's bounds."""
        return self.model.actuator_ctrlrange[self._arm_indices().actuators]

    def set_arm_control(self, action) -> None:
        """Write tendon contractions to the arm's actuators only (a robot may have others)."""
        self.data.ctrl[self._arm_indices().actuators] = action

    def step(self, nstep: int = 1) -> None:
        """Step, but turn a divergence into a flag the task ends the episode on.

        A divergence ends the episode, so it is logged once per episode: one line
        with MuJoCo's own warnings and how many episodes have diverged so far."""
        if self.divergence is not None:
            return
        _MUJOCO_WARNINGS.active, _MUJOCO_WARNINGS.messages = True, []
        try:
            super().step(nstep)
        except control.PhysicsError as error:
            self.divergence = str(error)
        else:
            if not (np.all(np.isfinite(self.data.qpos)) and np.all(np.isfinite(self.data.qvel))):
                self.divergence = "non-finite joint state"
        finally:
            _MUJOCO_WARNINGS.active = False
        if self.divergence is not None:
            self._log_divergence(_MUJOCO_WARNINGS.messages)

    def _log_divergence(self, mujoco_messages: list[str]) -> None:
        self.episodes_diverged += 1
        episodes = max(self.episodes_started, 1)
        detail = " ".join(mujoco_messages) or self.divergence
        _log.warning("physics diverged in episode %d, ending it (%d of %d episodes diverged "
                     "so far): %s", episodes, self.episodes_diverged, episodes, detail)

    def __setstate__(self, state):
        super().__setstate__(state)
        # dm_control's Euler step ends each step with mj_step1 and begins the next with
        # mj_step2, which reuses what mj_step1 computed (constraint rows among it). A
        # pickled MjData keeps the state but not those, so recompute them: an unpickled
        # environment (a resumed training run) then continues bit-exactly.
        mujoco_lib.mj_step1(self.model.ptr, self.data.ptr)

    def reset(self, keyframe_id=None):
        self.divergence = None
        self.episodes_started += 1
        return super().reset(keyframe_id)
