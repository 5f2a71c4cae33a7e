"""Where a reaching episode starts (paper Sec. 3.2 and the additions to it).

* ``"fixed"``: the straight, upright pose at rest (lessons 1 and 2);
* ``"continue"``: the final state of the previous episode (lesson 3), so the agent learns to
  move between targets; the first episode, and any episode after a divergence, starts fixed.

Shares of the episodes may start elsewhere: ``stored_starts`` (of a ``"continue"`` lesson's)
where the arm comes to rest holding one of ``start_inputs`` (stored level poses), so the agent
also learns to leave poses it would never reach by itself; ``release_starts`` (of those that
continue) after every tendon was released (zero contraction) for a random time up to
``release_time``, the states a neck passes through while it uncurls; ``fixed_stored_starts`` (of
a ``"fixed"`` lesson's) from a stored pose as well, so what lessons 1-2 hand to lesson 3 already
holds moves out of lesson 3's starts.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from robostrich_suite.tasks import options
from robostrich_suite.tasks.actions import check_action

INITIAL_STATES = ("fixed", "continue")
# How long a stored start holds its inputs from the fixed pose before the episode begins: as
# long as the evaluation's moving starts hold theirs (one 2 s episode), so the arm is at rest.
STORED_START_SETTLE_TIME = 2.0  # s
RELEASE_TIME = 1.0  # s: releasing a neck curled back by a turn brings it up to level in 0.8 s
MAX_TENDON_INPUT = 1.0  # m: a stored pose's tendon input (the arm's inputs are centimetres)


def check_initial_state(initial_state: str) -> str:
    if initial_state not in INITIAL_STATES:
        raise ValueError(f"unknown initial_state {initial_state!r}; use one of {INITIAL_STATES}")
    return initial_state


@dataclasses.dataclass
class StartDistribution:
    """How each episode's first state is drawn (module doc); ``begin`` puts the physics there."""
    initial_state: str = "fixed"
    stored_starts: float = 0.0
    fixed_stored_starts: float = 0.0
    start_inputs: np.ndarray | None = None
    release_starts: float = 0.0
    release_time: float = RELEASE_TIME

    def __post_init__(self):
        check_initial_state(self.initial_state)
        for name in ("stored_starts", "fixed_stored_starts", "release_starts"):
            setattr(self, name, options.share(name, getattr(self, name)))
        if self.start_inputs is not None:
            what = f"a non-empty (n, tendons) array of finite tendon inputs within {MAX_TENDON_INPUT:g} m"
            inputs = options.array("start_inputs", self.start_inputs, what)
            if (inputs.ndim != 2 or len(inputs) == 0 or not np.all(np.isfinite(inputs))
                    or np.any(np.abs(inputs) > MAX_TENDON_INPUT)):
                raise ValueError(f"start_inputs must be {what}, got shape {inputs.shape}")
            self.start_inputs = inputs
        elif self.stored_starts > 0 or self.fixed_stored_starts > 0:
            name = "stored_starts" if self.stored_starts > 0 else "fixed_stored_starts"
            raise ValueError(f"{name} > 0 needs start_inputs: the (n, tendons) tendon inputs "
                             "of the stored poses to start from")
        self.release_time = options.number("release_time", self.release_time, 0.0, options.MAX_SECONDS,
                                           f"a positive finite time in seconds, at most {options.MAX_SECONDS:g}",
                                           above=True)

    def begin(self, physics, random, continuing_state) -> None:
        """Put ``physics`` (just reset to the fixed pose) at this episode's start, drawing from
        ``random``; ``continuing_state`` is where the last episode ended (None: none to continue)."""
        if self.initial_state == "continue":
            if self.stored_starts and random.rand() < self.stored_starts:
                self._settle_at_stored_input(physics, random)
            elif continuing_state is not None:
                restore_state(physics, continuing_state)
                if self.release_starts and random.rand() < self.release_starts:
                    released = np.zeros(len(physics.arm_control_bounds()[0]))  # every tendon at rest length
                    hold_before_episode(physics, released, random.uniform(0.0, self.release_time))
        elif self.fixed_stored_starts and random.rand() < self.fixed_stored_starts:
            self._settle_at_stored_input(physics, random)

    def _settle_at_stored_input(self, physics, random) -> None:
        """Hold one of ``start_inputs`` from the fixed pose until the arm is at rest, as the
        evaluation's moving starts do; the episode's clock then starts at 0."""
        inputs = self.start_inputs[random.randint(len(self.start_inputs))]
        hold_before_episode(physics, inputs, STORED_START_SETTLE_TIME)


def hold_before_episode(physics, inputs, seconds: float) -> None:
    """Hold tendon ``inputs`` for ``seconds`` before an episode (stored and release starts); its
    clock then starts at 0.  A divergence meanwhile puts back the state before the hold (the
    divergence is logged like any other)."""
    steps = int(round(seconds / physics.timestep()))
    if steps < 1:
        return
    before = (physics.data.qpos.copy(), physics.data.qvel.copy(), physics.data.act.copy(),
              physics.arm_control())
    physics.set_arm_control(check_action(inputs, physics.arm_control_bounds()))
    physics.step(steps)
    if physics.divergence is not None:
        physics.divergence = None
        restore_state(physics, before)
    physics.data.time = 0.0


def restore_state(physics, state) -> None:
    """Put the arm in ``state``, (qpos, qvel, act, tendon command), its servos keeping their command."""
    qpos, qvel, act, command = state
    with physics.reset_context():
        physics.data.qpos[:] = qpos
        physics.data.qvel[:] = qvel
        if act.size:
            physics.data.act[:] = act
        physics.set_arm_control(command)  # the servos keep their command, as a real arm's would
