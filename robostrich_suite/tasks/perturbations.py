"""The robot differs from its model: one definition of each difference and of its scale s.

Used both to measure how far a policy's success falls (``robostrich-robustness``) and to train
with those differences (``robostrich-train --task-kwargs '{"perturbation": {"mass": 0.2}}'``), so a
scale means the same thing in both. A task takes ``perturbation=Perturbation(mass=0.2, ...)`` (or a dict of its fields); scale 0 (the
default of every family) changes nothing and draws nothing: the task and its random stream are
the nominal ones.

What scale s does to each family (draws are per episode, relative to the nominal model, never
cumulative; an episode that continues from the previous one's final state, as lesson 3 and the
moving starts do, keeps the previous episode's robot):

* ``mass``: each arm link's mass and inertia times a factor drawn uniformly from [1-s, 1+s].
* ``joint``: each joint's passive stiffness and each joint's damping times its own factor from
  [1-s, 1+s].
* ``servo``: each tendon servo's gain (kp, its damping term and rest-length term with it, so the
  rest length is kept) and its force limit times their own factors from [1-s, 1+s].
* ``tendon_length``: each tendon's rest length offset by a length drawn uniformly from
  [-s, s] x ``TENDON_LENGTH_AT_1`` (slack when longer: the servo pulls that much later).
* ``friction``: each joint gets dry friction (MuJoCo's frictionloss; the model has none) drawn
  uniformly from [0, s] x ``FRICTION_AT_1``.
* ``joint_noise``: Gaussian noise of standard deviation s x ``JOINT_NOISE_AT_1`` on every
  observed joint angle, fresh at every control step.
* ``latency``: every action reaches the servos ``latency_steps(s)`` control steps late
  (round(s x ``LATENCY_STEPS_PER_SCALE``), at most ``MAX_LATENCY_STEPS``: s = 0.1 and 0.2 are
  one step, 0.3 two, 0.5 and above three); until then the servos hold the input they had when
  the episode began.
* ``trunk_height`` (quadruped): the trunk stands higher or lower than commanded by an offset drawn
  uniformly from [-s, s] x ``TRUNK_HEIGHT_AT_1``.
* ``gait_timing`` (quadruped, walking): the gait's clock runs at a rate drawn uniformly from
  [1-s, 1+s] and starts at a phase drawn uniformly from [0, s] of a second.

With ``vary`` (training across robots rather than measuring one), each fresh episode first draws
each family's scale uniformly from [0, s] (latency: a whole number of steps from 0 to
``latency_steps(s)``), then the family's draws at that scale: the robots trained on then span the
nominal one up to s, where without ``vary`` a latency is always exactly ``latency_steps(s)``.

The draws of each family come from their own stream seeded from one number the task's
RandomState draws per fresh episode: a family's draws do not depend on which other families
are on, and "all families at once" perturbs each exactly as alone.
"""
from __future__ import annotations

import collections
import dataclasses

import numpy as np

from robostrich_suite.tasks import options
from robostrich_suite.tasks.randomization import Randomizer

ARM_FAMILIES = ("mass", "joint", "servo", "tendon_length", "friction", "joint_noise", "latency")
QUADRUPED_FAMILIES = ("trunk_height", "gait_timing")
FAMILIES = ARM_FAMILIES + QUADRUPED_FAMILIES
MAX_SCALE = 1.0  # a factor of 1 - s must stay >= 0

TENDON_LENGTH_AT_1 = 0.01  # m: s = 0.1 offsets each rest length by up to 1 mm
FRICTION_AT_1 = 0.05  # N m: the spring torque of a joint (stiffness 1 N m/rad) ~3 deg from rest
JOINT_NOISE_AT_1 = 0.0175  # rad (1 deg) standard deviation
LATENCY_STEPS_PER_SCALE = 6.0
MAX_LATENCY_STEPS = 3
TRUNK_HEIGHT_AT_1 = 0.05  # m

# The model fields each family writes (the tests check that it writes exactly these).
FIELDS = {
    "mass": ("body_mass", "body_inertia"),
    "joint": ("jnt_stiffness", "dof_damping"),
    "servo": ("actuator_gainprm", "actuator_biasprm", "actuator_forcerange"),
    "tendon_length": ("actuator_biasprm",),
    "friction": ("dof_frictionloss",),
    "joint_noise": (), "latency": (), "trunk_height": (), "gait_timing": (),
}


