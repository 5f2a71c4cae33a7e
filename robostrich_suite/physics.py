"""The one accessor layer: reading the arm and the quadruped in a compiled model.

Finding the arm in a model (:func:`arm_indices`), which tendon is on which side
(:func:`tendon_sides`) and the head's attitude are stated here once; tasks and
studies alike read them from here.  :class:`ArmPhysicsMixin` is mixed into each
domain's ``Physics`` so tasks read the head, joints and tendons by meaning rather
than by index; robostrich_suite/quadruped_physics.py adds the quadruped's trunk, legs
and the trunk frame.  Joint angles come in Table 1 order (atlas first, C18 last);
tendons in actuator (= action) order.
"""
from __future__ import annotations

import logging
import math
from typing import NamedTuple

import mujoco as mujoco_lib
import numpy as np
from dm_control.mujoco import engine
from dm_control.rl import control

from robostrich_suite.model import arm as arm_lib

_log = logging.getLogger(__name__)
# dm_control's message for an invalid state, so both step paths report it alike.
_INVALID_STATE = engine._INVALID_PHYSICS_STATE


_COUNTS = {"body": "nbody", "joint": "njnt", "actuator": "nu", "tendon": "ntendon",
           "site": "nsite", "geom": "ngeom"}


def arm_ids(model, kind: str) -> np.ndarray:
    """Ids of the attached arm's elements of ``kind`` ("body", "joint", "actuator", ...) in
    model order: the arm is whatever is named under its ``arm.ARM_MODEL_NAME/`` prefix."""
    prefix = arm_lib.ARM_MODEL_NAME + "/"
    return np.array([i for i in range(getattr(model, _COUNTS[kind]))
                     if (model.id2name(i, kind) or "").startswith(prefix)], dtype=int)


class ArmIndices(NamedTuple):
    """Where the attached arm sits in a compiled model (see :func:`arm_indices`)."""
    joints: np.ndarray  # hinge joint ids, Table 1 order (atlas first)
    qpos: np.ndarray  # their qpos addresses
    dofs: np.ndarray  # their dof addresses
    actuators: np.ndarray  # tendon actuator ids, in action order
    tendons: np.ndarray  # each actuator's tendon id
    head_site: int
    head_body: int
    head_velocity: int  # sensordata address of the head's linear velocity
    servo_gain: np.ndarray  # kp of each tendon servo
    servo_bias: np.ndarray  # kp * rest length of each tendon servo
    # Length of each tendon in the straight pose (m): the servo's zero contraction,
    # (kp * rest) / kp, fixed at model creation (randomisation scales kp and bias together).
    rest_lengths: np.ndarray
    # ``qpos``, ``actuators`` and ``tendons`` as slices where the ids are evenly spaced (the
    # frame arm's and the quadruped's are; :func:`as_slice`): the per-step accessors read
    # through these.
    qpos_select: slice | np.ndarray
    actuator_select: slice | np.ndarray
    tendon_select: slice | np.ndarray
    rk4: bool  # the model integrates with RK4 (dm_control's step then skips mj_step2)


class ArmViews(NamedTuple):
    """Views into a compiled model and its data that the per-step accessors read (built once per
    model by ``ArmPhysicsMixin``, where the arm's joints, tendons and actuators each lie evenly
    spaced): MuJoCo writes every step into the same buffers, so a view always shows the live
    value, and an edit of the model's ranges shows through too.  Each read then skips the
    bindings' property lookup and numpy's indexing, about half a microsecond per accessor."""
    control_low: np.ndarray  # m, the action spec's minimum
    control_high: np.ndarray  # m, its maximum
    pull_limit: np.ndarray  # actuator_forcerange's lower bound: minus the largest pull (N)
    head_position: np.ndarray  # (3,) head site, world frame
    head_frame: np.ndarray  # (9,) head body's rotation matrix, row-major
    head_velocity: np.ndarray  # (3,) head velocity sensor
    joint_angles: np.ndarray  # (18,) qpos, Table 1 order
    tendon_lengths: np.ndarray  # actuated tendons' lengths, action order
    tendon_forces: np.ndarray  # actuator forces (negative: a pull), action order
    controls: np.ndarray  # the arm's ctrl entries, action order


def as_slice(ids) -> slice | np.ndarray:
    """``ids`` (non-negative) as a slice that reads the same elements in the same order
    where they are evenly spaced, else ``ids`` as an array: a slice reads a view without
    numpy's fancy-indexing cost, which the per-step paths pay for every read."""
    ids = np.asarray(ids, dtype=int)
    if len(ids) < 2 or ids[1] == ids[0] or np.any(np.diff(ids) != ids[1] - ids[0]):
        return ids
    step = int(ids[1] - ids[0])
    stop = int(ids[-1]) + step
    return slice(int(ids[0]), None if stop < 0 else stop, step)


