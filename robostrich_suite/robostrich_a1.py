"""Domain ``robostrich_a1``: the Robostrich arm on a walking A1-like quadruped (Sec. 4.2, 5.2).

Tasks:

* ``lesson1``-``lesson3``: the lessons of ``robostrich`` with the quadruped standing
  (pre-training);
* ``lesson4``: the lesson-2 reward while the quadruped trots, its trunk height
  changing over the episode (a random height held in the middle third);
* ``head_stabilize`` (Sec. 5.2.1, Fig. 9): while walking, keep the head at a constant
  height above the ground, level, and a constant distance ``P_d`` ahead of the trunk;
  the trunk height dips at 4-6 s and recovers at 8-10 s, as in Fig. 9A;
* ``narrow_gap`` (Sec. 5.2.2, Fig. 10): the quadruped walks up to a wall and stops;
  the head tracks six sub-targets in order, under the wall's overhang to the bottom of
  a narrow slot, up through it and to the final target on top.  The obstacle: a wall
  taller than the head can reach, standing on a horizontal shelf (0.50-0.53 m high)
  that reaches back from it and is pierced by a 7 cm slot; below the shelf it is open.
  The planar neck fits the slot; the head must go under the shelf and up through the
  slot.  The arm collides with all of it (its geoms carry the arm's contact bit).

The model is :func:`robostrich_suite.scenes.build_a1`; the tasks, the trunk frame
their targets and observations are given in, and the gait are in
:mod:`robostrich_suite.tasks.quadruped_tasks`.  Run ``robostrich-walk`` to see the
perturbation the arm gets.
"""
from __future__ import annotations

import functools

from dm_control import mujoco
from dm_control.utils import containers

from robostrich_suite import quadruped_physics
from robostrich_suite import scenes
from robostrich_suite.model import legs as legs_lib
from robostrich_suite.tasks import lessons, options, target_samplers
from robostrich_suite.tasks import quadruped_tasks as tasks
from robostrich_suite.tasks.conventions import CONTROL_TIMESTEP

SUITE = containers.TaggedTasks()
MOUNT = "quadruped"  # the arm rides the walking quadruped


@functools.lru_cache(maxsize=4)
def _default_xml(scene: str) -> str:
    return scenes.build_a1(scene=scene).to_xml_string()


def get_model_and_assets(arm_spec=None, tendon_layout=None, scene: str = "flat"):
    """The MJCF of the arm on the quadruped on a floor (no assets); the default model is
    what ``xml/robostrich_a1.xml`` holds."""
    if arm_spec is None and tendon_layout is None:
        return _default_xml(scene), {}
    return scenes.build_a1(arm_spec, tendon_layout, scene).to_xml_string(), {}


class Physics(quadruped_physics.QuadrupedPhysicsMixin, mujoco.Physics):
    """The arm's accessors plus the quadruped's and the trunk frame (``QuadrupedPhysicsMixin``)."""


_FACTORY = lessons.LessonFactory(Physics, get_model_and_assets, tasks.QuadrupedReach)
_FACTORY.add_lessons(SUITE, ", with the quadruped standing.")


# Targets of the arm on its frame in this domain's coordinates: its trunk frame, standing.
targets_from_frame = tasks.frame_to_trunk


@SUITE.add(lessons.CURRICULUM, lessons.DRAWS_TARGETS, lessons.WALKING)
def lesson4(time_limit=tasks.LESSON4_TIME_LIMIT, random=None, environment_kwargs=None,
            arm_spec=None, tendon_layout=None, height_range=tasks.LESSON4_HEIGHT_RANGE,
            **task_kwargs):
    """Lesson 4: eq. 10 while the quadruped trots, trunk height changing (random per episode)."""
    height_range = options.pair("height_range", height_range, legs_lib.MIN_TRUNK_HEIGHT, legs_lib.MAX_TRUNK_HEIGHT,
                                " m (a trunk height the legs hold)")
    heights = functools.partial(tasks.lesson4_heights, time_limit=time_limit,
                                height_range=height_range)
    return _FACTORY.lesson("lesson2", "fixed", time_limit, random, environment_kwargs, arm_spec,
                           tendon_layout, task_kwargs, legs="walk", trunk_heights=heights)


@SUITE.add(lessons.EVALUATION)
def head_stabilize(time_limit=tasks.HEAD_STABILIZE_TIME_LIMIT, random=None,
                   environment_kwargs=None, arm_spec=None, tendon_layout=None,
                   distance=tasks.HEAD_STABILIZE_DISTANCE, height=tasks.HEAD_STABILIZE_HEIGHT,
                   trunk_heights=tasks.HEAD_STABILIZE_HEIGHTS, **task_kwargs):
    """Sec. 5.2.1: hold the head ``height`` above ground, level, ``distance`` (P_d) ahead of
    the trunk, while walking with the trunk height of Fig. 9A."""
    reach = target_samplers.MAX_TARGET_DISTANCE
    distance, height = (options.number(name, value, -reach, reach, f"a finite distance from {-reach:g} to {reach:g} m")
                        for name, value in (("distance", distance), ("height", height)))
    task = tasks.QuadrupedReach(reward="lesson2", initial_state="fixed", random=random,
                                legs="walk", trunk_heights=trunk_heights,
                                target_pool=[[distance, height]], **task_kwargs)
    return _FACTORY.environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs)


@SUITE.add(lessons.EVALUATION)
def narrow_gap(time_limit=None, random=None, environment_kwargs=None, arm_spec=None,
               tendon_layout=None, steps_per_target=tasks.NARROW_GAP_STEPS_PER_TARGET,
               **task_kwargs):
    """Sec. 5.2.2: walk to the wall, then the head tracks the six sub-targets of Fig. 10,
    ``steps_per_target`` control steps each (``switch="reached"``: the next one once the
    head is within the position tolerance of the current one; see ``tasks.NarrowGap``)."""
    task = tasks.NarrowGap(steps_per_target=steps_per_target, random=random, reward="lesson2",
                           **task_kwargs)
    if time_limit is None:
        time_limit = len(task.targets) * steps_per_target * CONTROL_TIMESTEP
    return _FACTORY.environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs,
                                scene="narrow_gap")
