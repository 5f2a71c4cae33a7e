"""The one lesson factory both domain modules are built with.

A domain is its ``Physics`` class, its ``get_model_and_assets`` and the task class its
lessons use (:class:`reach.Reach` on the frame, ``QuadrupedReach`` on the quadruped).
:class:`LessonFactory` turns a task into an environment on the domain's model (control
timestep ``conventions.CONTROL_TIMESTEP``) and :meth:`LessonFactory.add_lessons`
registers the curriculum's lessons 1-3 in the domain's ``SUITE``:

* ``lesson1``: reach the target position, eq. 9 reward, fixed initial state;
* ``lesson2``: reach it with the head level, eq. 10 reward, fixed initial state;
* ``lesson3``: as lesson 2, each episode starts where the previous one ended.
"""
from __future__ import annotations

import dataclasses
import functools
import types
from typing import Callable

from dm_control.rl import control

from robostrich_suite import fingerprint as fingerprint_lib
from robostrich_suite.model import arm as arm_lib
from robostrich_suite.tasks import options, reach
from robostrich_suite.tasks.conventions import CONTROL_TIMESTEP

LESSON_TIME_LIMIT = 2.0  # s (250 control steps): the tendon servos bring the neck to rest in ~1.5 s

# What a task is for, as tags of the domains' registries (``robostrich_suite.tasks_tagged``), so
# that code judging a policy asks the registry instead of knowing task names.
CURRICULUM = "curriculum"  # a lesson of Algorithm 1, in order
DRAWS_TARGETS = "draws_targets"  # each episode's target drawn from a pool (``target_pool``)
HELDOUT = "heldout"  # held-out targets are judged here: eq. 10 from the fixed start, every target alike
MOVING_START = "moving_start"  # each episode continues from where the last ended
TRACK = "track"  # several targets in turn (Fig. 7)
EVALUATION = "evaluation"  # an evaluation of its own, not a lesson
WALKING = "walking"  # held-out targets judged while the legs walk (what the robot's walk does to the arm)
# the tags of each lesson beside CURRICULUM and DRAWS_TARGETS
LESSON_TAGS = {"lesson1": (), "lesson2": (HELDOUT,), "lesson3": (MOVING_START,)}

# name -> (reward, initial state, what the lesson asks)
LESSONS = {
    "lesson1": ("lesson1", "fixed", "Lesson 1: position only (eq. 9), from the fixed initial pose"),
    "lesson2": ("lesson2", "fixed", "Lesson 2: position and level head (eq. 10), from the fixed "
                                    "initial pose"),
    "lesson3": ("lesson2", "continue", "Lesson 3: as lesson 2, each episode continues from the "
                                       "previous final state"),
}


def check_arm(arm_spec, tendon_layout) -> None:
    """TypeError naming the option unless each is None or what it names (a string from JSON is
    not an arm)."""
    if arm_spec is not None and not isinstance(arm_spec, arm_lib.ArmSpec):
        raise TypeError(f"arm_spec must be an ArmSpec, got {options.shown(arm_spec)}")
    if tendon_layout is not None and not isinstance(tendon_layout, arm_lib.TendonLayout):
        raise TypeError(f"tendon_layout must be a TendonLayout or a built-in layout's name, "
                        f"got {options.shown(tendon_layout)}")


def model_and_assets(get_model_and_assets: Callable, arm_spec, tendon_layout, **model_kwargs):
    """``get_model_and_assets(arm_spec, tendon_layout, **model_kwargs)``, kept for the last few arms:
    generating the MJCF takes a tenth of a second, which a run that makes an environment per
    evaluation would pay again and again for the same arm (an unhashable argument is not kept)."""
    try:
        return _kept_model_and_assets(get_model_and_assets, arm_spec, tendon_layout,
                                      tuple(sorted(model_kwargs.items())))
    except TypeError:  # unhashable: generated each time
        return get_model_and_assets(arm_spec, tendon_layout, **model_kwargs)


@functools.lru_cache(maxsize=16)
def _kept_model_and_assets(get_model_and_assets, arm_spec, tendon_layout, model_items):
    xml, assets = get_model_and_assets(arm_spec, tendon_layout, **dict(model_items))
    return xml, types.MappingProxyType(dict(assets))


@dataclasses.dataclass(frozen=True)
class LessonFactory:
    """Environments of one domain: ``physics`` (a ``Physics`` class) on the model of
    ``get_model_and_assets(arm_spec, tendon_layout, **model_kwargs)``; lessons use
    ``reach_task`` (called with ``reward``, ``initial_state``, ``random`` and the task
    keyword arguments)."""
    physics: type
    get_model_and_assets: Callable
    reach_task: Callable

    def environment(self, task, time_limit, arm_spec, tendon_layout, environment_kwargs,
                    **model_kwargs) -> control.Environment:
        time_limit = reach.check_time_limit(time_limit)
        environment_kwargs = options.environment_kwargs(environment_kwargs)
        check_arm(arm_spec, tendon_layout)
        physics = self.physics.from_xml_string(
            *model_and_assets(self.get_model_and_assets, arm_spec, tendon_layout, **model_kwargs))
        environment_kwargs.setdefault("control_timestep", CONTROL_TIMESTEP)
        return control.Environment(physics, task, time_limit=time_limit, **environment_kwargs)

    def lesson(self, reward, initial_state, time_limit, random, environment_kwargs, arm_spec,
               tendon_layout, task_kwargs, **task_options) -> control.Environment:
        """A ``reach_task`` environment; warns when the default targets were made with
        another arm than ``arm_spec``/``tendon_layout``."""
        check_arm(arm_spec, tendon_layout)
        if "target_pool" not in task_kwargs:
            fingerprint_lib.warn_if_other_arm(arm_spec, tendon_layout)
        task = self.reach_task(reward=reward, initial_state=initial_state, random=random,
                               **task_options, **task_kwargs)
        return self.environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs)

    def add_lessons(self, suite, setting: str) -> None:
        """Register ``lesson1``-``lesson3`` in ``suite`` (tagged ``LESSON_TAGS``); ``setting``
        ends each lesson's docstring (", with the quadruped standing.")."""
        for name, (reward, initial_state, summary) in LESSONS.items():
            suite.add(CURRICULUM, DRAWS_TARGETS, *LESSON_TAGS[name])(
                self._lesson_factory(name, reward, initial_state, summary + setting))

    def _lesson_factory(self, name, reward, initial_state, doc):
        def lesson(time_limit=LESSON_TIME_LIMIT, random=None, environment_kwargs=None,
                   arm_spec=None, tendon_layout=None, **task_kwargs):
            return self.lesson(reward, initial_state, time_limit, random, environment_kwargs,
                               arm_spec, tendon_layout, task_kwargs)
        lesson.__name__ = lesson.__qualname__ = name
        lesson.__doc__ = doc
        return lesson