def arm_indices(model) -> ArmIndices:
    """Find the attached arm in ``model`` (a dm_control physics' model): the one place that
    does; callers that read it every step cache the result per model."""
    joints = np.array([j for j in arm_ids(model, "joint") if model.jnt_type[j] == 3],
                      dtype=int)  # hinges
    joints = joints[::-1]  # generator adds caudal first; Table 1 is cranial first
    actuators = arm_ids(model, "actuator")
    head_site = int(model.name2id(arm_lib.HEAD_SITE_PATH, "site"))
    sensor = model.name2id(f"{arm_lib.ARM_MODEL_NAME}/{arm_lib.HEAD_VELOCITY_SENSOR}", "sensor")
    servo_gain = -model.actuator_gainprm[actuators, 0].copy()
    servo_bias = model.actuator_biasprm[actuators, 0].copy()
    qpos = np.array(model.jnt_qposadr[joints])
    tendons = np.array(model.actuator_trnid[actuators, 0], dtype=int)
    return ArmIndices(joints, qpos, np.array(model.jnt_dofadr[joints]), actuators, tendons,
                      head_site, int(model.site_bodyid[head_site]), int(model.sensor_adr[sensor]),
                      servo_gain, servo_bias, servo_bias / servo_gain,
                      as_slice(qpos), as_slice(actuators), as_slice(tendons),
                      int(model.opt.integrator) == int(mujoco_lib.mjtIntegrator.mjINT_RK4))


def tendon_sides(model) -> list[str]:
    """The side (one of ``arm.SIDES``) of each of the arm's tendons, in action order.

    Read from the model: a tendon runs through the holes of its ``TendonSpec.side``
    (``build_arm`` names them so), so its last hole says its side whatever its name.
    ``model`` is a physics' model with an attached arm (other actuators are skipped).
    """
    hole_suffixes = {side: arm_lib.hole_site_name("", side) for side in arm_lib.SIDES}
    sides = []
    for i in arm_ids(model, "actuator"):
        tendon = model.actuator_trnid[i, 0]
        last_site = model.wrap_objid[model.tendon_adr[tendon] + model.tendon_num[tendon] - 1]
        name = model.id2name(int(last_site), "site")
        sides.append(next(side for side, suffix in hole_suffixes.items()
                          if name.endswith(suffix)))
    return sides


def dorsal_index(model) -> int:
    """Action index of the arm's dorsal tendon: the first one on the dorsal side (every
    layout lists the paper's dorsal tendon, the one to the head, first)."""
    sides = tendon_sides(model)
    if "dorsal" not in sides:
        raise ValueError("the arm has no dorsal tendon")
    return sides.index("dorsal")


def ventral_indices(model) -> list[int]:
    """Action indices of the arm's ventral tendons, in action order."""
    return [i for i, side in enumerate(tendon_sides(model)) if side == "ventral"]


def head_axis(physics) -> np.ndarray:
    """World direction of the head's long axis (the head body's z axis)."""
    site_id = physics.model.name2id(arm_lib.HEAD_SITE_PATH, "site")
    body_id = physics.model.site_bodyid[site_id]
    return np.array(physics.data.xmat[body_id]).reshape(3, 3)[:, 2]


def continuous_attitude_deg(axis_angle_deg, joint_angles_rad):
    """Head attitude (deg) continuous over every pose the arm can take.

    ``axis_angle_deg`` is the head axis' angle from the vertical as ``atan2``
    gives it, in (-180, 180]; it jumps by 360 deg when the head passes
    straight down, while Table 1's limits let the joints sum from -409 to
    +292 deg.  In a planar chain of parallel hinges the attitude is the base's
    attitude plus the sum of the joint angles; the base (a frame or a
    quadruped's trunk) never turns by 180 deg, so taking the ``atan2`` value
    360k away that lies nearest the joint sum gives one continuous attitude.
    Works on scalars and on arrays ((n,) angles with (n, joints) joints).
    """
    summed = np.degrees(np.sum(joint_angles_rad, axis=-1))
    return axis_angle_deg + 360.0 * np.round((summed - axis_angle_deg) / 360.0)


