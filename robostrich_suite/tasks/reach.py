"""Reaching tasks for any domain whose Physics has the arm accessors.

``Reach`` is one curriculum lesson (paper Sec. 3.2): lesson 1 rewards only the
position (eq. 9); lessons 2 and 3 reward position and head attitude (eq. 10).
They differ in how an episode starts:

* ``"fixed"``: the straight, upright pose at rest (lessons 1 and 2);
* ``"continue"``: the final state of the previous episode (lesson 3), so the
  agent learns to move between targets; the first episode, and any episode
  after a divergence, starts fixed.  With ``stored_starts`` > 0, that share of
  the episodes starts instead where the arm comes to rest holding one of
  ``start_inputs`` (stored level poses), so the agent also learns to leave
  poses it would never reach by itself.  With ``release_starts`` > 0, that share
  of the episodes starts after the arm, from the last episode's final state, had
  every tendon released (zero contraction) for a random time up to
  ``release_time``: the states a neck passes through while it uncurls, which a
  policy that holds its inputs never visits.  With ``fixed_stored_starts`` > 0,
  that share of a ``"fixed"`` lesson's episodes (lessons 1-2) starts from a stored
  pose as well, so what lessons 1-2 hand to lesson 3 already holds moves out of
  lesson 3's starts (a neck uncurling among them).

``Track`` is the evaluation task of Fig. 7: a sequence of targets reached in
order, one after another, within one episode.

Actions are tendon contractions (m); values outside the action spec are
clipped to it, a NaN action raises ``ValueError``.  A physics divergence ends
the episode (discount 0) and is logged, instead of raising from the step.
"""
from __future__ import annotations

import math

import numpy as np
from dm_control.suite import base
from dm_env import specs

from robostrich_suite import physics as physics_lib
from robostrich_suite.tasks import randomization as randomization_lib
from robostrich_suite.tasks import rewards
from robostrich_suite.tasks.conventions import LEVEL_ATTITUDE_DEG as DESIRED_ATTITUDE
from robostrich_suite.tasks.conventions import LEVEL_TOLERANCE_DEG as ATTITUDE_TOLERANCE
from robostrich_suite.tasks.conventions import POSITION_TOLERANCE

INITIAL_STATES = ("fixed", "continue")
REWARDS = ("lesson1", "lesson2")
# How the next target is drawn from the pool: "uniform" (the paper), or "failures": each
# target in proportion to its estimated failure rate, (failures + 1) / (tries + 2), judged
# on the previous episode's final pose against what the lesson's reward asks for;
# "continue_failures": "failures" in lessons whose episodes continue from the last pose (lesson 3),
# "uniform" in fixed-start ones, so one option leaves lessons 1-2 the paper's.
TARGET_SAMPLINGS = ("uniform", "failures", "continue_failures")
# How long a stored start holds its inputs from the fixed pose before the episode begins: as
# long as the evaluation's moving starts hold theirs (one 2 s episode), so the arm is at rest.
STORED_START_SETTLE_TIME = 2.0  # s
RELEASE_TIME = 1.0  # s: releasing a neck curled back by a turn brings it up to level in 0.8 s


def _real_vector(action, size: int) -> np.ndarray:
    """``action`` as an array of ``size`` real numbers (not copied), or a ValueError naming
    what was expected and what came (a scalar must not silently drive every tendon, nor 8
    values fail deep inside numpy)."""
    array = np.asarray(action)
    if array.dtype.kind not in "iuf":  # not bool, complex, str, object (None), ...
        raise ValueError(f"action must be {size} real numbers (float), got dtype {array.dtype} "
                         f"({type(action).__name__})")
    if array.shape != (size,):
        raise ValueError(f"action must have shape ({size},), got shape {array.shape}")
    return array


def validate_action(action, size: int) -> np.ndarray:
    """``action`` as a new float64 vector of ``size`` real numbers, or a ValueError naming what
    was expected and what came."""
    return _real_vector(action, size).astype(np.float64)


def _hold_before_episode(physics, inputs, seconds: float) -> None:
    """Hold tendon ``inputs`` for ``seconds`` before an episode (stored and release starts); its
    clock then starts at 0.  A divergence meanwhile leaves the fixed pose (logged like any other)."""
    steps = int(round(seconds / physics.timestep()))
    if steps < 1:
        return
    physics.set_arm_control(check_action(inputs, physics.arm_control_bounds()))
    physics.step(steps)
    if physics.divergence is not None:
        physics.reset()
    physics.data.time = 0.0


def _length(vector: np.ndarray) -> float:
    """Euclidean length: np.linalg.norm's own formula, without its checks (a per-step path)."""
    return math.sqrt(vector.dot(vector))


