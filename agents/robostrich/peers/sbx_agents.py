"""Peer agents (SBX: SAC, TQC, CrossQ with their published defaults) on the arm, through the
project's gymnasium adapter, evaluated by the project's own evaluation.

Why here: a researcher compares a learner with what they already use; these runs train on the
same lessons (the main job's task options, layout and lesson shares), for the same control steps
and seeds as our SAC, and are scored on the same held-out targets, moving starts and `track`.
Needs the ``peers`` extra (``pip install -e '.[peers]'``); :func:`require` says so in one line.
"""
import dataclasses
import json
import os
import time
from typing import Optional

import numpy as np

from agents.replay import ObservationFlattener
from agents.robostrich.evaluate import episodes, evaluation
from agents.robostrich.domains import Domain

PEERS = {"sac": "SAC", "tqc": "TQC", "crossq": "CrossQ"}  # flag name -> sbx class
WAYS = {"final": "final lesson only", "lessons": "through the lessons"}
EXTRA_HINT = "pip install -e '.[peers]'"


class MissingExtra(ImportError):
    """The peers' packages are not installed (the message says which extra brings them)."""


def require():
    """The ``sbx`` module, or MissingExtra naming the extra that installs it."""
    try:
        import gymnasium  # noqa: F401  (the adapter's)
        import sbx
    except ImportError as error:
        raise MissingExtra(f"the peer agents need the 'peers' extra ({EXTRA_HINT}): {error}") from None
    return sbx


def versions() -> dict:
    """The peers' package versions, for the record."""
    from importlib import metadata
    return {name: metadata.version(name) for name in ("sbx-rl", "stable-baselines3", "flax", "jax", "gymnasium")}


@dataclasses.dataclass(frozen=True)
class PeerSpec:
    """One peer run (picklable, for a worker): agent, how it meets the lessons, seed, budget, where."""
    agent: str
    way: str
    seed: int
    plan: tuple  # of agents.curriculum.Lesson
    task_kwargs: dict
    layout: str
    heldout_task: str
    track_task: Optional[str]
    eval_at: tuple
    num_eval_targets: int
    final_eval_targets: Optional[int]
    out: str

    @property
    def label(self) -> str:
        return f"{self.agent}_{self.way}"


class PeerActor:
    """A trained SBX model as an evaluation actor: the flattened observation in (the adapter's
    order, which is the spec's, as ObservationFlattener's), its deterministic action mapped from
    [-1, 1] onto the tendon contractions by the adapter."""

    def __init__(self, model, gym_env):
        self.model, self.gym_env = model, gym_env

    def select_action(self, flat_obs) -> np.ndarray:
        action, _ = self.model.predict(np.asarray(flat_obs, np.float32), deterministic=True)
        return self.gym_env.to_dm_action(np.clip(action, -1.0, 1.0))


def make_env(domain: Domain, task: str, seed: int, task_kwargs: dict):
    """The lesson's environment as our SAC trains it (layout, stored starts, task options), in the adapter."""
    from robostrich_suite.gym_adapter import GymnasiumEnv
    return GymnasiumEnv(domain.make_environment(task, seed, **task_kwargs))


def build_model(agent: str, env, seed: int):
    """The sbx agent with its published defaults; only the seed is ours."""
    sbx = require()
    from stable_baselines3.common.logger import Logger  # sbx's own dependency
    model = getattr(sbx, PEERS[agent])("MlpPolicy", env, seed=seed, verbose=0)
    # A logger that writes nowhere: without one, every learn() makes an empty SB3-<time> folder in /tmp.
    model.set_logger(Logger(folder=None, output_formats=[]))
    return model


def segments(plan, eval_at) -> list:
    """[(lesson index, steps)]: the plan cut at every evaluation point, so that training pauses there."""
    bounds = np.cumsum([lesson.steps for lesson in plan])
    cuts = sorted(set(int(s) for s in eval_at if 0 < s <= bounds[-1]) | set(int(b) for b in bounds))
    out, done = [], 0
    for cut in cuts:
        lesson = int(np.searchsorted(bounds, cut, side="left"))
        out.append((lesson, cut - done))
        done = cut
    return out


def train(spec: PeerSpec) -> dict:
    """Train the peer through its plan (a held-out evaluation at every point of ``eval_at``, into
    OUT/evals.jsonl), then the final evaluation (OUT/evaluation/LABEL_*.json); returns its result."""
    domain = Domain(spec.plan[-1].domain, spec.layout)
    env = make_env(domain, spec.plan[0].task, spec.seed, spec.task_kwargs)
    model = build_model(spec.agent, env, spec.seed)
    flattener = ObservationFlattener(env.dm_env.observation_spec())
    os.makedirs(spec.out, exist_ok=True)
    lesson_now, curve, start = 0, [], time.time()
    for lesson, steps in segments(spec.plan, spec.eval_at):
        if lesson != lesson_now:  # the same agent and replay, the next lesson's environment
            env = make_env(domain, spec.plan[lesson].task, spec.seed + lesson, spec.task_kwargs)
            model.set_env(env)
            lesson_now = lesson
        model.learn(steps, reset_num_timesteps=False)
        report = episodes.evaluate_heldout(PeerActor(model, env), flattener, domain, spec.heldout_task,
                                             domain.heldout_targets(spec.num_eval_targets), spec.num_eval_targets)
        curve.append({"env_steps": int(model.num_timesteps), "summary": report["summary"]})
        with open(os.path.join(spec.out, "evals.jsonl"), "a") as f:
            f.write(json.dumps(curve[-1]) + "\n")
    seconds, start = time.time() - start, time.time()  # training with its periodic evaluations, as our runs time it
    reports = evaluation.evaluate_agent(PeerActor(model, env), flattener, os.path.join(spec.out, "evaluation"),
                                        spec.label, domain, spec.heldout_task, spec.track_task,
                                        spec.final_eval_targets, env_steps=int(model.num_timesteps), record=False)
    return {"env_steps": int(model.num_timesteps), "train_seconds": seconds,
            "eval_seconds": time.time() - start, "curve": curve,
            "final": {kind: report["summary"] for kind, report in reports.items()}}
