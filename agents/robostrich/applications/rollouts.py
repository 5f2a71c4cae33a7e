"""What the two application evaluations (Sec. 5.2) share: the policies compared, the gait of
each seed and a rollout that records what each evaluation asks for.

Why one place: `head_stabilize` (agents/robostrich/applications/stabilization.py) and `narrow_gap` (agents/robostrich/applications/narrow_gap.py)
compare the same policies on `robostrich_a1` -- a trained checkpoint, optionally a second
one (e.g. lessons 1-3 without lesson 4), zero tendon input and the no-learning lookup
(agents/robostrich/lookup.py) -- over the same seeds.

Seeds are gait phases.  Both tasks are deterministic given the gait (one fixed target or
sub-target list, a fixed start), so seed ``k`` of ``n`` starts the gait ``k / (2 n)`` of its
period later (:class:`PhaseShifted`); the policies are deterministic too.  Half a period,
not a whole one: the second half of a trot is the first with the diagonal leg pairs
swapped, a mirror image that gives the same numbers (measured: identical to 5 digits).

Rerun recordings log every ``RECORD_EVERY``-th control step (25 frames per second of
simulated time): every step of a 12 s walk is ~14 MB and ~13 s of logging.
"""
import dataclasses
from typing import Callable, Optional

import numpy as np

from agents.replay import ObservationFlattener
from agents.robostrich.domains import as_domain, Domain
from agents.robostrich.evaluate.evaluation import load_run_from_checkpoint
from agents.robostrich.lookup import LABEL, LookupPolicy
from agents.robostrich.recording import open_recorder
from agents.sac.builder import SACBuilder
from robostrich_suite import cli as cli_lib
from robostrich_suite.tasks import gait as gait_lib
from robostrich_suite.tasks.measurement import measure

DOMAIN = "robostrich_a1"
RECORD_EVERY = 5  # control steps per recorded frame (module doc)


@dataclasses.dataclass
class Policy:
    """A policy to compare: `make_actor(env, flattener)` gives an object with
    `select_action(flat_obs)`; it reads observations with `flattener` (a trained policy's own;
    None: the environment's) and acts every `action_repeat` control steps on `domain`."""
    label: str
    domain: Domain
    make_actor: Callable
    flattener: Optional[object] = None
    action_repeat: int = 1

    def bind(self, env):
        """(actor, flattener) for `env`."""
        spec = env.observation_spec()
        flattener = self.flattener or ObservationFlattener(spec)
        missing = [key for key in (flattener.keys or ()) if key not in spec]
        if missing:
            raise ValueError(f"policy {self.label!r} reads observations {missing} that "
                             f"{self.domain.name} task {type(env.task).__name__} does not have")
        return self.make_actor(env, flattener), flattener


class ZeroInput:
    """No tendon contraction at all: the arm hangs on its passive joints (the paper's baseline of
    doing nothing; with it the neck tips forward while walking)."""

    def __init__(self, size: int):
        self.action = np.zeros(size)

    def select_action(self, flat_obs) -> np.ndarray:
        return self.action.copy()


def zero_policy(domain: Domain) -> Policy:
    return Policy("zero", domain, lambda env, _: ZeroInput(env.action_spec().shape[0]))


def lookup_policy(domain: Domain) -> Policy:
    """Hold the stored input of the level pose nearest to the target (trunk frame), re-chosen
    every step as the target moves (agents/robostrich/lookup.py)."""
    table = domain.lookup_table()
    return Policy(LABEL, domain, lambda env, flattener: LookupPolicy(flattener, table))


def checkpoint_policy(path: str, label: str) -> Policy:
    """The deterministic actor of a `robostrich-train` checkpoint trained on `robostrich_a1`."""
    run = load_run_from_checkpoint(path)
    domain = run.domain()
    if domain.name != DOMAIN:
        raise ValueError(f"{path}: trained on domain {domain.name!r}; the application tasks run on {DOMAIN!r} "
                         f"(train with --domain {DOMAIN})")
    actor = SACBuilder.make_eval_actor(run.loop)
    return Policy(label, domain, lambda env, _: actor, run.loop.flattener, int(run.config.action_repeat))