MAX_TARGET_DISTANCE = 1.5  # m from the origin of the targets' frame: no arm reaches farther


def as_targets(targets, name: str) -> np.ndarray:
    """(n, 2) finite head positions (x, z); one (2,) position is one target. Anything else (a
    (4, 3) or (1, 4) array) is an error, not silently reshaped into other targets."""
    array = np.asarray(targets, dtype=np.float64)
    if array.shape == (2,):
        array = array[None]
    if array.ndim != 2 or array.shape[1] != 2 or len(array) == 0:
        raise ValueError(f"{name} must be a non-empty (n, 2) array of (x, z) positions, got shape {array.shape}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must hold finite positions")
    far = np.flatnonzero(np.linalg.norm(array, axis=1) > MAX_TARGET_DISTANCE)
    if far.size:
        raise ValueError(f"{name} holds {far.size} position(s) far outside any workspace, e.g. {array[far[0]].tolist()}: "
                         f"more than {MAX_TARGET_DISTANCE} m from the origin (the arm is 0.67 m long, its base "
                         "within 0.5 m of the frame's and the trunk's origin)")
    return array


def check_time_limit(time_limit) -> float:
    """A positive number of seconds (inf: no limit); NaN would never end an episode."""
    if not (float(time_limit) > 0):
        raise ValueError(f"time_limit must be positive seconds (or inf), got {time_limit}")
    return float(time_limit)


def check_action(action: np.ndarray, bounds, out: np.ndarray | None = None) -> np.ndarray:
    """Reject actions of the wrong shape or type and NaN/inf; clip the rest into ``bounds``,
    the (low, high) arrays ``physics.arm_control_bounds()`` gives.  The clipped action goes
    into ``out`` where given (the simulation's controls: the per-step path), else a new array;
    nothing is written unless the action is valid."""
    low, high = bounds
    array = _real_vector(action, len(low))
    # One dot product is finite when every entry is (and small enough that squares stay
    # finite, which real tendon inputs are); only otherwise look at each entry.
    if not math.isfinite(array.dot(array)):
        finite = np.isfinite(array)
        if not finite.all():
            bad = np.flatnonzero(~finite).tolist()
            raise ValueError(f"action has non-finite values at indices {bad}: {array}")
    # np.clip's result (in float64 whatever came), by two in-place steps: a third of its cost
    if out is None:
        out = np.empty(len(low))
    np.maximum(array, low, out=out)
    return np.minimum(out, high, out=out)


