"""Domain randomisation of the arm, for policies meant to survive the real robot.

The paper names it as the next step towards sim-to-real (Sec. 6: randomise
friction and damping, add noise to the joint measurements).  Each episode
draws new scales for the arm's link masses, joint stiffness and damping and the
tendon servo gains, always relative to the nominal model (never cumulative),
and joint-angle observations can carry Gaussian noise.

    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(
        randomization=DomainRandomization(mass_scale=(0.8, 1.2))))
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from robostrich_suite import physics as physics_lib
from robostrich_suite.tasks import options


@dataclasses.dataclass(frozen=True)
class DomainRandomization:
    """Uniform ranges of multiplicative scales; (1, 1) switches a parameter off."""
    mass_scale: tuple[float, float] = (0.9, 1.1)
    stiffness_scale: tuple[float, float] = (0.8, 1.2)
    damping_scale: tuple[float, float] = (0.7, 1.3)
    tendon_gain_scale: tuple[float, float] = (0.9, 1.1)
    joint_angle_noise: float = 0.0  # rad, standard deviation added to observed joint angles

    def __post_init__(self):
        for field in ("mass_scale", "stiffness_scale", "damping_scale", "tendon_gain_scale"):
            low, high = options.pair(field, getattr(self, field), 0.0, options.MAX_SCALE)
            if low <= 0:
                raise ValueError(f"{field} must be (low, high) with 0 < low <= high <= {options.MAX_SCALE:g}, "
                                 f"got {(low, high)}")
            object.__setattr__(self, field, (low, high))  # JSON's [low, high] as the tuple it stands for
        options.number("joint_angle_noise", self.joint_angle_noise, 0.0, math.pi,
                       "a standard deviation from 0 to pi rad")


class Randomizer:
    """Remembers the nominal model and applies fresh draws of ``DomainRandomization``."""

    def __init__(self, config: DomainRandomization):
        self.config = config
        self._nominal = None

    def _remember(self, physics):
        model = physics.model
        bodies = physics_lib.arm_ids(model, "body")
        joints = physics_lib.arm_ids(model, "joint")
        dofs = model.jnt_dofadr[joints]
        actuators = physics_lib.arm_ids(model, "actuator")
        self._nominal = dict(
            bodies=bodies, joints=joints, dofs=dofs, actuators=actuators,
            mass=model.body_mass[bodies].copy(), inertia=model.body_inertia[bodies].copy(),
            stiffness=model.jnt_stiffness[joints].copy(), damping=model.dof_damping[dofs].copy(),
            gain=model.actuator_gainprm[actuators].copy(),
            bias=model.actuator_biasprm[actuators].copy())

    # What ``_remember`` keeps: element ids and their nominal parameters.
    NOMINAL_FIELDS = ("bodies", "joints", "dofs", "actuators", "mass", "inertia", "stiffness", "damping", "gain",
                      "bias")

    def checkpoint_state(self) -> dict:
        """The nominal model remembered at the first draw, as data (the task's checkpoint state): a
        resumed run scales the same nominal values, not the randomised model it restores."""
        return {"nominal": self._nominal}

    def restore_checkpoint_state(self, state: dict) -> None:
        nominal = state["nominal"]
        if nominal is not None and set(nominal) != set(self.NOMINAL_FIELDS):
            raise ValueError(f"the stored nominal model has {sorted(nominal)}, not {sorted(self.NOMINAL_FIELDS)}")
        self._nominal = None if nominal is None else {k: np.array(nominal[k]) for k in self.NOMINAL_FIELDS}

    def apply(self, physics, random: np.random.RandomState) -> dict:
        """Draw and set new parameters; returns the scales drawn."""
        if self._nominal is None:
            self._remember(physics)
        n, c, model = self._nominal, self.config, physics.model
        scales = dict(
            mass=random.uniform(*c.mass_scale, size=len(n["bodies"])),
            stiffness=random.uniform(*c.stiffness_scale, size=len(n["joints"])),
            damping=random.uniform(*c.damping_scale, size=len(n["dofs"])),
            tendon_gain=random.uniform(*c.tendon_gain_scale, size=len(n["actuators"])))
        model.body_mass[n["bodies"]] = n["mass"] * scales["mass"]
        model.body_inertia[n["bodies"]] = n["inertia"] * scales["mass"][:, None]
        model.jnt_stiffness[n["joints"]] = n["stiffness"] * scales["stiffness"]
        model.dof_damping[n["dofs"]] = n["damping"] * scales["damping"]
        # Scaling gain and all bias terms together keeps the servo's rest length.
        model.actuator_gainprm[n["actuators"]] = n["gain"] * scales["tendon_gain"][:, None]
        model.actuator_biasprm[n["actuators"]] = n["bias"] * scales["tendon_gain"][:, None]
        return scales

    def begin_episode(self, physics, random: np.random.RandomState, continuing: bool) -> None:
        """Every episode draws new parameters (``continuing``: it starts where the last one ended)."""
        self.apply(physics, random)

    def delayed(self, action):
        """The action that reaches the servos (tasks.perturbations delays it; here it is not)."""
        return action

    def begin_actions(self, held) -> None:
        """Nothing held back here (tasks.perturbations: the input held until a delayed action arrives)."""

    def observe_joint_angles(self, angles: np.ndarray, random: np.random.RandomState
                             ) -> np.ndarray:
        if self.config.joint_angle_noise == 0:
            return angles
        return angles + random.normal(0.0, self.config.joint_angle_noise, size=angles.shape)
