"""A numpy ring-buffer replay that stores flattened dm_env observations.

Numpy, not device arrays: inserts are one row at a time and cheap, and a
whole stack of batches for one learner call is drawn with a single fancy
index (see `sample_stack`).
"""
from typing import Mapping

import numpy as np

from agents.types import Transitions


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
    """Uniform replay of transitions (s, a, r, discount, s').

    With ``goal_width`` > 0 it also keeps, per transition, the achieved goal and
    attitude error after each of its (up to ``repeat``) control steps and the
    episode it belongs to, so that :meth:`sample_stack` can relabel goals with
    hindsight (agents/goals.py).
    """

    FIELDS = ("obs", "action", "reward", "discount", "next_obs")
    GOAL_FIELDS = ("substep_goals", "substeps", "abs_index", "episode_last")

    def __init__(self, obs_size: int, action_size: int, capacity: int, seed: int = 0,
                 goal_width: int = 0, repeat: int = 1):
        self.capacity = int(capacity)
        self.obs_size, self.action_size = int(obs_size), int(action_size)
        self.goal_width, self.repeat = int(goal_width), int(repeat)
        self.obs = np.zeros((capacity, obs_size), np.float32)
        self.action = np.zeros((capacity, action_size), np.float32)
        self.reward = np.zeros((capacity,), np.float32)
        self.discount = np.zeros((capacity,), np.float32)
        self.next_obs = np.zeros((capacity, obs_size), np.float32)
        if self.goal_width:
            self.substep_goals = np.zeros((capacity, self.repeat, self.goal_width), np.float32)
            self.substeps = np.zeros((capacity,), np.int32)
            self.abs_index = np.zeros((capacity,), np.int64)  # position in the stream of all additions
            self.episode_last = np.zeros((capacity,), np.int64)  # abs index of its episode's end; -1 open
        self.goal_free = None  # (capacity,) once a transition comes with a goal-free reward part
        self.size = 0
        self.insert_index = 0
        self.total_added = 0
        self.episode_start = 0  # abs index of the open episode's first transition
        self.row_base = 0  # abs index of the transition in row 0: rows fill from 0 again after a clear
        self.rng = np.random.default_rng(seed)

    def __len__(self):
        return self.size

    @property
    def fields(self):
        return self.FIELDS + (self.GOAL_FIELDS if self.goal_width else ())

    def add(self, obs, action, reward, discount, next_obs, substep_goals=None, goal_free=None):
        """One transition; ``substep_goals`` (taken control steps, goal_width) when goals are kept;
        ``goal_free``: the part of ``reward`` a recomputed reward keeps (agents/goals.py)."""
        i = self.insert_index
        self.obs[i] = obs
        self.action[i] = action
        self.reward[i] = reward
        self.discount[i] = discount
        self.next_obs[i] = next_obs
        if self.goal_width:
            taken = len(substep_goals)
            self.substep_goals[i, :taken] = substep_goals
            self.substeps[i] = taken
            self.abs_index[i] = self.total_added
            self.episode_last[i] = -1
        if goal_free is not None and self.goal_free is None:
            self.goal_free = np.zeros((self.capacity,), np.float32)
        if self.goal_free is not None:
            self.goal_free[i] = 0.0 if goal_free is None else goal_free
        self.insert_index = (i + 1) % self.capacity
        self.size = min(self.size + 1, self.capacity)
        self.total_added += 1

    def _rows(self, abs_index):
        """The rows holding the transitions with these positions in the stream of all additions."""
        return (abs_index - self.row_base) % self.capacity

    def clear(self):
        """Forget every transition (a lesson that starts with an empty replay); the stream's count
        and the sampling RNG go on, so a resumed run clears and samples as the uninterrupted one."""
        self.size = self.insert_index = 0
        self.episode_start = self.row_base = self.total_added

    def end_episode(self):
        """Close the open episode: hindsight goals are drawn from within it only."""
        if self.goal_width and self.total_added > self.episode_start:
            first = max(self.episode_start, self.total_added - self.size)
            self.episode_last[self._rows(np.arange(first, self.total_added))] = self.total_added - 1
        self.episode_start = self.total_added

    def sample_stack(self, num_batches: int, batch_size: int, relabeler=None, her_ratio: float = 0.0,
                     relabel_rewards: bool = False) -> Transitions:
        """num_batches independent uniform batches, shaped [num_batches, batch_size, ...].

        With a ``relabeler`` (agents/goals.py), a ``her_ratio`` share of the rows get as goal
        the position reached at a uniformly drawn later step of the same episode ("future"
        strategy), and their rewards are recomputed; ``relabel_rewards`` recomputes every
        row's reward with the relabeler's (the current lesson's) reward function. Rows that
        ended in a divergence (discount 0) keep their stored penalty. Where the task limits the
        goals it could set (``GoalRelabeler.settable``), a row is relabelled only when the later
        pose is one of them; the others keep theirs.
        """
        if self.size == 0:
            raise ValueError("cannot sample from an empty replay buffer")
        idx = self.rng.integers(0, self.size, size=(num_batches, batch_size))
        obs, action, reward = self.obs[idx], self.action[idx], self.reward[idx]
        discount, next_obs = self.discount[idx], self.next_obs[idx]
        if relabeler is None or not self.goal_width or not (her_ratio > 0 or relabel_rewards):
            return Transitions(obs, action, reward, discount, next_obs)
        goal = obs[..., relabeler.goal]
        recompute = np.full(idx.shape, bool(relabel_rewards))
        if her_ratio > 0:
            her = self.rng.random(idx.shape) < her_ratio
            first = self.abs_index[idx]
            last = self.episode_last[idx]
            last = np.where(last < 0, self.total_added - 1, last)
            future = first + np.floor(self.rng.random(idx.shape) * (last - first + 1)).astype(np.int64)
            rows = self._rows(future)
            reached_pose = self.substep_goals[rows, self.substeps[rows] - 1]
            settable = relabeler.settable(reached_pose)
            if settable is not None:
                her &= settable
            reached = reached_pose[..., :relabeler.goal_size]
            goal = np.where(her[..., None], reached, goal)
            obs[her] = relabeler.with_goal(obs[her], goal[her])
            next_obs[her] = relabeler.with_goal(next_obs[her], goal[her])
            recompute |= her
        recompute &= discount > 0
        if np.any(recompute):
            new = relabeler.rewards(self.substep_goals[idx], self.substeps[idx], goal)
            if self.goal_free is not None:
                new = new + self.goal_free[idx]
            reward = np.where(recompute, new, reward).astype(np.float32)
        return Transitions(obs, action, reward, discount, next_obs)

    def state_dict(self) -> dict:
        """The filled part only, plus the insertion point and sampling RNG, for exact resumption.
        The arrays are views of the buffer (a checkpoint pickles them at once; a copy of a full
        replay costs as much as writing it): copy them to keep them while the replay moves on."""
        n = self.size
        return {"capacity": self.capacity, "obs_size": self.obs_size, "action_size": self.action_size,
                "goal_width": self.goal_width, "repeat": self.repeat,
                "size": n, "insert_index": self.insert_index, "rng": self.rng.bit_generator.state,
                "total_added": self.total_added, "episode_start": self.episode_start, "row_base": self.row_base,
                **{f: getattr(self, f)[:n] for f in self.fields},
                **({} if self.goal_free is None else {"goal_free": self.goal_free[:n]})}

    def load_state_dict(self, d: dict):
        for k in ("capacity", "obs_size", "action_size", "goal_width", "repeat"):
            if d.get(k, 0 if k == "goal_width" else 1) != getattr(self, k):
                raise ValueError(f"replay {k} mismatch: checkpoint has {d.get(k)}, this run has {getattr(self, k)}")
        n = d["size"]
        for f in self.fields:
            getattr(self, f)[:n] = d[f]
        if "goal_free" in d:
            self.goal_free = np.zeros((self.capacity,), np.float32)
            self.goal_free[:n] = d["goal_free"]
        self.size = n
        self.insert_index = d["insert_index"]
        self.total_added = d.get("total_added", n)
        self.episode_start = d.get("episode_start", self.total_added)
        self.row_base = d.get("row_base", 0)
        self.rng.bit_generator.state = d["rng"]
