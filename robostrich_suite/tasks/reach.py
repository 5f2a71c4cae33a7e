"""Reaching tasks for any domain whose Physics has the arm accessors.

``Reach`` is one curriculum lesson (paper Sec. 3.2): lesson 1 rewards only the
position (eq. 9); lessons 2 and 3 reward position and head attitude (eq. 10).
Lessons 1-2 start from the fixed pose, lesson 3 from where the last episode ended
(:mod:`~robostrich_suite.tasks.starts`, with the other start distributions); targets come
from a pool (:mod:`~robostrich_suite.tasks.target_samplers`).  Every option is a field of
:class:`ReachConfig`, whose paper values :func:`default_config` gives.

``Track`` (:mod:`~robostrich_suite.tasks.track`) is the evaluation task of Fig. 7 built on it.

Actions are tendon contractions (m); values outside the action spec are
clipped to it, a NaN action raises ``ValueError``.  A physics divergence ends
the episode (discount 0) and is logged, instead of raising from the step.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
from dm_control.suite import base
from dm_env import specs

from robostrich_suite import physics as physics_lib
from robostrich_suite.tasks import options
from robostrich_suite.tasks import perturbations as perturbations_lib
from robostrich_suite.tasks import randomization as randomization_lib
from robostrich_suite.tasks import rewards
from robostrich_suite.tasks.measurement import Measurement
from robostrich_suite.tasks.actions import check_action
from robostrich_suite.tasks.starts import RELEASE_TIME, StartDistribution, check_initial_state
from robostrich_suite.tasks.target_samplers import MAX_TARGET_DISTANCE, TargetSampler
from robostrich_suite.tasks.conventions import LEVEL_ATTITUDE_DEG as DESIRED_ATTITUDE
from robostrich_suite.tasks.conventions import LEVEL_TOLERANCE_DEG as ATTITUDE_TOLERANCE
from robostrich_suite.tasks.conventions import CONTROL_TIMESTEP, POSITION_TOLERANCE
from robostrich_suite import targets

REWARDS = ("lesson1", "lesson2")


def length(vector: np.ndarray) -> float:
    """Euclidean length: np.linalg.norm's own formula, without its checks (a per-step path)."""
    return math.sqrt(vector.dot(vector))


def check_time_limit(time_limit) -> float:
    """A positive number of seconds, at most ``options.MAX_SECONDS``: NaN or 1e300 would never end
    an episode."""
    return options.seconds("time_limit", time_limit)


@dataclasses.dataclass(frozen=True)
class ReachConfig:
    """Every option of a reaching task, with the paper's values as defaults (:func:`default_config`);
    a lesson sets ``reward`` and ``initial_state``, the training defaults override others.

    reward: ``"lesson1"`` (eq. 9) or ``"lesson2"`` (eq. 10).  initial_state, stored_starts,
    fixed_stored_starts, start_inputs, release_starts, release_time: where episodes start
    (:mod:`~robostrich_suite.tasks.starts`).  target_pool: (n, 2) head positions (x, z) to draw
    targets from (None: :func:`robostrich_suite.targets.training_targets`); target_sampling: how
    (:mod:`~robostrich_suite.tasks.target_samplers`).  position_tolerance, attitude_tolerance: d (m)
    and a (deg) of eqs. 9-10; desired_attitude: the head attitude to hold (deg; 90 = level);
    weights: lambda_1..lambda_4 (a ``RewardWeights`` or a dict of its fields); target_axes: the
    world axes the targets are given in; randomization: a ``DomainRandomization`` (or a dict of
    its fields) drawing new arm parameters every episode, None = off; perturbation: a
    ``perturbations.Perturbation`` (or a dict of its fields), the robot differing from the model by
    the families and scales it names (the robustness tool's and ``--randomize``'s), None = off.
    observe_sent_actions: k > 0 adds the observation ``sent_actions``, the last k actions the agent
    sent (clipped, newest first; at an episode's start the inputs the servos hold): with an
    action latency of up to k control steps the actions still on their way to the servos are then
    in the observation, which the arm's state alone does not show. hindsight_level_goals: an
    agent's hindsight goals (agents/goals.py) only from reached poses whose head was level (within
    the attitude tolerance), goals eq. 10's lessons could set (:meth:`Reach.settable_goals`).
    target_jitter: each drawn target moved by up to this distance (m), uniformly over a disk in the
    targets' plane, so that training meets the poses between the pool's, not the list alone (0: off).
    """
    reward: str = "lesson2"
    initial_state: str = "fixed"
    target_pool: object = None
    position_tolerance: float = POSITION_TOLERANCE
    attitude_tolerance: float = ATTITUDE_TOLERANCE
    desired_attitude: float = DESIRED_ATTITUDE
    weights: object = None
    target_axes: tuple = (0, 2)
    randomization: object = None
    target_sampling: str = "uniform"
    stored_starts: float = 0.0
    start_inputs: object = None
    release_starts: float = 0.0
    release_time: float = RELEASE_TIME
    fixed_stored_starts: float = 0.0
    perturbation: object = None
    observe_sent_actions: int = 0
    hindsight_level_goals: bool = False
    target_jitter: float = 0.0
    target_between: int = 0