def parse_scales(text: str) -> dict:
    """``FAMILY=S,...`` (``all=S`` for every family of the domain, named ones over it) as
    {name: scale}; a ValueError naming the problem for an unknown or repeated family, an empty
    item or a bad scale."""
    scales = {}
    for item in (part.strip() for part in text.split(",")):
        if not item:
            raise ValueError(f"an empty item in {text!r}: expected FAMILY=SCALE items separated by single commas")
        name, sep, value = item.partition("=")
        name = name.strip()
        if not sep or name not in FAMILIES + ("all",):
            raise ValueError(f"expected FAMILY=SCALE items with FAMILY one of all, {', '.join(FAMILIES)}; got {item!r}")
        if name in scales:
            raise ValueError(f"{name} is given twice in {text!r}: give each family once")
        try:
            scale = float(value)
        except ValueError:
            raise ValueError(f"{name}: expected a scale from 0 to {MAX_SCALE:g}, got {value.strip()!r}") from None
        scales[name] = options.number(name, scale, 0.0, MAX_SCALE, f"a scale from 0 to {MAX_SCALE:g}")
    if not scales:
        raise ValueError("expected FAMILY=SCALE items, e.g. all=0.3,latency=0.5")
    return scales


def training_perturbation(scales: dict, families) -> dict:
    """The task option ``perturbation`` that trains across robots up to ``scales`` ({name: s}, ``all``
    for every one of ``families``): each family's scale drawn per episode (``vary``)."""
    unknown = [name for name in scales if name != "all" and name not in families]
    if unknown:
        raise ValueError(f"{', '.join(unknown)} do not apply here (the families here: {', '.join(families)})")
    chosen = {family: scales["all"] for family in families} if "all" in scales else {}
    chosen.update({name: s for name, s in scales.items() if name != "all"})
    return {**{f: s for f, s in chosen.items() if s > 0}, "vary": True}


def latency_steps(scale: float) -> int:
    """Control steps of delay at ``scale``: round(6 s), at most 3 (module doc)."""
    return min(MAX_LATENCY_STEPS, int(np.floor(scale * LATENCY_STEPS_PER_SCALE + 0.5)))


@dataclasses.dataclass(frozen=True)
class Perturbation:
    """Scale s (0 to 1) of each family (module doc); all 0 = the nominal robot."""
    mass: float = 0.0
    joint: float = 0.0
    servo: float = 0.0
    tendon_length: float = 0.0
    friction: float = 0.0
    joint_noise: float = 0.0
    latency: float = 0.0
    trunk_height: float = 0.0
    gait_timing: float = 0.0
    vary: bool = False  # draw each family's scale per episode from [0, s] (module doc)

    def __post_init__(self):
        for family in FAMILIES:
            value = options.number(family, getattr(self, family), 0.0, MAX_SCALE, f"a scale from 0 to {MAX_SCALE:g}")
            object.__setattr__(self, family, float(value))
        object.__setattr__(self, "vary", options.flag("vary", self.vary))

    @classmethod
    def of(cls, families, scale: float) -> "Perturbation":
        """``families`` (names, or one name) all at ``scale``."""
        families = (families,) if isinstance(families, str) else tuple(families)
        unknown = [f for f in families if f not in FAMILIES]
        if unknown:
            raise ValueError(f"unknown perturbation families {unknown}; use {', '.join(FAMILIES)}")
        return cls(**{f: scale for f in families})

    def active(self) -> tuple:
        return tuple(f for f in FAMILIES if getattr(self, f) > 0)


