"""A numpy ring-buffer replay that stores flattened dm_env observations.

Numpy, not device arrays: inserts are one row at a time and cheap, and a
whole stack of batches for one learner call is drawn with a single fancy
index (see `sample_stack`).
"""
from typing import Mapping

import numpy as np

from agents.sac.learning import Transitions


class ObservationFlattener:
    """Concatenates a dict observation into one float32 vector in the spec's key order."""

    def __init__(self, observation_spec):
        if isinstance(observation_spec, Mapping):
            self.keys = tuple(observation_spec.keys())
            self.sizes = tuple(int(np.prod(observation_spec[k].shape)) for k in self.keys)
        else:
            self.keys = None
            self.sizes = (int(np.prod(observation_spec.shape)),)
        self.size = int(sum(self.sizes))

    def __call__(self, observation) -> np.ndarray:
        if self.keys is None:
            return np.asarray(observation, np.float32).ravel()
        return np.concatenate([np.asarray(observation[k], np.float32).ravel() for k in self.keys])

    def describe(self) -> list:
        return [[k, s] for k, s in zip(self.keys or ("observation",), self.sizes)]


class ReplayBuffer:
    """Uniform replay of transitions (s, a, r, discount, s')."""

    FIELDS = ("obs", "action", "reward", "discount", "next_obs")

    def __init__(self, obs_size: int, action_size: int, capacity: int, seed: int = 0):
        self.capacity = int(capacity)
        self.obs_size, self.action_size = int(obs_size), int(action_size)
        self.obs = np.zeros((capacity, obs_size), np.float32)
        self.action = np.zeros((capacity, action_size), np.float32)
        self.reward = np.zeros((capacity,), np.float32)
        self.discount = np.zeros((capacity,), np.float32)
        self.next_obs = np.zeros((capacity, obs_size), np.float32)
        self.size = 0
        self.insert_index = 0
        self.rng = np.random.default_rng(seed)

    def __len__(self):
        return self.size

    def add(self, obs, action, reward, discount, next_obs):
        i = self.insert_index
        self.obs[i] = obs
        self.action[i] = action
        self.reward[i] = reward
        self.discount[i] = discount
        self.next_obs[i] = next_obs
        self.insert_index = (i + 1) % self.capacity
        self.size = min(self.size + 1, self.capacity)

    def sample_stack(self, num_batches: int, batch_size: int) -> Transitions:
        """num_batches independent uniform batches, shaped [num_batches, batch_size, ...]."""
        if self.size == 0:
            raise ValueError("cannot sample from an empty replay buffer")
        idx = self.rng.integers(0, self.size, size=(num_batches, batch_size))
        return Transitions(self.obs[idx], self.action[idx], self.reward[idx], self.discount[idx], self.next_obs[idx])

    def state_dict(self) -> dict:
        """The filled part only, plus the insertion point and sampling RNG, for exact resumption."""
        n = self.size
        return {"capacity": self.capacity, "obs_size": self.obs_size, "action_size": self.action_size,
                "size": n, "insert_index": self.insert_index, "rng": self.rng.bit_generator.state,
                **{f: getattr(self, f)[:n].copy() for f in self.FIELDS}}

    def load_state_dict(self, d: dict):
        for k in ("capacity", "obs_size", "action_size"):
            if d[k] != getattr(self, k):
                raise ValueError(f"replay {k} mismatch: checkpoint has {d[k]}, this run has {getattr(self, k)}")
        n = d["size"]
        for f in self.FIELDS:
            getattr(self, f)[:n] = d[f]
        self.size = n
        self.insert_index = d["insert_index"]
        self.rng.bit_generator.state = d["rng"]