def attitude_error_deg(attitude_deg, desired_deg):
    """How far the head is turned from ``desired_deg``, in [-180, 180) deg.

    The attitude itself is continuous and can differ from level by more than a
    turn (a neck curled back by -270 deg holds the head level, facing forward,
    as at +90); the error is about where the head points, so it is taken
    modulo a turn.  Its magnitude is continuous everywhere, so are rewards on it.
    """
    if isinstance(attitude_deg, float):  # one reading (the per-step path): plain floats, same result
        return (attitude_deg - desired_deg + 180.0) % 360.0 - 180.0
    return (np.asarray(attitude_deg) - desired_deg + 180.0) % 360.0 - 180.0


def one_pose_attitude_deg(axis_angle_rad: float, joint_angles_rad: np.ndarray) -> float:
    """:func:`continuous_attitude_deg` of one pose in plain floats (same result): the
    physics accessors run it once per control step."""
    axis_angle = math.degrees(axis_angle_rad)
    # The sum only chooses the whole number of turns, so its rounding never shows: a Python
    # sum of the list is half the cost of numpy's on 18 numbers.
    turns = (math.degrees(sum(joint_angles_rad.tolist())) - axis_angle) / 360.0
    return axis_angle + 360.0 * round(turns) if math.isfinite(turns) else math.nan


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


TARGET_RGBA = np.array([0.9, 0.1, 0.1, 1.0], np.float32)  # the target drawn in rendered frames
TOLERANCE_RGBA = np.array([0.9, 0.1, 0.1, 0.15], np.float32)  # the position tolerance around it
TARGET_DOT_RADIUS = 0.01  # m


