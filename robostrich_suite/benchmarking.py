"""Shared timing helpers of the benchmark scripts in ``tools/`` (never used in tests)."""
from __future__ import annotations

import time

import numpy as np

import robostrich_suite


def env_steps_per_second(domain: str, task: str, steps: int, actions: np.ndarray) -> float:
    """Control steps per second of ``robostrich_suite.load(domain, task)``, resets included."""
    env = robostrich_suite.load(domain, task, task_kwargs=dict(random=0))
    env.reset()
    start = time.perf_counter()
    for i in range(steps):
        if env.step(actions[i % len(actions)]).last():
            env.reset()
    return steps / (time.perf_counter() - start)


def random_actions(domain: str, task: str, count: int = 500, seed: int = 0) -> np.ndarray:
    """Uniform actions within the task's action spec."""
    spec = robostrich_suite.load(domain, task, task_kwargs=dict(random=0)).action_spec()
    return np.random.default_rng(seed).uniform(spec.minimum, spec.maximum,
                                               size=(count,) + spec.shape)


def episode_steps(domain: str, task: str) -> int:
    """Control steps per episode of ``robostrich_suite.load(domain, task)``."""
    env = robostrich_suite.load(domain, task, task_kwargs=dict(random=0))
    return int(env._step_limit)  # dm_control keeps the time limit only as this step count
