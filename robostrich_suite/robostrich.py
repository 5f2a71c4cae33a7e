"""Domain ``robostrich``: the Robostrich arm on an immobile frame (paper Sec. 4.2).

Tasks (one per curriculum lesson, plus evaluation):

* ``lesson1``: reach the target position, eq. 9 reward, fixed initial state;
* ``lesson2``: reach it with the head level, eq. 10 reward, fixed initial state;
* ``lesson3``: as lesson 2, each episode starts where the previous one ended;
* ``track``: three targets in order within one episode (Fig. 7), eq. 10 reward.

Control timestep 0.008 s (the paper's) = 4 physics steps of 0.002 s.  Episodes
last ``time_limit`` seconds (default 2 s = 250 control steps): the tendon
servos bring the neck to rest in about 1.5 s.  Extra ``task_kwargs`` go to
:class:`robostrich_suite.tasks.reach.Reach` (tolerances, reward weights, target pool,
desired attitude); ``arm_spec`` and ``tendon_layout`` swap in another arm.
"""
from __future__ import annotations

import collections.abc  # noqa: F401  dm_control.utils.containers uses it without importing it

from dm_control.utils import containers

from robostrich_suite import fingerprint as fingerprint_lib
from robostrich_suite import scenes
from robostrich_suite.tasks import lessons, reach
from robostrich_suite.tasks.track import Track
from robostrich_suite.tasks.conventions import CONTROL_TIMESTEP, PHYSICS_TIMESTEP

TRACK_STEPS_PER_TARGET = 250
XML_PRECISION = 10  # significant digits in the generated MJCF (readable, and exact enough)

SUITE = containers.TaggedTasks()
MOUNT = "frame"  # the arm stands on an immobile frame


def get_model_and_assets(arm_spec=None, tendon_layout=None):
    """The MJCF of the arm on its frame, generated from Table 1 (no assets)."""
    model = scenes.build_frame_arm(arm_spec, tendon_layout)
    model.option.timestep = PHYSICS_TIMESTEP
    return model.to_xml_string(precision=XML_PRECISION), {}


# The arm on its frame with its accessors: one class for the domain and the studies.
Physics = scenes.FramePhysics


_FACTORY = lessons.LessonFactory(Physics, get_model_and_assets, reach.Reach)
_FACTORY.add_lessons(SUITE, ".")


def targets_from_frame(frame_targets):
    """Targets of the arm on its frame in this domain's coordinates: the same ones."""
    return frame_targets


@SUITE.add(lessons.EVALUATION, lessons.TRACK)
def track(time_limit=None, random=None, environment_kwargs=None, arm_spec=None,
          tendon_layout=None, targets=None, steps_per_target=TRACK_STEPS_PER_TARGET,
          **task_kwargs):
    """Reach three targets in order (Fig. 7); per-step errors are in the observation."""
    lessons.check_arm(arm_spec, tendon_layout)
    if targets is None:
        fingerprint_lib.warn_if_other_arm(arm_spec, tendon_layout)
    task = Track(targets=targets, steps_per_target=steps_per_target, random=random,
                       **task_kwargs)
    if time_limit is None:
        time_limit = len(task.targets) * steps_per_target * CONTROL_TIMESTEP
    return _FACTORY.environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs)