MAX_SENT_ACTIONS = 8  # control steps of sent actions an observation may hold
MAX_TARGET_JITTER = 0.05  # m: well inside the spacing of the workspace's far ends
MAX_TARGET_BETWEEN = 16  # nearest neighbours a drawn target may be moved towards


def default_config() -> ReachConfig:
    """The reaching task's options as the paper has them (``dataclasses.replace`` to override)."""
    return ReachConfig()


class Reach(base.Task):
    """Bring the head to a target position (and, from lesson 2, hold it level).

    Built from a :class:`ReachConfig` (default :func:`default_config`) with any of its fields
    overridden by keyword; it composes a :class:`~robostrich_suite.tasks.starts.StartDistribution`
    and a :class:`~robostrich_suite.tasks.target_samplers.TargetSampler`."""

    def __init__(self, config: ReachConfig | None = None, random=None, **overrides):
        config = dataclasses.replace(config or default_config(), **overrides)
        random = options.seed("random", random)
        if config.reward not in REWARDS:
            raise ValueError(f"unknown reward {config.reward!r}; use one of {REWARDS}")
        self.starts = StartDistribution(config.initial_state, config.stored_starts,
                                        config.fixed_stored_starts, config.start_inputs,
                                        config.release_starts, config.release_time)
        pool = config.target_pool
        if pool is None:
            pool = targets.training_targets()
        self.sampler = TargetSampler(pool, config.target_sampling)
        self._set_reward(config)
        self._set_target_axes(config.target_axes)
        randomization = options.instance("randomization", config.randomization,
                                         randomization_lib.DomainRandomization)
        self.randomizer = (randomization_lib.Randomizer(randomization)
                           if randomization is not None else None)
        perturbation = options.instance("perturbation", config.perturbation, perturbations_lib.Perturbation)
        if perturbation is not None and perturbation.active():  # all scales 0: the nominal task
            if self.randomizer is not None:
                raise ValueError("randomization and perturbation both change the robot; set one of them")
            self.randomizer = perturbations_lib.Perturber(perturbation)
        self.observe_sent_actions = options.whole("observe_sent_actions", config.observe_sent_actions, 0,
                                                  MAX_SENT_ACTIONS, "a whole number of control steps")
        self.hindsight_level_goals = options.flag("hindsight_level_goals", config.hindsight_level_goals)
        self.target_jitter = options.number("target_jitter", config.target_jitter, 0.0, MAX_TARGET_JITTER,
                                            f"a distance from 0 to {MAX_TARGET_JITTER:g} m")
        self.target_between = options.whole("target_between", config.target_between, 0, MAX_TARGET_BETWEEN,
                                            "a whole number of nearest neighbours")
        self._sent_actions = None  # (observe_sent_actions, tendons), newest first, see before_step
        self._robot_ready = False  # see _begin_robot
        self.target_position = self.target_pool[0].copy()
        self._last_reached = None
        self._head_reading = None
        self._continues_from_physics = False  # see _continuing_state
        self._next_start = None  # see continue_next_from
        self._action_change = 0.0  # mean |change| of the tendon inputs at the last step (m), see RewardWeights
        super().__init__(random=random)

    def _set_reward(self, config: ReachConfig) -> None:
        """Eq. 9 or 10's name, tolerances, desired attitude and weights, checked."""
        self.position_tolerance = options.number(
            "position_tolerance", config.position_tolerance, 0.0, MAX_TARGET_DISTANCE,
            f"a positive finite distance, at most {MAX_TARGET_DISTANCE:g} m", above=True)
        self.attitude_tolerance = options.number("attitude_tolerance", config.attitude_tolerance, 0.0, 180.0,
                                                 "a positive finite angle, at most 180 deg", above=True)
        self.desired_attitude = options.number("desired_attitude", config.desired_attitude, -360.0, 360.0,
                                               "a finite angle in degrees from -360 to 360")
        weights = options.instance("weights", config.weights, rewards.RewardWeights)
        self.reward_name = config.reward
        self.weights = weights or rewards.RewardWeights()

    def _set_target_axes(self, target_axes) -> None:
        self.target_axes = tuple(target_axes) if isinstance(target_axes, (tuple, list, np.ndarray)) else ()
        if (len(self.target_axes) != 2 or len(set(self.target_axes)) != 2
                or not all(isinstance(a, (int, np.integer)) and 0 <= a <= 2 for a in self.target_axes)):
            raise ValueError(f"target_axes must be two different world axes (0 = x, 1 = y, 2 = z), "
                             f"got {target_axes!r}")
        self._target_axes_index = physics_lib.as_slice(self.target_axes)

    # --- the parts it composes ---------------------------------------------------
    @property
    def initial_state(self) -> str:
        return self.starts.initial_state

    @property
    def start_inputs(self):
        return self.starts.start_inputs

    @property
    def target_sampling(self) -> str:
        return self.sampler.sampling

    @property
    def target_pool(self) -> np.ndarray:
        return self.sampler.pool

    @target_pool.setter
    def target_pool(self, targets) -> None:
        self.set_target_pool(targets)

    @property
    def target_tries(self) -> np.ndarray:
        return self.sampler.tries

    @property
    def target_failures(self) -> np.ndarray:
        return self.sampler.failures

    # --- episode structure -------------------------------------------------
    def initialize_episode(self, physics):
        self._head_reading = None
        self._action_change = 0.0
        if self._samples_failures():  # before anything moves the physics
            self.sampler.record(self._last_reached)
            self._last_reached = None
        if not self._robot_ready:
            self._begin_robot(physics)
        self._robot_ready = False
        self.starts.begin(physics, self.random, self._continuing_state(physics)
                          if self.initial_state == "continue" else None)
        if self.randomizer is not None:
            self.randomizer.begin_actions(physics.arm_control())
        if self.observe_sent_actions:
            self._sent_actions = np.tile(physics.arm_control(), (self.observe_sent_actions, 1))
        self.target_position = self.next_target()
        physics.show_target_of(self)
        super().initialize_episode(physics)
        self._continues_from_physics = True
        self._next_start = None

    def _begin_robot(self, physics) -> None:
        """This episode's robot (randomisation, perturbation); a task that must know it before
        ``initialize_episode`` (the quadruped's trunk height) calls this first, and it is drawn once."""
        if self.randomizer is not None:
            continuing = self.initial_state == "continue" and self._continuing_state(physics) is not None
            self.randomizer.begin_episode(physics, self.random, continuing)
        self._robot_ready = True

    def _continuing_state(self, physics):
        """The state a "continue" episode starts from while ``initialize_episode`` runs: where the
        last episode of this task ended (the physics keeps it at each reset), None before this
        task's first episode, after a divergence or after :meth:`forget_last_state`."""
        if self._next_start is not None:
            return self._next_start
        return physics.state_before_reset if self._continues_from_physics else None

    def continue_next_from(self, state) -> None:
        """The next "continue" episode starts from ``state`` (what ``Physics.continuing_state``
        gave) instead of where the last episode ended: an evaluation that starts many episodes from
        one resting pose brings the arm there once."""
        self._next_start = state

    def _samples_failures(self) -> bool:
        """Whether the next target is drawn by failure rate (and episodes are scored for it)."""
        return self.sampler.by_failures(self.initial_state)

    def set_target_pool(self, targets) -> None:
        """Draw the next episodes' targets from ``targets`` ((n, 2) or one (2,) position):
        an evaluation reuses one compiled environment for many targets this way. The
        failure counts of ``target_sampling="failures"`` start again from zero."""
        self.sampler.set_pool(targets)

    def set_initial_state(self, initial_state: str) -> None:
        """``"fixed"`` or ``"continue"`` from the next episode on (see the module doc)."""
        self.starts.initial_state = check_initial_state(initial_state)

    def forget_last_state(self) -> None:
        """The next "continue" episode starts from the fixed pose (as after a divergence)."""
        self._continues_from_physics = False

    def next_target(self) -> np.ndarray:
        target = self.sampler.draw(self.random, self.initial_state)
        return self.sampler.moved(target, self.random, self.target_between, self.target_jitter)

    # --- checkpoints ----------------------------------------------------------
    def checkpoint_state(self) -> dict:
        """The variables an episode changes, as data, for a checkpoint to resume it exactly
        (agents/robostrich/environment_state.py stores the RNG beside them); the rest is configuration,
        which the constructor rebuilds from the task's options."""
        return {"target_position": self.target_position, "last_reached": self._last_reached,
                "continues_from_physics": self._continues_from_physics, "action_change": self._action_change,
                "initial_state": self.initial_state, "sampler": self.sampler.checkpoint_state(),
                "randomizer": None if self.randomizer is None else self.randomizer.checkpoint_state(),
                "sent_actions": None if self._sent_actions is None else self._sent_actions.copy()}

    def restore_checkpoint_state(self, state: dict) -> None:
        """Continue from :meth:`checkpoint_state`'s variables (ValueError if they do not fit this task)."""
        if (state["randomizer"] is None) != (self.randomizer is None):
            raise ValueError("the stored task state and this task differ in domain randomisation")
        self.target_position = np.array(state["target_position"], np.float64)
        self._last_reached = state["last_reached"]
        self._continues_from_physics = bool(state["continues_from_physics"])
        self._action_change = float(state["action_change"])
        self.set_initial_state(state["initial_state"])
        self.sampler.restore_checkpoint_state(state["sampler"])
        if self.randomizer is not None:
            self.randomizer.restore_checkpoint_state(state["randomizer"])
        sent = state.get("sent_actions")
        self._sent_actions = None if sent is None else np.array(sent, np.float64)
        self._head_reading = None

    def action_spec(self, physics):
        """The tendon contractions (m), named after the tendons; nothing else is actuated."""
        low, high = physics.arm_control_range().T
        return specs.BoundedArray((len(low),), np.float64, low, high,
                                  name="\t".join(physics.tendon_names()))

    def before_step(self, action, physics):
        self._head_reading = None
        if self.weights.action_change:  # the inputs before this step, for the action-change term
            previous = physics.arm_control()
            self._set_action(action, physics)
            self._action_change = float(np.mean(np.abs(physics.arm_control() - previous)))
        else:
            self._set_action(action, physics)

    def _set_action(self, action, physics) -> None:
        controls = physics.arm_control_view()
        if self._sent_actions is not None or self.randomizer is not None:
            action = check_action(action, physics.arm_control_bounds())
        if self._sent_actions is not None:  # the observation's memory of what was sent
            self._sent_actions[1:] = self._sent_actions[:-1]
            self._sent_actions[0] = action
        if self.randomizer is not None:  # an action may reach the servos late (tasks.perturbations)
            action = self.randomizer.delayed(action)
        if controls is None:
            physics.set_arm_control(check_action(action, physics.arm_control_bounds()))
        else:  # checked and clipped straight into the simulation's controls
            check_action(action, physics.arm_control_bounds(), out=controls)

    def after_step(self, physics):
        self._head_reading = None

    def get_termination(self, physics):
        if physics.divergence is not None:
            return 0.0
        return None

    # --- measurements ------------------------------------------------------
    def head_xz(self, physics) -> np.ndarray:
        return physics.head_position()[self._target_axes_index]

    def _read_head(self, physics) -> tuple:
        """(head x-z, attitude in deg, target minus head) for ``get_observation``.
        ``get_reward`` always reads the head afresh and keeps its reading for the
        ``get_observation`` that dm_control calls next in the same step, which uses it once (a
        step or a new episode drops it): the attitude is a step's costliest reading."""
        reading = self._head_reading
        if reading is None:
            head = self.head_xz(physics)
            return head, physics.head_attitude(), self.target_position - head
        self._head_reading = None
        return reading

    def position_error(self, physics) -> float:
        return length(self.target_position - self.head_xz(physics))

    def attitude_error(self, physics) -> float:
        """Signed head attitude error in degrees (positive = head pitched down), in [-180, 180)."""
        return float(physics_lib.attitude_error_deg(physics.head_attitude(), self.desired_attitude))

    def is_success(self, physics) -> bool:
        return self._within_tolerances(self.position_error(physics), self.attitude_error(physics))

    def measure(self, physics) -> Measurement:
        """Everything this task measures now, read once (tasks/measurement.py): the errors and
        success by the same functions as ``get_reward``, ``is_success`` and the observation."""
        head = self.head_xz(physics)
        position_error = length(self.target_position - head)
        attitude = physics.head_attitude()
        attitude_error = float(physics_lib.attitude_error_deg(attitude, self.desired_attitude))
        return Measurement(position_error, attitude_error,
                           is_success=bool(self._within_tolerances(position_error, attitude_error)),
                           position_tolerance=float(self.position_tolerance),
                           attitude_tolerance=float(self.attitude_tolerance),
                           target=self.target_position, head_position=head, head_attitude=float(attitude),
                           target_in_world=self.target_in_world(physics), head_in_world=physics.head_position())

    def target_in_world(self, physics) -> np.ndarray:
        """The target as a world point (x, y, z): its two components on ``target_axes``, 0 on the third."""
        point = np.zeros(3)
        point[list(self.target_axes)] = self.target_position
        return point

    def _within_tolerances(self, position_error: float, attitude_error_deg: float | None = None) -> bool:
        """Within the position tolerance and, where an attitude error is given, the attitude one:
        the one success rule of ``is_success`` and of failure sampling's judgement."""
        return position_error <= self.position_tolerance and (
            attitude_error_deg is None or abs(attitude_error_deg) <= self.attitude_tolerance)

    # --- hindsight goals ------------------------------------------------------
    # What an agent needs to put another goal into an observation and recompute the reward for
    # it (agents/goals.py): the goal, the head position it is compared with (these components of
    # it: all on the frame, (forward, up) on the quadruped) and their difference ...
    ACHIEVED_COMPONENTS = None

    def goal_spec(self) -> dict:
        return {"goal": "target_position", "achieved": "head_position",
                "achieved_components": self.ACHIEVED_COMPONENTS, "goal_delta": "to_target"}

    def achieved_goal(self, observation) -> np.ndarray:
        """... and what a control step reached: the head position compared with the goal, then
        the attitude error (deg) eq. 10 reads, from its observation entries."""
        head = observation["head_position"]
        head = head if self.ACHIEVED_COMPONENTS is None else head[list(self.ACHIEVED_COMPONENTS)]
        return np.concatenate([head, np.degrees(observation["attitude_error"])])

    def settable_goals(self, reached):
        """Which reached poses (..., 3) are goals this task could set, under the option
        ``hindsight_level_goals``: those within the attitude tolerance where the reward asks for
        a level head (not in lesson 1: eq. 9 ignores the attitude). None: every one."""
        if not self.hindsight_level_goals or self.reward_name == "lesson1":
            return None
        return np.abs(reached[..., 2]) <= self.attitude_tolerance

    def has_goal_free_reward(self) -> bool:
        """Whether this task's reward holds a part no goal changes (the inputs' change charged in
        eq. 10's lessons): the replay keeps it through hindsight goals and recomputed rewards."""
        return self.reward_name != "lesson1" and bool(self.weights.action_change)

    def goal_reward(self, reached, goal) -> np.ndarray:
        """The reward this task gives with the head at ``reached[..., :2]``, its attitude
        ``reached[..., 2]`` deg off (:meth:`achieved_goal`), had the target been ``goal`` (..., 2):
        eqs. 9-10 on arrays, equal to :meth:`get_reward` for the real target (no divergence)."""
        achieved, attitude_error_deg = reached[..., :2], reached[..., 2]
        error = np.linalg.norm(np.asarray(goal) - np.asarray(achieved), axis=-1)
        if self.reward_name == "lesson1":
            return rewards.lesson1_rewards(error, self.position_tolerance)
        return rewards.lesson2_rewards(error, attitude_error_deg, self.position_tolerance,
                                       self.attitude_tolerance, self.weights)

    # --- dm_control Task API ------------------------------------------------
    def get_observation(self, physics):
        """Table 2 (head position, head velocity, joint angles) + goal + tendon state.

        Units are chosen so that every entry is of order one: metres, m/s,
        radians, and tendon forces as a fraction of the actuator's limit.
        """
        obs = {}  # ordered by insertion, as dm_control's specs and our flattener read it (an
        # OrderedDict costs about a microsecond more per step)
        head, attitude, to_target = self._read_head(physics)
        obs["head_position"] = head
        obs["head_velocity"] = physics.head_velocity()[self._target_axes_index]
        joint_angles = physics.joint_angles()
        if self.randomizer is not None:
            joint_angles = self.randomizer.observe_joint_angles(joint_angles, self.random)
        obs["joint_angles"] = joint_angles
        obs["target_position"] = self.target_position.copy()
        obs["to_target"] = to_target
        attitude_error = physics_lib.attitude_error_deg(attitude, self.desired_attitude)
        obs["attitude_error"] = np.array([math.radians(attitude_error)])
        obs["head_attitude"] = np.array([math.radians(attitude)])
        obs["tendon_contraction"] = physics.tendon_contractions()
        obs["tendon_tension"] = physics.tendon_tensions()
        if self.observe_sent_actions:  # before the first episode: the inputs the servos hold
            obs["sent_actions"] = (np.tile(physics.arm_control(), self.observe_sent_actions)
                                   if self._sent_actions is None else self._sent_actions.ravel().copy())
        return obs

    def get_reward(self, physics):
        """Eq. 9 or 10 on this step's head reading; with failure sampling it also judges, on the
        same reading, whether the pose does what the lesson asks (the episode's last step's
        judgement scores its target)."""
        if physics.divergence is not None:
            self._last_reached = None
            return -2.0 if self.reward_name == "lesson1" else -2.0 * self.weights.largest_penalty
        head = self.head_xz(physics)
        to_target = self.target_position - head
        attitude = physics.head_attitude()
        self._head_reading = head, attitude, to_target
        error = length(to_target)  # position_error, on this reading
        if self.reward_name == "lesson1":
            if self._samples_failures():
                self._last_reached = self._within_tolerances(error)  # eq. 9 asks for the position alone
            return rewards.lesson1_reward(error, self.position_tolerance)
        attitude_error = physics_lib.attitude_error_deg(attitude, self.desired_attitude)
        if self._samples_failures():
            self._last_reached = self._within_tolerances(error, attitude_error)
        reward = rewards.lesson2_reward(error, attitude_error, self.position_tolerance, self.attitude_tolerance,
                                        self.weights)
        if self.weights.action_change:
            reward -= self.weights.action_change * self._action_change
        if self.weights.head_vertical_speed and error <= self.position_tolerance:  # holding, not reaching
            reward -= self.weights.head_vertical_speed * abs(float(physics.head_velocity()[2]))
        return reward