def policies(checkpoint: Optional[str], reference: Optional[str], layout: Optional[str]) -> list:
    """The compared policies: the checkpoint (`trained`) and `--reference` (`reference`) where given,
    then zero input and the lookup, all on one domain (the checkpoints' layout, or `layout`)."""
    trained = [checkpoint_policy(path, label) for path, label in ((checkpoint, "trained"), (reference, "reference"))
               if path]
    domains = {p.domain for p in trained} | ({as_domain(DOMAIN, layout)} if layout or not trained else set())
    if len(domains) > 1:
        raise ValueError("the policies were trained on different arms: "
                         + ", ".join(sorted(d.describe() for d in domains)) + " (--layout must match the checkpoints)")
    domain = domains.pop()
    return trained + [zero_policy(domain), lookup_policy(domain)]


class PhaseShifted:
    """A gait started `phase` (fraction of its period) later: one seed of the evaluations."""

    def __init__(self, gait, phase: float):
        self.gait, self.phase = gait, float(phase)
        self.offset = self.phase * float(getattr(gait, "period", 0.0))

    def joint_targets(self, t, trunk_height=None, stride_scale=None):
        return self.gait.joint_targets(t + self.offset, trunk_height, stride_scale)


def load_gait(path: Optional[str] = None):
    """The shipped gait file, or `path` (a gait CSV; a malformed one is a ValueError naming line and column)."""
    return gait_lib.GaitReplay.from_file(gait_lib.DATA_PATH if path is None else path)


def seed_phase(seed: int, seeds: int) -> float:
    """Fraction of the gait period seed `seed` of `seeds` starts later: spread over half a period (module doc)."""
    return 0.5 * seed / max(seeds, 1)


def make_environment(domain: Domain, task: str, seed: int, seeds: int, gait, **task_kwargs):
    """`task` on `domain`, the gait shifted by `seed_phase` (module doc)."""
    return domain.make_environment(task, seed, gait=PhaseShifted(gait, seed_phase(seed, seeds)), **task_kwargs)


def rollout(env, policy: Policy, record: Callable, recorder=None) -> dict:
    """One episode of `policy`; `record(env, action, measured)` returns a dict of numbers per control
    step, given the task's measurement of that step (robostrich_suite/tasks/measurement.py), which
    `recorder` (a RolloutRecorder) gets too every `RECORD_EVERY`-th step.

    Returns the columns as arrays, plus `fell` (the episode ended before its time limit: the
    quadruped fell or the physics diverged)."""
    actor, flattener = policy.bind(env)
    timestep = env.reset()
    if recorder is not None:
        recorder.log_step(env, None, timestep, measure(env))
    rows, step, action = [], 0, None
    while not timestep.last():
        cli_lib.raise_if_interrupted()  # a Ctrl-C some library swallowed
        if step % policy.action_repeat == 0:
            action = np.asarray(actor.select_action(flattener(timestep.observation)), np.float64)
        timestep = env.step(action)
        step += 1
        measured = measure(env)
        rows.append(record(env, action, measured))
        if recorder is not None and (step % RECORD_EVERY == 0 or timestep.last()):
            recorder.log_step(env, action, timestep, measured)
    series = {key: np.array([row[key] for row in rows]) for key in rows[0]} if rows else {}
    series["fell"] = bool(timestep.discount == 0)
    return series


def rollouts(policy: Policy, task: str, seeds: int, gait, record_for: Callable,
             recording: Optional[str] = None, bar=None, **task_kwargs):
    """`policy` on `task` over `seeds` gait phases: yields (seed, environment, series) per phase.
    `record_for(env)` gives :func:`rollout`'s per-step `record`; the phase-0 rollout is recorded
    to `recording` (a .rrd path; None: no recording)."""
    for seed in range(seeds):
        env = make_environment(policy.domain, task, seed, seeds, gait, **task_kwargs)
        with open_recorder(recording if seed == 0 else None, f"{task} {policy.label}") as recorder:
            series = rollout(env, policy, record_for(env), recorder)
        yield seed, env, series
        if bar is not None:
            bar.update(1)