class Perturber(Randomizer):
    """Applies a ``Perturbation`` to a task's physics each fresh episode and filters its actions
    and observations; extends the Randomizer's memory of the nominal model by the fields it adds."""

    NOMINAL_FIELDS = Randomizer.NOMINAL_FIELDS + ("forcerange", "frictionloss")

    def __init__(self, config: Perturbation):
        super().__init__(config)
        self._latency = latency_steps(config.latency)
        self._joint_noise = config.joint_noise  # this episode's scale (``vary`` draws it)
        self._pending = collections.deque()
        self.trunk_height_offset = 0.0
        self.gait_rate = 1.0
        self.gait_phase = 0.0

    def _remember(self, physics):
        super()._remember(physics)
        model, n = physics.model, self._nominal
        n["forcerange"] = model.actuator_forcerange[n["actuators"]].copy()
        n["frictionloss"] = model.dof_frictionloss[n["dofs"]].copy()

    def checkpoint_state(self) -> dict:
        return {**super().checkpoint_state(), "latency": self._latency, "joint_noise": self._joint_noise,
                "pending": [np.array(a) for a in self._pending],
                "trunk_height_offset": self.trunk_height_offset, "gait_rate": self.gait_rate,
                "gait_phase": self.gait_phase}

    def restore_checkpoint_state(self, state: dict) -> None:
        super().restore_checkpoint_state(state)
        self._latency = int(state.get("latency", self._latency))
        self._joint_noise = float(state.get("joint_noise", self._joint_noise))
        self._pending = collections.deque(np.array(a, np.float64) for a in state["pending"])
        self.trunk_height_offset = float(state["trunk_height_offset"])
        self.gait_rate = float(state["gait_rate"])
        self.gait_phase = float(state["gait_phase"])

    def apply(self, physics, random: np.random.RandomState) -> dict:
        """Draw this episode's robot (only for the families that are on: scale 0 draws nothing)."""
        c = self.config
        if not c.active():
            return {}
        if self._nominal is None:
            self._remember(physics)
        seed = int(random.randint(2**31))
        stream = {f: np.random.RandomState([seed, i]) for i, f in enumerate(FAMILIES)}
        n, model, drawn = self._nominal, physics.model, {}
        scale = {f: getattr(c, f) for f in FAMILIES}
        if c.vary:  # this episode's scale of each family that is on, from its own stream first
            for family in c.active():
                scale[family] = float(stream[family].uniform(0.0, scale[family]))
            self._latency = (int(stream["latency"].randint(0, latency_steps(c.latency) + 1)) if c.latency else 0)
            drawn["scale"] = {f: scale[f] for f in c.active()}
            drawn["latency_steps"] = self._latency
            c = dataclasses.replace(c, **scale)
        self._joint_noise = c.joint_noise

        def factors(family, size):
            s = getattr(c, family)
            return stream[family].uniform(1 - s, 1 + s, size=size)

        self.restore(physics)
        if c.mass:
            drawn["mass"] = f = factors("mass", len(n["bodies"]))
            model.body_mass[n["bodies"]] = n["mass"] * f
            model.body_inertia[n["bodies"]] = n["inertia"] * f[:, None]
        if c.joint:
            drawn["stiffness"] = factors("joint", len(n["joints"]))
            drawn["damping"] = factors("joint", len(n["dofs"]))
            model.jnt_stiffness[n["joints"]] = n["stiffness"] * drawn["stiffness"]
            model.dof_damping[n["dofs"]] = n["damping"] * drawn["damping"]
        if c.servo:
            drawn["gain"] = gain = factors("servo", len(n["actuators"]))
            drawn["force_limit"] = limit = factors("servo", len(n["actuators"]))
            model.actuator_gainprm[n["actuators"]] = n["gain"] * gain[:, None]
            model.actuator_biasprm[n["actuators"]] = n["bias"] * gain[:, None]
            model.actuator_forcerange[n["actuators"]] = n["forcerange"] * limit[:, None]
        if c.tendon_length:
            drawn["tendon_length"] = offset = stream["tendon_length"].uniform(
                -c.tendon_length, c.tendon_length, size=len(n["actuators"])) * TENDON_LENGTH_AT_1
            # The servo's force is kp (rest - length - contraction): biasprm[0] = kp rest, kp = -biasprm[1].
            biases = model.actuator_biasprm[n["actuators"]]
            model.actuator_biasprm[n["actuators"], 0] = biases[:, 0] - biases[:, 1] * offset
        if c.friction:
            drawn["friction"] = stream["friction"].uniform(0.0, c.friction, size=len(n["dofs"])) * FRICTION_AT_1
            model.dof_frictionloss[n["dofs"]] = n["frictionloss"] + drawn["friction"]
        self.trunk_height_offset = (float(stream["trunk_height"].uniform(-1, 1)) * c.trunk_height
                                    * TRUNK_HEIGHT_AT_1 if c.trunk_height else 0.0)
        self.gait_rate = float(factors("gait_timing", None)) if c.gait_timing else 1.0
        self.gait_phase = float(stream["gait_timing"].uniform(0, c.gait_timing)) if c.gait_timing else 0.0
        return drawn

    def begin_episode(self, physics, random, continuing: bool) -> None:
        """A fresh episode draws a new robot; one that continues the last episode's motion keeps it."""
        if not continuing:
            self.apply(physics, random)

    def restore(self, physics) -> None:
        """Put every field a family writes back to its nominal value."""
        n, model = self._nominal, physics.model
        if n is None:
            return
        model.body_mass[n["bodies"]] = n["mass"]
        model.body_inertia[n["bodies"]] = n["inertia"]
        model.jnt_stiffness[n["joints"]] = n["stiffness"]
        model.dof_damping[n["dofs"]] = n["damping"]
        model.actuator_gainprm[n["actuators"]] = n["gain"]
        model.actuator_biasprm[n["actuators"]] = n["bias"]
        model.actuator_forcerange[n["actuators"]] = n["forcerange"]
        model.dof_frictionloss[n["dofs"]] = n["frictionloss"]

    def begin_actions(self, held) -> None:
        """A new episode: the servos hold ``held`` until the first delayed action arrives."""
        self._pending = collections.deque(np.array(held, np.float64) for _ in range(self._latency))

    def delayed(self, action) -> np.ndarray:
        """The action that reaches the servos now: ``action`` sent ``latency`` control steps ago."""
        if not self._latency:
            return action
        self._pending.append(np.array(action, np.float64))
        return self._pending.popleft()

    def observe_joint_angles(self, angles: np.ndarray, random: np.random.RandomState) -> np.ndarray:
        if not self.config.joint_noise:  # off: nothing drawn (with ``vary`` at 0 this episode, a draw of 0)
            return angles
        return angles + random.normal(0.0, self._joint_noise * JOINT_NOISE_AT_1, size=angles.shape)

