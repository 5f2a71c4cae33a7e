"""Where the head can go: the kinematic and the actuated workspace.

The *kinematic* workspace (the paper's Fig. 6) samples joint angles within
Table 1's limits and asks MuJoCo's forward kinematics where the head is.  The
*actuated* workspace holds random tendon inputs until the passive chain
settles under gravity and records where the head came to rest: these are
poses the arm really reaches.  Its level-head subset (attitude 90 +- 5 deg) is
the one source of the tasks' targets (see :mod:`robostrich_suite.targets`).
"""
from __future__ import annotations

import dataclasses
import hashlib

import numpy as np
from dm_control import mjcf

from robostrich_suite import arm as arm_lib

LEVEL_ATTITUDE_DEG = 90.0
LEVEL_TOLERANCE_DEG = 5.0


def model_fingerprint(spec: arm_lib.ArmSpec | None = None,
                      layout: arm_lib.TendonLayout | None = None) -> str:
    """Short hash of what decides where the arm comes to rest; a pose set made with
    another arm is stale.  Colours, names and sensors do not count."""
    model = frame_physics(spec, layout).model
    digest = hashlib.sha256()
    for field in ("body_pos", "body_quat", "body_mass", "body_inertia", "jnt_range",
                  "jnt_stiffness", "jnt_solref", "jnt_solimp", "dof_damping", "dof_armature",
                  "site_pos", "geom_size", "actuator_gainprm", "actuator_biasprm",
                  "actuator_ctrlrange", "actuator_forcerange", "wrap_objid"):
        digest.update(np.round(np.asarray(getattr(model, field), np.float64), 9).tobytes())
    digest.update(np.array([model.opt.timestep, model.opt.integrator], np.float64).tobytes())
    return digest.hexdigest()[:16]


def frame_physics(spec=None, layout=None) -> mjcf.Physics:
    return mjcf.Physics.from_mjcf_model(arm_lib.build_frame_arm(spec, layout))


def head_position_xz(physics: mjcf.Physics) -> np.ndarray:
    return arm_lib.head_position(physics)[[0, 2]]


def head_attitude_deg(physics: mjcf.Physics) -> float:
    """Angle of the head axis from the vertical in the x-z plane: 90 = level."""
    return arm_lib.head_attitude_deg(physics)


@dataclasses.dataclass
class ActuatedSamples:
    """Settled head poses under random constant tendon inputs."""
    head_position: np.ndarray  # (n, 2) x, z in metres
    head_attitude: np.ndarray  # (n,) degrees
    control: np.ndarray  # (n, num_tendons) the inputs that hold each pose
    settled: np.ndarray  # (n,) bool: joint speeds below the threshold at the end

    def level(self, tolerance_deg: float = LEVEL_TOLERANCE_DEG) -> np.ndarray:
        """Mask of settled poses with the head level (90 +- tolerance deg)."""
        return self.settled & (np.abs(self.head_attitude - LEVEL_ATTITUDE_DEG) <= tolerance_deg)


def settle(physics: mjcf.Physics, control: np.ndarray, settle_time: float = 1.5,
           speed_tolerance: float = 0.05) -> bool:
    """Reset, hold ``control`` for ``settle_time`` seconds; True if the arm came to rest."""
    physics.reset()
    physics.data.ctrl[:] = control
    steps = int(round(settle_time / physics.model.opt.timestep))
    physics.step(steps)
    return bool(np.all(np.isfinite(physics.data.qpos))
                and np.abs(physics.data.qvel).max() < speed_tolerance)


def actuated_samples(num_samples: int, seed: int = 0, settle_time: float = 1.5,
                     physics: mjcf.Physics | None = None, progress: bool = False
                     ) -> ActuatedSamples:
    """Hold uniformly random tendon inputs and record the settled head poses."""
    physics = physics or frame_physics()
    rng = np.random.default_rng(seed)
    low, high = physics.model.actuator_ctrlrange.T
    controls = rng.uniform(low, high, size=(num_samples, physics.model.nu))
    positions = np.zeros((num_samples, 2))
    attitudes = np.zeros(num_samples)
    settled = np.zeros(num_samples, bool)
    iterator = range(num_samples)
    if progress:
        from tqdm import tqdm
        iterator = tqdm(iterator, desc="actuated workspace", unit="pose")
    for i in iterator:
        settled[i] = settle(physics, controls[i], settle_time)
        positions[i] = head_position_xz(physics)
        attitudes[i] = head_attitude_deg(physics)
    return ActuatedSamples(positions, attitudes, controls, settled)
