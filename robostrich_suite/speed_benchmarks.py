"""Shared helpers of the speed benchmarks in ``tools/``: timed loops and the report they write."""
from __future__ import annotations

import json
import os
import shlex
import time

import numpy as np

import robostrich_suite
from robostrich_suite import atomic_files


class EnvLoop:
    """``robostrich_suite.load(domain, task)`` stepped with ``actions`` in turn, resets included;
    each ``run`` continues where the last one stopped, so short timed rounds add up to episodes."""

    def __init__(self, domain: str, task: str, actions: np.ndarray):
        self._start(robostrich_suite.load(domain, task, task_kwargs=dict(random=0)), actions)

    @classmethod
    def of(cls, env, actions: np.ndarray) -> "EnvLoop":
        """The loop of any dm_env environment ``env`` (a baseline's)."""
        loop = cls.__new__(cls)
        loop._start(env, actions)
        return loop

    def _start(self, env, actions: np.ndarray) -> None:
        self.env = env
        self.env.reset()
        self.actions, self.count = actions, 0

    def run(self, steps: int) -> float:
        """Seconds for ``steps`` control steps."""
        env, actions = self.env, self.actions
        start = time.perf_counter()
        for i in range(self.count, self.count + steps):
            if env.step(actions[i % len(actions)]).last():
                env.reset()
        self.count += steps
        return time.perf_counter() - start


def env_steps_per_second(domain: str, task: str, steps: int, actions: np.ndarray) -> float:
    """Control steps per second of ``robostrich_suite.load(domain, task)``, resets included."""
    return steps / EnvLoop(domain, task, actions).run(steps)


def random_actions(domain: str, task: str, count: int = 500, seed: int = 0) -> np.ndarray:
    """Uniform actions within the task's action spec."""
    spec = robostrich_suite.load(domain, task, task_kwargs=dict(random=0)).action_spec()
    return np.random.default_rng(seed).uniform(spec.minimum, spec.maximum,
                                               size=(count,) + spec.shape)


def episode_steps(domain: str, task: str) -> int:
    """Control steps per episode of ``robostrich_suite.load(domain, task)``."""
    env = robostrich_suite.load(domain, task, task_kwargs=dict(random=0))
    return int(env._step_limit)  # dm_control keeps the time limit only as this step count


def rate(what: str, value: float, unit: str) -> dict:
    """One measured speed of a report."""
    return {"what": what, "value": float(value), "unit": unit}


def ratio(what: str, value: float, low: float = None, high: float = None) -> dict:
    """One ratio against a baseline measured in the same run, with its spread where the benchmark has one."""
    row = {"what": what, "value": float(value)}
    if low is not None:
        row.update(low=float(low), high=float(high))
    return row


def write_report(path, script: str, argv: list, description: str, rates: list, ratios: list) -> None:
    """A speed benchmark's ``--json`` file: what ``tools/results_page.py add`` records (kind "speed"),
    with the command that made it."""
    command = shlex.join(["python", f"tools/{os.path.basename(script)}", *argv])
    atomic_files.write_text(path, json.dumps({"benchmark": "speed", "command": command, "description": description,
                                       "rates": rates, "ratios": ratios}, indent=1) + "\n")
