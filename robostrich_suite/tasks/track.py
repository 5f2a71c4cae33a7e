"""``Track``, the evaluation task of Fig. 7: a ``Reach`` whose targets are reached in order, one
after another, within one episode; and the three held-out targets it uses by default."""
from __future__ import annotations

import numpy as np

from robostrich_suite.tasks import options
from robostrich_suite.tasks.conventions import CONTROL_TIMESTEP
from robostrich_suite.tasks.reach import Reach, length
from robostrich_suite.tasks.target_samplers import as_targets
from robostrich_suite import targets as targets_lib

MAX_STEPS_PER_TARGET = int(options.MAX_SECONDS / CONTROL_TIMESTEP)  # a target held for the longest episode

class Track(Reach):
    """Reach ``targets`` in order, ``steps_per_target`` control steps each (Fig. 7)."""

    def __init__(self, targets=None, steps_per_target: int = 250, **kwargs):
        if targets is None:
            targets = default_track_targets(targets_lib.heldout_targets())
        targets = as_targets(targets, "targets")
        steps_per_target = options.whole("steps_per_target", steps_per_target, 1, MAX_STEPS_PER_TARGET,
                                         "a whole number of control steps")
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

    def checkpoint_state(self) -> dict:
        return {**super().checkpoint_state(), "target_index": self.target_index, "step": self._step}

    def restore_checkpoint_state(self, state: dict) -> None:
        super().restore_checkpoint_state(state)
        index = int(state["target_index"])
        if not 0 <= index < len(self.targets):
            raise ValueError(f"the stored target index {index} is not one of this task's {len(self.targets)} targets")
        self.target_index, self._step = index, int(state["step"])

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
        obs["position_error"] = np.array([length(obs["to_target"])])  # position_error, same reading
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
