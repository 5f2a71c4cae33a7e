"""Find tendon inputs that hold the head level at a given place (sampling the blue region).

Random inputs (:func:`workspace.actuated_samples`) land where the routing lets a
hanging neck fall, and rarely in the paper's blue region, so a layout that *could*
hold a blue-region pose may never be seen to.  Here each blue-region sample is
sought directly, the same way for every layout:

1. start from the inputs that give every tendon its length in the kinematic pose;
2. from the fixed start, move the inputs slowly (an integral loop) by the tendon
   length changes that would move the head towards the target position with the
   head level: the damped least-squares joint step for (x, z, attitude) mapped
   through the tendons' Jacobian;
3. keep the final inputs only as a candidate: :func:`workspace.settle` holds them
   constant from the fixed start, and only a pose at rest counts (what a policy
   holding these inputs for an episode would get).
"""
from __future__ import annotations

import mujoco
import numpy as np

from robostrich_suite import physics as physics_lib
from robostrich_suite.model import arm as arm_lib
from robostrich_suite import scenes
from robostrich_suite.studies import workspace
from robostrich_suite.tasks import conventions

SEEK_TIME = 8.0  # s of input adjustment per target
SEEK_GAIN = 0.003  # fraction of the wanted tendon-length change applied per update
UPDATE_EVERY = 4  # physics steps per update: the environments' control step
ATTITUDE_SCALE = 0.1  # m per rad: how a degree of attitude error weighs against position
DAMPING = 1e-4  # of the least-squares joint step
HOLD_TIME = workspace.SETTLE_TIME  # s a candidate is held from the fixed start: one episode


def contraction_at(physics, joint_angles: np.ndarray, spec: arm_lib.ArmSpec) -> np.ndarray:
    """Every tendon's contraction (servo rest length minus length) in the pose ``joint_angles``."""
    with physics.reset_context():
        physics.data.qpos[physics_lib.arm_indices(physics.model).qpos] = joint_angles
    contraction = physics.tendon_contractions()
    physics.reset()
    return contraction


def seek_pose(physics, target_xz, control, seek_time: float = SEEK_TIME,
              gain: float = SEEK_GAIN) -> np.ndarray:
    """From reset, adjust ``control`` for ``seek_time`` s towards a level head at
    ``target_xz``; return the final inputs (a candidate, see the module doc)."""
    model, data = physics.model.ptr, physics.data.ptr
    site = physics.model.name2id(arm_lib.HEAD_SITE_PATH, "site")
    head_body = physics.model.site_bodyid[site]
    tendons = physics.model.actuator_trnid[:, 0]
    low, high = physics.model.actuator_ctrlrange.T
    control = np.clip(np.asarray(control, np.float64), low, high)
    jacp, jacr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    tendon_jacobian = np.zeros((model.ntendon, model.nv))
    physics.reset()
    data.ctrl[:] = control
    for step in range(int(round(seek_time / model.opt.timestep))):
        if step % UPDATE_EVERY == 0:
            mujoco.mj_jacSite(model, data, jacp, jacr, site)
            head_axis = data.xmat[head_body, [2, 8]]
            attitude = physics_lib.continuous_attitude_deg(
                np.degrees(np.arctan2(*head_axis)), data.qpos[:model.nv])
            error = np.array([target_xz[0] - data.site_xpos[site, 0],
                              target_xz[1] - data.site_xpos[site, 2],
                              ATTITUDE_SCALE * np.radians(float(physics_lib.attitude_error_deg(
                                  conventions.LEVEL_ATTITUDE_DEG, attitude)))])
            jacobian = np.stack([jacp[0], jacp[2], ATTITUDE_SCALE * jacr[1]])
            joint_step = jacobian.T @ np.linalg.solve(jacobian @ jacobian.T + DAMPING * np.eye(3), error)
            mujoco.mju_sparse2dense(tendon_jacobian, data.ten_J, model.ten_J_rownnz,
                                    model.ten_J_rowadr, model.ten_J_colind)
            control = np.clip(control - gain * (tendon_jacobian[tendons] @ joint_step), low, high)
            data.ctrl[:] = control
        mujoco.mj_step(model, data)
    return control


def seek_samples(targets_xz, joint_angles, spec: arm_lib.ArmSpec | None = None,
                 layout: arm_lib.TendonLayout | None = None, seek_time: float = SEEK_TIME,
                 hold_time: float = HOLD_TIME, progress=None) -> workspace.ActuatedSamples:
    """One sought pose per target (head position ``targets_xz[i]``, kinematic pose
    ``joint_angles[i]`` to start from), held from the fixed start: the same record as
    :func:`workspace.actuated_samples`.  ``progress(n)`` is called after each."""
    spec = spec or arm_lib.ArmSpec.from_table1()
    physics = scenes.frame_physics(spec, layout)
    count = len(targets_xz)
    result = workspace.ActuatedSamples(np.zeros((count, 2)), np.zeros(count),
                                       np.zeros((count, physics.model.nu)), np.zeros(count, bool),
                                       np.zeros((count, spec.num_joints)))
    for i, (target, angles) in enumerate(zip(targets_xz, joint_angles)):
        start = contraction_at(physics, angles, spec)
        control = seek_pose(physics, target, start, seek_time)
        result.control[i] = control
        result.settled[i] = workspace.settle(physics, control, hold_time)
        result.head_position[i] = physics.head_position()[[0, 2]]
        result.head_attitude[i] = physics.head_attitude()
        result.joint_angles[i] = physics.joint_angles()
        if progress is not None:
            progress(1)
    return result
