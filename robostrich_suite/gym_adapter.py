"""A gymnasium view of any robostrich_suite task, for libraries that speak gymnasium.

    from robostrich_suite import gym_adapter
    env = gym_adapter.make("robostrich", "lesson2", seed=0)
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())

Observations are the dm_env dict flattened in its (stable) key order into one
float32 vector; ``env.observation_slices`` says which entries are which.  A
time-limit end (discount 1) is ``truncated``; a divergence (discount 0) is
``terminated``.  With ``normalize_actions=True`` (the default, as most gymnasium
agents expect) actions live in [-1, 1] and are mapped linearly onto the
tendon contraction range; pass False for contractions in metres.  Requires the ``gym`` extra: ``pip install -e '.[gym]'``.
"""
from __future__ import annotations

import gymnasium
import numpy as np
from gymnasium import spaces

import robostrich_suite


class GymnasiumEnv(gymnasium.Env):
    """Wraps a ``dm_env.Environment`` with dict observations and a bounded action."""

    metadata = {"render_modes": []}

    def __init__(self, dm_environment, normalize_actions: bool = True):
        self.dm_env = dm_environment
        action_spec = dm_environment.action_spec()
        self._action_low = np.asarray(action_spec.minimum, np.float64)
        self._action_high = np.asarray(action_spec.maximum, np.float64)
        self.normalize_actions = normalize_actions
        if normalize_actions:
            ones = np.ones(action_spec.shape, np.float32)
            self.action_space = spaces.Box(-ones, ones, dtype=np.float32)
        else:
            self.action_space = spaces.Box(self._action_low.astype(np.float32),
                                           self._action_high.astype(np.float32), dtype=np.float32)
        self.observation_slices = {}
        start = 0
        for name, spec in dm_environment.observation_spec().items():
            size = int(np.prod(spec.shape))
            self.observation_slices[name] = slice(start, start + size)
            start += size
        self.observation_space = spaces.Box(-np.inf, np.inf, shape=(start,), dtype=np.float32)

    def _flatten(self, observation) -> np.ndarray:
        return np.concatenate([np.asarray(v, np.float32).ravel() for v in observation.values()])

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        if seed is not None:
            self.dm_env.task.random.seed(seed)
            # A seeded reset is a fresh start: lesson 3 must not carry over the last pose,
            # or two resets with one seed would differ (gymnasium's determinism check).
            forget = getattr(self.dm_env.task, "forget_last_state", None)
            if forget is not None:
                forget()
        timestep = self.dm_env.reset()
        self._episode_over = False
        return self._flatten(timestep.observation), {}

    def to_dm_action(self, action) -> np.ndarray:
        """The dm_env action (contractions in metres) for a gymnasium action."""
        from robostrich_suite.reach import validate_action
        action = validate_action(action, self._action_low.size)
        if not self.normalize_actions:
            return action
        return self._action_low + (action + 1.0) * 0.5 * (self._action_high - self._action_low)

    def step(self, action):
        if getattr(self, "_episode_over", True):
            raise gymnasium.error.ResetNeeded(
                "cannot call step() before reset() or after the episode ended; call reset()")
        timestep = self.dm_env.step(self.to_dm_action(action))
        self._episode_over = timestep.last()
        terminated = timestep.last() and timestep.discount == 0.0
        truncated = timestep.last() and not terminated
        info = {}
        if getattr(self.dm_env.physics, "divergence", None):
            info["divergence"] = self.dm_env.physics.divergence
        return (self._flatten(timestep.observation), float(timestep.reward), bool(terminated),
                bool(truncated), info)


def make(domain_name: str, task_name: str, seed: int | None = None,
         normalize_actions: bool = True, **task_kwargs) -> GymnasiumEnv:
    """``robostrich_suite.load`` + the gymnasium wrapper."""
    if seed is not None:
        task_kwargs["random"] = seed
    return GymnasiumEnv(robostrich_suite.load(domain_name, task_name, task_kwargs=task_kwargs),
                        normalize_actions=normalize_actions)