class Reach(base.Task):
    """Bring the head to a target position (and, from lesson 2, hold it level)."""

    # Class-level defaults, so that an environment pickled before target sampling existed
    # (a checkpoint's) still unpickles into a working task.
    target_sampling = "uniform"
    _target_index = None
    _last_reached = None
    stored_starts = 0.0
    fixed_stored_starts = 0.0
    start_inputs = None
    release_starts = 0.0
    release_time = RELEASE_TIME
    _head_reading = None
    _continues_from_physics = False  # see _continuing_state
    _action_change = 0.0  # mean |change| of the tendon inputs at the last step (m), see RewardWeights

    def __init__(self, reward: str = "lesson2", initial_state: str = "fixed",
                 target_pool=None, position_tolerance: float = POSITION_TOLERANCE,
                 attitude_tolerance: float = ATTITUDE_TOLERANCE,
                 desired_attitude: float = DESIRED_ATTITUDE,
                 weights: rewards.RewardWeights | dict | None = None,
                 target_axes=(0, 2), randomization=None, target_sampling: str = "uniform",
                 stored_starts: float = 0.0, start_inputs=None, release_starts: float = 0.0,
                 release_time: float = RELEASE_TIME, fixed_stored_starts: float = 0.0, random=None):
        """
        Args:
          reward: ``"lesson1"`` (eq. 9) or ``"lesson2"`` (eq. 10).
          initial_state: ``"fixed"`` or ``"continue"`` (see the module doc).
          target_pool: (n, 2) head positions (x, z) to draw targets from; defaults
            to :func:`robostrich_suite.targets.training_targets`.
          position_tolerance, attitude_tolerance: d (m) and a (deg) of eqs. 9-10.
          desired_attitude: head attitude to hold (deg; 90 = level).
          weights: lambda_1..lambda_4 (a ``RewardWeights`` or a dict of its fields).
          target_axes: world axes of the head position the targets are given in.
          randomization: a ``DomainRandomization`` (or a dict of its fields) to draw
            new arm parameters every episode and add joint-angle noise; None = off.
          target_sampling: ``"uniform"``, ``"failures"`` (targets the agent misses are
            drawn more often) or ``"continue_failures"`` (that, in ``"continue"`` lessons
            only); see ``TARGET_SAMPLINGS``.
          stored_starts: share (0-1) of a ``"continue"`` lesson's episodes that start where
            the arm comes to rest holding one of ``start_inputs`` (drawn uniformly) from the
            fixed pose for ``STORED_START_SETTLE_TIME``; 0 (default): the paper's lesson 3.
            Ignored by ``"fixed"`` lessons, so one option can serve a whole curriculum.
          start_inputs: (n, tendons) tendon inputs for ``stored_starts`` and
            ``fixed_stored_starts`` (the agent layer passes the lookup table's, minus the
            evaluation's start poses).
          release_starts: share (0-1) of a ``"continue"`` lesson's episodes (those that
            continue from the last state) that start after every tendon was released for a
            uniformly drawn time in [0, ``release_time``] s; 0 (default): the paper's lesson 3.
          fixed_stored_starts: share (0-1) of a ``"fixed"`` lesson's episodes that start
            from a stored pose as ``stored_starts`` ones do; 0 (default): the paper's
            lessons 1-2. Ignored by ``"continue"`` lessons.
        """
        if reward not in REWARDS:
            raise ValueError(f"unknown reward {reward!r}; use one of {REWARDS}")
        if initial_state not in INITIAL_STATES:
            raise ValueError(f"unknown initial_state {initial_state!r}; use one of {INITIAL_STATES}")
        if target_sampling not in TARGET_SAMPLINGS:
            raise ValueError(f"unknown target_sampling {target_sampling!r}; use one of {TARGET_SAMPLINGS}")
        if target_pool is None:
            from robostrich_suite import targets
            target_pool = targets.training_targets()
        target_pool = as_targets(target_pool, "target_pool")
        for name, value in (("position_tolerance", position_tolerance), ("attitude_tolerance", attitude_tolerance)):
            if not (np.isfinite(value) and value > 0):
                raise ValueError(f"{name} must be a positive finite number, got {value}")
        if not np.isfinite(desired_attitude):
            raise ValueError(f"desired_attitude must be a finite angle in degrees, got {desired_attitude}")
        if isinstance(weights, dict):
            weights = rewards.RewardWeights(**weights)
        for name, share in (("stored_starts", stored_starts), ("fixed_stored_starts", fixed_stored_starts)):
            if not (np.isfinite(share) and 0.0 <= share <= 1.0):
                raise ValueError(f"{name} must be a share between 0 and 1, got {share}")
        if stored_starts > 0 or fixed_stored_starts > 0:
            if start_inputs is None:
                name = "stored_starts" if stored_starts > 0 else "fixed_stored_starts"
                raise ValueError(f"{name} > 0 needs start_inputs: the (n, tendons) tendon inputs "
                                 "of the stored poses to start from")
            start_inputs = np.asarray(start_inputs, np.float64)
            if start_inputs.ndim != 2 or len(start_inputs) == 0 or not np.all(np.isfinite(start_inputs)):
                raise ValueError("start_inputs must be a non-empty (n, tendons) array of finite tendon "
                                 f"inputs, got shape {start_inputs.shape}")
        if not (np.isfinite(release_starts) and 0.0 <= release_starts <= 1.0):
            raise ValueError(f"release_starts must be a share between 0 and 1, got {release_starts}")
        if not (np.isfinite(release_time) and release_time > 0):
            raise ValueError(f"release_time must be a positive finite time in seconds, got {release_time}")
        self.stored_starts = float(stored_starts)
        self.fixed_stored_starts = float(fixed_stored_starts)
        self.release_starts = float(release_starts)
        self.release_time = float(release_time)
        self.start_inputs = start_inputs
        self.reward_name = reward
        self.initial_state = initial_state
        self.target_sampling = target_sampling
        self.set_target_pool(target_pool)
        self.position_tolerance = float(position_tolerance)
        self.attitude_tolerance = float(attitude_tolerance)
        self.desired_attitude = float(desired_attitude)
        self.weights = weights or rewards.RewardWeights()
        self.target_axes = tuple(target_axes)
        if (len(self.target_axes) != 2 or len(set(self.target_axes)) != 2
                or not all(isinstance(a, (int, np.integer)) and 0 <= a <= 2 for a in self.target_axes)):
            raise ValueError(f"target_axes must be two different world axes (0 = x, 1 = y, 2 = z), "
                             f"got {target_axes!r}")
        self._target_axes_index = physics_lib.as_slice(self.target_axes)
        if isinstance(randomization, dict):
            randomization = randomization_lib.DomainRandomization(**randomization)
        self.randomizer = (randomization_lib.Randomizer(randomization)
                           if randomization is not None else None)
        self.target_position = self.target_pool[0].copy()
        super().__init__(random=random)

    # --- episode structure -------------------------------------------------
    def initialize_episode(self, physics):
        self._head_reading = None
        self._action_change = 0.0
        if self._samples_failures():  # before anything moves the physics
            self._count_previous_episode()
        if self.randomizer is not None:
            self.randomizer.apply(physics, self.random)
        if self.initial_state == "continue":
            last_state = self._continuing_state(physics)
            if self.stored_starts and self.random.rand() < self.stored_starts:
                self._settle_at_stored_input(physics)
            elif last_state is not None:
                self._restore_state(physics, last_state)
                if self.release_starts and self.random.rand() < self.release_starts:
                    released = np.zeros(len(physics.arm_control_bounds()[0]))  # every tendon at rest length
                    _hold_before_episode(physics, released, self.random.uniform(0.0, self.release_time))
        elif self.fixed_stored_starts and self.random.rand() < self.fixed_stored_starts:
            self._settle_at_stored_input(physics)
        self.target_position = self.next_target()
        super().initialize_episode(physics)
        self._continues_from_physics = True

    def _continuing_state(self, physics):
        """The state a "continue" episode starts from while ``initialize_episode`` runs: where the
        last episode of this task ended (the physics keeps it at each reset), None before this
        task's first episode, after a divergence or after :meth:`forget_last_state`."""
        return physics.state_before_reset if self._continues_from_physics else None

    def __setstate__(self, state):
        # A task pickled before the physics kept the pre-reset state (an older checkpoint's)
        # held it as _last_state; its physics unpickles in that state, so continue from it.
        if "_last_state" in state:
            state["_continues_from_physics"] = state.pop("_last_state") is not None
        self.__dict__.update(state)

    @staticmethod
    def _restore_state(physics, last_state):
        qpos, qvel, act, command = last_state
        with physics.reset_context():
            physics.data.qpos[:] = qpos
            physics.data.qvel[:] = qvel
            if act.size:
                physics.data.act[:] = act
            physics.set_arm_control(command)  # the servos keep their command, as a real arm's would

    def _settle_at_stored_input(self, physics):
        """Hold one of ``start_inputs`` from the fixed pose until the arm is at rest, as the
        evaluation's moving starts do; the episode's clock then starts at 0.  A divergence
        while settling leaves the fixed pose (and is logged like any other)."""
        inputs = self.start_inputs[self.random.randint(len(self.start_inputs))]
        _hold_before_episode(physics, inputs, STORED_START_SETTLE_TIME)

    def _count_previous_episode(self):
        """Score the episode that just ended for ``target_sampling="failures"``: whether its
        final pose (judged by ``get_reward``) did what the lesson asks."""
        if self._target_index is not None and self._last_reached is not None:
            self.target_tries[self._target_index] += 1
            self.target_failures[self._target_index] += not self._last_reached
        self._last_reached = None

    def _samples_failures(self) -> bool:
        """Whether the next target is drawn by failure rate (and episodes are scored for it)."""
        return self.target_sampling == "failures" or (
            self.target_sampling == "continue_failures" and self.initial_state == "continue")

    def set_target_pool(self, targets) -> None:
        """Draw the next episodes' targets from ``targets`` ((n, 2) or one (2,) position):
        an evaluation reuses one compiled environment for many targets this way. The
        failure counts of ``target_sampling="failures"`` start again from zero."""
        self.target_pool = as_targets(targets, "target_pool")
        self.target_tries = np.zeros(len(self.target_pool), np.int64)
        self.target_failures = np.zeros(len(self.target_pool), np.int64)
        self._target_index = None

    def set_initial_state(self, initial_state: str) -> None:
        """``"fixed"`` or ``"continue"`` from the next episode on (see the module doc)."""
        if initial_state not in INITIAL_STATES:
            raise ValueError(f"unknown initial_state {initial_state!r}; use one of {INITIAL_STATES}")
        self.initial_state = initial_state

    def forget_last_state(self) -> None:
        """The next "continue" episode starts from the fixed pose (as after a divergence)."""
        self._continues_from_physics = False

    def next_target(self) -> np.ndarray:
        if self._samples_failures():
            failure_rate = (self.target_failures + 1.0) / (self.target_tries + 2.0)
            self._target_index = int(self.random.choice(len(self.target_pool),
                                                        p=failure_rate / failure_rate.sum()))
        else:
            self._target_index = int(self.random.randint(len(self.target_pool)))
        return self.target_pool[self._target_index].copy()

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
        return _length(self.target_position - self.head_xz(physics))

    def attitude_error(self, physics) -> float:
        """Signed head attitude error in degrees (positive = head pitched down), in [-180, 180)."""
        return float(physics_lib.attitude_error_deg(physics.head_attitude(), self.desired_attitude))

    def is_success(self, physics) -> bool:
        return self._within_tolerances(self.position_error(physics), self.attitude_error(physics))

    def _within_tolerances(self, position_error: float, attitude_error_deg: float | None = None) -> bool:
        """Within the position tolerance and, where an attitude error is given, the attitude one:
        the one success rule of ``is_success`` and of failure sampling's judgement."""
        return position_error <= self.position_tolerance and (
            attitude_error_deg is None or abs(attitude_error_deg) <= self.attitude_tolerance)

    # --- hindsight goals ------------------------------------------------------
    # The observation keys an agent needs to put another goal into an observation
    # (agents/goals.py): the goal, the achieved position it is compared with, and
    # their difference.
    GOAL_OBSERVATION = "target_position"
    ACHIEVED_OBSERVATION = "head_position"
    GOAL_DELTA_OBSERVATION = "to_target"
    ATTITUDE_ERROR_OBSERVATION = "attitude_error"  # rad

    def goal_attitude_tolerance(self):
        """How far from level (deg) a reached pose may be for its position to be a goal this
        task could set: the attitude tolerance where the reward asks for a level head, None
        in lesson 1 (eq. 9 ignores the attitude, so every reached position is one)."""
        return None if self.reward_name == "lesson1" else self.attitude_tolerance

    def goal_reward(self, achieved, attitude_error_deg, goal) -> np.ndarray:
        """The reward this task gives with the head at ``achieved`` (..., 2), its attitude
        ``attitude_error_deg`` (...) off, had the target been ``goal`` (..., 2): eqs. 9-10
        on arrays, equal to :meth:`get_reward` for the real target (no divergence)."""
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
        error = _length(to_target)  # position_error, on this reading
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
        return reward


