"""Goals in flat observations: hindsight relabelling (HER) and reward recomputation.

A goal-reaching task whose reward is a function of the achieved pose and the
goal lets the agent ask "what would this
transition have earned had the target been g?" and get the exact answer. The
task says where the goal sits in its observation (``GOAL_OBSERVATION``,
``ACHIEVED_OBSERVATION``, ``GOAL_DELTA_OBSERVATION``,
``ATTITUDE_ERROR_OBSERVATION``; ``ACHIEVED_COMPONENTS``, where the achieved observation
holds more components than the goal, names those the goal is compared with) and gives the
reward with ``goal_reward``; the agent never looks at the system itself.

A reward may also hold a part that does not depend on the goal (the arm's charge for changing its
inputs): where the task says so (``has_goal_free_reward``), the replay keeps that part of each
stored reward (the reward less what ``goal_reward`` gives for the transition's own goal) and adds it
to every reward it recomputes, so the charge survives hindsight goals and the curriculum's reward
recomputation.

Under an action repeat a transition spans several control steps whose rewards
are summed, so the replay keeps the achieved position and attitude error after
each of them (``substep_goals``) and sums the recomputed rewards the same way.
"""
from typing import Optional

import numpy as np


class GoalRelabeler:
    """Overwrites the goal of flat observations and recomputes the task's reward."""

    def __init__(self, flattener, task, slices: Optional[dict] = None):
        slices = _slices(flattener) if slices is None else slices
        self.goal = slices[task.GOAL_OBSERVATION]
        self.achieved = _achieved_index(task, slices[task.ACHIEVED_OBSERVATION])
        self.delta = slices.get(task.GOAL_DELTA_OBSERVATION)
        self.attitude = slices[task.ATTITUDE_ERROR_OBSERVATION]
        self.goal_size = self.goal.stop - self.goal.start
        self.reward_fn = task.goal_reward
        # Reached poses farther than this from level (deg) are not goals the task could set;
        # None: every reached position is one.
        tolerance = getattr(task, "goal_attitude_tolerance", None)
        self.goal_attitude_tolerance = tolerance() if callable(tolerance) else None
        goal_free = getattr(task, "has_goal_free_reward", None)
        self.keeps_goal_free = bool(goal_free()) if callable(goal_free) else False

    @classmethod
    def for_environment(cls, env, flattener) -> Optional["GoalRelabeler"]:
        """A relabeler for ``env``'s task, or None when the task has no goal reward."""
        task = getattr(env, "task", None)
        needed = ("goal_reward", "GOAL_OBSERVATION", "ACHIEVED_OBSERVATION", "ATTITUDE_ERROR_OBSERVATION")
        if task is None or not all(hasattr(task, n) for n in needed) or flattener.keys is None:
            return None
        slices = _slices(flattener)
        goal, achieved = slices.get(task.GOAL_OBSERVATION), slices.get(task.ACHIEVED_OBSERVATION)
        if goal is None or achieved is None or task.ATTITUDE_ERROR_OBSERVATION not in slices:
            return None
        index = _achieved_index(task, achieved)
        if goal.stop - goal.start != (index.stop - index.start if isinstance(index, slice) else len(index)):
            raise ValueError(f"the task's goal {task.GOAL_OBSERVATION!r} has {goal.stop - goal.start} components "
                             f"but its achieved {task.ACHIEVED_OBSERVATION!r} {achieved.stop - achieved.start}: "
                             "name the ones to compare in ACHIEVED_COMPONENTS")
        return cls(flattener, task, slices)

    def substep(self, flat_obs: np.ndarray) -> np.ndarray:
        """(achieved goal..., attitude error in deg) of one control step's flat observation."""
        return np.concatenate([flat_obs[self.achieved], np.degrees(flat_obs[self.attitude])])

    def with_goal(self, flat_obs: np.ndarray, goal: np.ndarray) -> np.ndarray:
        """Copies of ``flat_obs`` (..., obs) with ``goal`` (..., g) as their target."""
        out = flat_obs.copy()
        out[..., self.goal] = goal
        if self.delta is not None:
            out[..., self.delta] = goal - flat_obs[..., self.achieved]
        return out

    def settable(self, reached: np.ndarray) -> np.ndarray:
        """Which reached poses (..., g + 1) (position, attitude error in deg) are goals the task
        could set: all of them unless the task limits the attitude error of its goals."""
        if self.goal_attitude_tolerance is None:
            return np.ones(reached.shape[:-1], bool)
        return np.abs(reached[..., self.goal_size]) <= self.goal_attitude_tolerance

    def rewards(self, substep_goals: np.ndarray, substeps: np.ndarray, goal: np.ndarray) -> np.ndarray:
        """Summed reward of transitions whose control steps reached ``substep_goals``
        (..., k, g + 1) (only the first ``substeps`` (...) of the k count), for ``goal`` (..., g)."""
        g = self.goal_size
        per_step = self.reward_fn(substep_goals[..., :g], substep_goals[..., g], goal[..., None, :])
        taken = np.arange(substep_goals.shape[-2]) < substeps[..., None]
        return np.sum(np.where(taken, per_step, 0.0), axis=-1)

    def goal_free(self, reward: float, substep_goals, flat_obs: np.ndarray) -> float:
        """The part of ``reward`` that ``goal_reward`` does not give: the stored reward of a
        transition from ``flat_obs`` whose control steps reached ``substep_goals``, less its goal's."""
        reached = np.asarray(substep_goals, np.float64)[None]
        goal_part = self.rewards(reached, np.array([len(reached[0])]), np.asarray(flat_obs[self.goal], np.float64)[None])
        return float(reward - goal_part[0])


def _achieved_index(task, achieved: slice):
    """The flat indices of the achieved goal: the whole observation, or the components the task
    names in ``ACHIEVED_COMPONENTS`` (a 3-D position compared with a 2-D goal)."""
    components = getattr(task, "ACHIEVED_COMPONENTS", None)
    if components is None:
        return achieved
    index = np.arange(achieved.start, achieved.stop)
    if not all(0 <= c < index.size for c in components):
        raise ValueError(f"ACHIEVED_COMPONENTS {tuple(components)} outside the {index.size} components of "
                         f"{task.ACHIEVED_OBSERVATION!r}")
    return index[list(components)]


def _slices(flattener) -> dict:
    offsets = np.concatenate([[0], np.cumsum(flattener.sizes)])
    return {k: slice(int(offsets[i]), int(offsets[i + 1])) for i, k in enumerate(flattener.keys)}
