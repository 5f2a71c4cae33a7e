"""How a reaching task draws each episode's target from its pool.

``"uniform"`` (the paper) draws every target alike; ``"failures"`` draws each in proportion to
its estimated failure rate, (failures + 1) / (tries + 2), judged on the previous episode's
final pose against what the lesson's reward asks for; ``"continue_failures"`` is ``"failures"``
in lessons whose episodes continue from the last pose (lesson 3) and ``"uniform"`` in fixed-start
ones, so one option leaves lessons 1-2 the paper's.
"""
from __future__ import annotations

import numpy as np

from robostrich_suite.tasks import options

TARGET_SAMPLINGS = ("uniform", "failures", "continue_failures")
MAX_TARGET_DISTANCE = 1.5  # m from the origin of the targets' frame: no arm reaches farther


def as_targets(targets, name: str) -> np.ndarray:
    """(n, 2) finite head positions (x, z); one (2,) position is one target. Anything else (a
    (4, 3) or (1, 4) array) is an error, not silently reshaped into other targets."""
    array = options.array(name, targets, "a non-empty (n, 2) array of (x, z) positions")
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


class TargetSampler:
    """A pool of (x, z) targets, the draw, and (for failure sampling) each target's tries and failures."""

    def __init__(self, pool, sampling: str = "uniform"):
        if sampling not in TARGET_SAMPLINGS:
            raise ValueError(f"unknown target_sampling {sampling!r}; use one of {TARGET_SAMPLINGS}")
        self.sampling = sampling
        self.set_pool(pool)

    def set_pool(self, targets) -> None:
        """Draw from ``targets`` ((n, 2) or one (2,) position) from now on; the counts start again."""
        self.pool = as_targets(targets, "target_pool")
        self.tries = np.zeros(len(self.pool), np.int64)
        self.failures = np.zeros(len(self.pool), np.int64)
        self.index = None
        self._neighbours = None  # each pose's nearest others, see moved

    def by_failures(self, initial_state: str) -> bool:
        """Whether a lesson with this initial state draws by failure rate (and scores its episodes)."""
        return self.sampling == "failures" or (self.sampling == "continue_failures" and initial_state == "continue")

    def record(self, reached) -> None:
        """Score the last drawn target: ``reached`` True or False (None: not judged, e.g. a divergence)."""
        if self.index is not None and reached is not None:
            self.tries[self.index] += 1
            self.failures[self.index] += not reached

    def checkpoint_state(self) -> dict:
        """The pool, its counts and the last draw, as data (the task's checkpoint state)."""
        return {"pool": self.pool, "tries": self.tries, "failures": self.failures, "index": self.index}

    def restore_checkpoint_state(self, state: dict) -> None:
        self.set_pool(state["pool"])
        counts = [np.array(state[name], np.int64) for name in ("tries", "failures")]
        if any(c.shape != self.tries.shape for c in counts):
            raise ValueError("the stored target counts do not fit the stored target pool")
        self.tries, self.failures = counts
        index = state["index"]
        if index is not None and not 0 <= int(index) < len(self.pool):
            raise ValueError(f"the stored target index {index} is outside the pool of {len(self.pool)}")
        self.index = None if index is None else int(index)

    def draw(self, random, initial_state: str) -> np.ndarray:
        """The next target (a copy), drawn with ``random``."""
        if self.by_failures(initial_state):
            failure_rate = (self.failures + 1.0) / (self.tries + 2.0)
            self.index = int(random.choice(len(self.pool), p=failure_rate / failure_rate.sum()))
        else:
            self.index = int(random.randint(len(self.pool)))
        return self.pool[self.index].copy()

    def moved(self, target, random, between: int = 0, jitter: float = 0.0) -> np.ndarray:
        """The last drawn ``target`` moved a uniform share of the way towards one of its ``between``
        nearest pool poses, then uniformly within a disk of radius ``jitter`` (m): training that
        meets the poses between the pool's (the reaching task's ``target_between`` and ``target_jitter``)."""
        if between and len(self.pool) > 1:
            k = min(between, len(self.pool) - 1)
            if self._neighbours is None or self._neighbours.shape[1] != k:  # made once per pool and k
                distances = np.linalg.norm(self.pool[:, None] - self.pool[None], axis=2)
                np.fill_diagonal(distances, np.inf)
                self._neighbours = np.argsort(distances, axis=1)[:, :k]
            other = self.pool[self._neighbours[self.index, random.randint(self._neighbours.shape[1])]]
            target = target + random.uniform() * (other - target)
        if jitter:  # uniform over the disk: the radius as the square root of a uniform draw
            radius = jitter * np.sqrt(random.uniform())
            angle = random.uniform(0.0, 2.0 * np.pi)
            target = target + radius * np.array([np.cos(angle), np.sin(angle)])
        return target