class Track(Reach):
    """Reach ``targets`` in order, ``steps_per_target`` control steps each (Fig. 7)."""

    def __init__(self, targets=None, steps_per_target: int = 250, **kwargs):
        if targets is None:
            from robostrich_suite import targets as targets_lib
            targets = default_track_targets(targets_lib.heldout_targets())
        targets = as_targets(targets, "targets")
        if isinstance(steps_per_target, bool) or int(steps_per_target) != steps_per_target or steps_per_target < 1:
            raise ValueError(f"steps_per_target must be a whole number of control steps >= 1, got {steps_per_target}")
        kwargs.setdefault("reward", "lesson2")
        super().__init__(target_pool=targets, **kwargs)
        self.targets = targets
        self.steps_per_target = int(steps_per_target)
        self.target_index = 0
        self._step = 0

    def initialize_episode(self, physics):
        self._step = 0
        self.target_index = 0
        super().initialize_episode(physics)
        # dm_control's base Task calls after_step once while initialising: that is no step of
        # the episode, so the first target keeps its full steps_per_target.
        self._step = 0
        if self.target_index != 0:
            self.target_index = 0
            self.target_position = self.targets[0].copy()

    def next_target(self) -> np.ndarray:
        return self.targets[self.target_index].copy()

    def after_step(self, physics):
        super().after_step(physics)
        self._step += 1
        index = self.active_target_index(physics)
        if index != self.target_index:
            self.target_index = index
            self.target_position = self.targets[index].copy()

    def active_target_index(self, physics) -> int:
        """The target after this step: by time, ``steps_per_target`` control steps each
        (a subclass may switch on something else, e.g. ``NarrowGap(switch="reached")``)."""
        return min(self._step // self.steps_per_target, len(self.targets) - 1)

    def get_observation(self, physics):
        obs = super().get_observation(physics)
        obs["position_error"] = np.array([_length(obs["to_target"])])  # position_error, same reading
        obs["target_index"] = np.array([float(self.target_index)])
        return obs


def default_track_targets(pool: np.ndarray, count: int = 3) -> np.ndarray:
    """Three well-separated targets from ``pool``: far forward-low, high, and middle.

    Deterministic, so every evaluation of ``track`` sees the same sequence.
    """
    pool = np.asarray(pool)
    order = [np.argmax(pool[:, 0] - pool[:, 1]),  # forward and low
             np.argmax(pool[:, 1]),  # highest
             np.argmin(np.linalg.norm(pool - pool.mean(0), axis=1))]  # central
    return pool[order[:count]]