class ArmPhysicsMixin:
    """Accessors for the arm's head, joints and tendons, plus divergence capture."""

    divergence: str | None = None
    # Episodes started and episodes that diverged, for the one log line per divergence.
    episodes_started: int = 0
    episodes_diverged: int = 0

    # Indices are looked up once per model, when dm_control binds it: it swaps the model only
    # through ``_reload_from_data`` (construction, reload, copy, unpickling).  The per-step
    # accessors read them, and the raw ``mujoco`` structs, as plain attributes: dm_control's
    # wrapper properties and a method call per read cost about as much as the task's work.
    _indices: ArmIndices

    def _reload_from_data(self, data):
        super()._reload_from_data(data)
        self.__dict__["_raw_model"], self.__dict__["_raw_data"] = data.model.ptr, data.ptr
        indices = self.__dict__["_indices"] = arm_indices(self.model)
        selects = (indices.qpos_select, indices.tendon_select, indices.actuator_select)
        model, raw = data.model.ptr, data.ptr
        # Views for the per-step readers (``ArmViews``); where an index is no slice, numpy would
        # copy instead of viewing and the copy would go stale, so then they read as before.
        if all(isinstance(select, slice) for select in selects):
            joints, tendons, actuators = selects
            velocity = indices.head_velocity
            views = ArmViews(
                model.actuator_ctrlrange[actuators, 0], model.actuator_ctrlrange[actuators, 1],
                model.actuator_forcerange[actuators, 0], raw.site_xpos[indices.head_site],
                raw.xmat[indices.head_body], raw.sensordata[velocity:velocity + 3],
                raw.qpos[joints], raw.ten_length[tendons], raw.actuator_force[actuators],
                raw.ctrl[actuators])
        else:
            views = None
        self.__dict__["_views"] = views

    def show_target_of(self, task) -> None:
        """Frames from :meth:`render` draw ``task``'s target (its ``target_in_world`` and
        ``position_tolerance``); the reaching tasks call it as each episode begins."""
        self.__dict__["_shown_task"] = task

    def render(self, *args, **kwargs):
        """dm_control's ``render``, with the target drawn where a task has shown one
        (:meth:`show_target_of`): a red dot inside a faint sphere of the position tolerance.
        Depth and segmentation frames, which are measurements, are left as the model makes them."""
        task = self.__dict__.get("_shown_task")
        measured = kwargs.get("depth", len(args) > 4 and args[4]) or kwargs.get("segmentation", len(args) > 5 and args[5])
        if task is None or measured or len(args) > 8:
            return super().render(*args, **kwargs)
        scene_callback = kwargs.pop("scene_callback", None)

        def draw_target(physics, scene):
            point = np.asarray(task.target_in_world(physics), np.float64)
            for radius, rgba in ((float(task.position_tolerance), TOLERANCE_RGBA), (TARGET_DOT_RADIUS, TARGET_RGBA)):
                if scene.ngeom < scene.maxgeom:
                    scene.ngeom += 1  # first: the bindings show only the scene's ngeom geoms
                    mujoco_lib.mjv_initGeom(scene.geoms[scene.ngeom - 1], mujoco_lib.mjtGeom.mjGEOM_SPHERE,
                                            np.array([radius, 0.0, 0.0]), point, np.eye(3).ravel(), rgba)
            if scene_callback is not None:
                scene_callback(physics, scene)
        return super().render(*args, scene_callback=draw_target, **kwargs)

    @property
    def arm_indices(self) -> ArmIndices:
        """Where the arm sits in this model (:func:`arm_indices`)."""
        return self._indices

    def arm_joint_names(self) -> list[str]:
        return [self.model.id2name(int(j), "joint") for j in self._indices.joints]

    def tendon_names(self) -> list[str]:
        return [self.model.id2name(int(i), "actuator") for i in self._indices.actuators]

    # What is returned is a copy (or a new array): the views are into the live simulation.
    # Each accessor reads through ``self._views`` where the model has them (``ArmViews``).
    def head_position(self) -> np.ndarray:
        """Head site position (x, y, z) in metres, world frame."""
        views = self._views
        if views is not None:
            return views.head_position.copy()
        return self._raw_data.site_xpos[self._indices.head_site].copy()

    def head_velocity(self) -> np.ndarray:
        """Head site linear velocity (x, y, z) in m/s, world frame."""
        views = self._views
        if views is not None:
            return views.head_velocity.copy()
        adr = self._indices.head_velocity
        return self._raw_data.sensordata[adr:adr + 3].copy()

    def _head_frame_and_joints(self) -> tuple[np.ndarray, np.ndarray]:
        """The head body's rotation matrix (9,) and the joint angles, as views where possible."""
        views = self._views
        if views is not None:
            return views.head_frame, views.joint_angles
        indices, data = self._indices, self._raw_data
        return data.xmat[indices.head_body], data.qpos[indices.qpos_select]

    def head_attitude(self) -> float:
        """Head attitude in degrees: 90 = head parallel to the ground (paper Fig. 2B); continuous
        past 180 (no wrap), see :func:`continuous_attitude_deg`."""
        xmat, joint_angles = self._head_frame_and_joints()  # row-major 3x3; column 2 = head axis
        return one_pose_attitude_deg(math.atan2(xmat[2], xmat[8]), joint_angles)

    def joint_angles(self) -> np.ndarray:
        """The 18 joint angles (rad), atlas first; positive = ventral flexion."""
        views = self._views
        if views is not None:
            return views.joint_angles.copy()
        return np.array(self._raw_data.qpos[self._indices.qpos_select])

    def tendon_lengths(self) -> np.ndarray:
        """Current length of each actuated tendon (m), in action order."""
        views = self._views
        if views is not None:
            return views.tendon_lengths.copy()
        return np.array(self._raw_data.ten_length[self._indices.tendon_select])

    def tendon_rest_lengths(self) -> np.ndarray:
        """Length of each tendon in the straight pose (m): the servo's zero contraction."""
        return self._indices.rest_lengths

    def tendon_contractions(self) -> np.ndarray:
        """How much each tendon is shorter than at rest (m)."""
        indices, views = self._indices, self._views
        if views is not None:
            return indices.rest_lengths - views.tendon_lengths
        return indices.rest_lengths - self._raw_data.ten_length[indices.tendon_select]

    def tendon_forces(self) -> np.ndarray:
        """Pull in each tendon (N, >= 0), in action order."""
        views = self._views
        if views is not None:
            return -views.tendon_forces
        return -self._raw_data.actuator_force[self._indices.actuator_select]

    def tendon_max_forces(self) -> np.ndarray:
        """Largest pull of each tendon's actuator (N, > 0), in action order."""
        return -self._raw_model.actuator_forcerange[self._indices.actuator_select, 0]

    def tendon_tensions(self) -> np.ndarray:
        """Pull in each tendon as a fraction of its actuator's largest pull (0-1)."""
        views = self._views
        if views is not None:
            return views.tendon_forces / views.pull_limit
        select = self._indices.actuator_select
        return self._raw_data.actuator_force[select] / self._raw_model.actuator_forcerange[select, 0]

    def arm_control(self) -> np.ndarray:
        views = self._views
        if views is not None:
            return views.controls.copy()
        return np.array(self._raw_data.ctrl[self._indices.actuator_select])

    def arm_control_range(self) -> np.ndarray:
        """(9, 2) low/high tendon contractions (m): the action spec's bounds."""
        return np.array(self._raw_model.actuator_ctrlrange[self._indices.actuator_select])

    def arm_control_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """(low, high) tendon contractions (m) for reading only: where the model has
        ``ArmViews`` these are views into it, which the per-step action check reads instead of
        copying the (9, 2) range."""
        views = self._views
        if views is not None:
            return views.control_low, views.control_high
        ctrlrange = self._raw_model.actuator_ctrlrange[self._indices.actuator_select]
        return ctrlrange[:, 0], ctrlrange[:, 1]

    def arm_control_view(self) -> np.ndarray | None:
        """The arm's entries of the simulation's controls as a writable view (action order), for
        the per-step action check to clip into; None where the model has no ``ArmViews``."""
        views = self._views
        return None if views is None else views.controls

    def set_arm_control(self, action) -> None:
        """Write tendon contractions to the arm's actuators only (a robot may have others)."""
        views = self._views
        if views is not None:
            views.controls[:] = action
        else:
            self._raw_data.ctrl[self._indices.actuator_select] = action

    def step(self, nstep: int = 1) -> None:
        """Step, but turn a divergence into a flag the task ends the episode on.

        The same MuJoCo calls and the same invalid-state test (a MuJoCo warning count that
        grew) as dm_control's ``Physics.step``, on the raw structs: its wrapper costs about
        as much as the whole task's observation.  A divergence ends the episode, so it is
        logged once per episode: one line with MuJoCo's own warnings and how many episodes
        have diverged so far."""
        if self.divergence is not None:
            return
        if not (self.legacy_step and self._warnings_cause_exception):
            return self._checked_step(nstep)  # dm_control's own path, for its other settings
        model, data, warnings = self._raw_model, self._raw_data, self._warnings
        # MuJoCo's warning counts stay 0 until something goes wrong (a reset clears them), so
        # mostly one test before and one after the step say that none grew (count_nonzero:
        # a third of ndarray.any's cost on 8 numbers).
        before = warnings.copy() if np.count_nonzero(warnings) else None
        _MUJOCO_WARNINGS.active, _MUJOCO_WARNINGS.messages = True, []
        try:
            # dm_control's legacy step: mj_step1 of this state ran at the end of the last step.
            if self._indices.rk4:
                mujoco_lib.mj_step(model, data, nstep)
            else:
                mujoco_lib.mj_step2(model, data)
                if nstep > 1:
                    mujoco_lib.mj_step(model, data, nstep - 1)
            mujoco_lib.mj_step1(model, data)
        finally:
            _MUJOCO_WARNINGS.active = False
        if not np.count_nonzero(warnings):
            return
        new_warnings = warnings > (0 if before is None else before)
        if new_warnings.any():
            names = np.compress(new_warnings, list(mujoco_lib.mjtWarning.__members__))
            self.divergence = _INVALID_STATE.format(warning_names=", ".join(names))
            self._log_divergence(_MUJOCO_WARNINGS.messages)

    def _checked_step(self, nstep: int) -> None:
        """dm_control's ``Physics.step`` with the divergence turned into the flag."""
        _MUJOCO_WARNINGS.active, _MUJOCO_WARNINGS.messages = True, []
        try:
            super().step(nstep)
        except control.PhysicsError as error:
            self.divergence = str(error)
        else:
            data = self._raw_data
            # A sum is non-finite exactly when an entry is (our states are far below overflow).
            if not (math.isfinite(data.qpos.sum()) and math.isfinite(data.qvel.sum())):
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

    def checkpoint_state(self) -> dict:
        """The variables beside MuJoCo's state that a resumed episode needs (agents/robostrich/environment_state.py)."""
        return {"divergence": self.divergence, "episodes_started": self.episodes_started,
                "episodes_diverged": self.episodes_diverged}

    def restore_checkpoint_state(self, state: dict) -> None:
        self.divergence = None if state["divergence"] is None else str(state["divergence"])
        self.episodes_started, self.episodes_diverged = int(state["episodes_started"]), int(state["episodes_diverged"])

    # The arm's state when the last reset began, (qpos, qvel, act, tendon command), or None if
    # the episode it ended diverged: a "continue" episode starts from it (``Reach``). Kept here,
    # once per reset, so that no task has to copy the state after every step in case it is the
    # episode's last (an unpickled physics starts without one: its state is the live one).
    state_before_reset: tuple | None = None

    def continuing_state(self) -> tuple | None:
        """What a "continue" episode would start from now: the state and the held tendon inputs
        (copies), None while the last episode's divergence stands or before any data exists."""
        data = self.__dict__.get("_raw_data")
        return None if data is None or self.divergence is not None else (
            data.qpos.copy(), data.qvel.copy(), data.act.copy(), self.arm_control())

    def reset(self, keyframe_id=None):
        self.state_before_reset = self.continuing_state()
        self.divergence = None
        self.episodes_started += 1
        return super().reset(keyframe_id)
