"""Goals in flat observations: hindsight relabelling (HER) and reward recomputation.

A goal-reaching task whose reward is a function of what was achieved and of the goal lets the
agent ask "what would this transition have earned had the goal been g?" and get the exact
answer. The task says which of its observations are goals, and the agent never looks at the
system itself. The contract (a task without ``goal_spec`` gets neither):

- ``goal_spec()``: a dict naming observation entries: ``"goal"`` (the goal the policy is
  given), ``"achieved"`` (what the goal is compared with) and optionally
  ``"achieved_components"`` (the components of it the goal is compared with, where it holds
  more) and ``"goal_delta"`` (an entry holding goal - achieved, rewritten with the goal);
- ``achieved_goal(observation)``: from one control step's observation entries (a mapping), the
  vector the replay keeps (``reached``): the achieved goal first, then whatever else the reward
  reads (the arm's head attitude error);
- ``goal_reward(reached, goal)``: the reward of each ``reached`` (..., r) had the goal been
  ``goal`` (..., g);
- optionally ``settable_goals(reached)``: which reached vectors (..., r) are goals the task could
  set (bool (...); None: every one): hindsight goals are drawn only among them (the arm's
  level-head goals, where its ``hindsight_level_goals`` option asks for them);
- optionally ``has_goal_free_reward()``: the reward also holds a part no goal changes (the arm's
  charge for changing its inputs). The replay then keeps that part of each stored reward (the
  reward less what ``goal_reward`` gives for the transition's own goal) and adds it to every
  reward it recomputes, so the charge survives hindsight goals and reward recomputation.

Under an action repeat a transition spans several control steps whose rewards are summed, so
the replay keeps the reached vector after each of them (``substep_goals``) and sums the
recomputed rewards the same way.
"""
from typing import Optional

import numpy as np


class GoalRelabeler:
    """Overwrites the goal of flat observations and recomputes the task's reward."""

    def __init__(self, flattener, task, slices: Optional[dict] = None):
        slices = _slices(flattener) if slices is None else slices
        spec = task.goal_spec()
        self.goal = slices[spec["goal"]]
        self.achieved = _achieved_index(spec, slices[spec["achieved"]])
        self.delta = slices.get(spec.get("goal_delta"))
        self.goal_size = self.goal.stop - self.goal.start
        self._slices, self._achieved_goal = slices, task.achieved_goal
        self.reward_fn = task.goal_reward
        self._settable = getattr(task, "settable_goals", None)
        goal_free = getattr(task, "has_goal_free_reward", None)
        self.keeps_goal_free = bool(goal_free()) if callable(goal_free) else False
        # The width of a reached vector: the task's, measured on a zero observation.
        self.reached_size = int(np.size(self.substep(np.zeros(flattener.size, np.float32))))

    @classmethod
    def for_environment(cls, env, flattener) -> Optional["GoalRelabeler"]:
        """A relabeler for ``env``'s task, or None when the task has no goals (module doc)."""
        task = getattr(env, "task", None)
        needed = ("goal_spec", "achieved_goal", "goal_reward")
        if task is None or not all(callable(getattr(task, n, None)) for n in needed) or flattener.keys is None:
            return None
        slices, spec = _slices(flattener), task.goal_spec()
        goal, achieved = slices.get(spec["goal"]), slices.get(spec["achieved"])
        if goal is None or achieved is None:
            return None
        index = _achieved_index(spec, achieved)
        if goal.stop - goal.start != (index.stop - index.start if isinstance(index, slice) else len(index)):
            raise ValueError(f"the task's goal {spec['goal']!r} has {goal.stop - goal.start} components "
                             f"but its achieved {spec['achieved']!r} {achieved.stop - achieved.start}: "
                             "name the ones to compare in its goal_spec's achieved_components")
        return cls(flattener, task, slices)

    def substep(self, flat_obs: np.ndarray) -> np.ndarray:
        """The reached vector (achieved goal, then what else the reward reads) of one control step."""
        return self._achieved_goal({k: flat_obs[s] for k, s in self._slices.items()})

    def with_goal(self, flat_obs: np.ndarray, goal: np.ndarray) -> np.ndarray:
        """Copies of ``flat_obs`` (..., obs) with ``goal`` (..., g) as their target."""
        out = flat_obs.copy()
        out[..., self.goal] = goal
        if self.delta is not None:
            out[..., self.delta] = goal - flat_obs[..., self.achieved]
        return out

    def settable(self, reached: np.ndarray) -> Optional[np.ndarray]:
        """Which reached vectors (..., r) are goals the task could set (bool (...)); None: all of them."""
        return self._settable(reached) if callable(self._settable) else None

    def rewards(self, substep_goals: np.ndarray, substeps: np.ndarray, goal: np.ndarray) -> np.ndarray:
        """Summed reward of transitions whose control steps reached ``substep_goals``
        (..., k, r) (only the first ``substeps`` (...) of the k count), for ``goal`` (..., g)."""
        per_step = self.reward_fn(substep_goals, goal[..., None, :])
        taken = np.arange(substep_goals.shape[-2]) < substeps[..., None]
        return np.sum(np.where(taken, per_step, 0.0), axis=-1)

    def goal_free(self, reward: float, substep_goals, flat_obs: np.ndarray) -> float:
        """The part of ``reward`` that ``goal_reward`` does not give: the stored reward of a
        transition from ``flat_obs`` whose control steps reached ``substep_goals``, less its goal's."""
        reached = np.asarray(substep_goals, np.float64)[None]
        goal_part = self.rewards(reached, np.array([len(reached[0])]), np.asarray(flat_obs[self.goal], np.float64)[None])
        return float(reward - goal_part[0])


def _achieved_index(spec: dict, achieved: slice):
    """The flat indices of the achieved goal: the whole observation, or the components the spec
    names in ``achieved_components`` (a 3-D position compared with a 2-D goal)."""
    components = spec.get("achieved_components")
    if components is None:
        return achieved
    index = np.arange(achieved.start, achieved.stop)
    if not all(0 <= c < index.size for c in components):
        raise ValueError(f"achieved_components {tuple(components)} outside the {index.size} components of "
                         f"{spec['achieved']!r}")
    return index[list(components)]


def _slices(flattener) -> dict:
    offsets = np.concatenate([[0], np.cumsum(flattener.sizes)])
    return {k: slice(int(offsets[i]), int(offsets[i + 1])) for i, k in enumerate(flattener.keys)}
