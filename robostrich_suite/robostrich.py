"""Domain ``robostrich``: the Robostrich arm on an immobile frame (paper Sec. 4.2).

Tasks (one per curriculum lesson, plus evaluation):

* ``lesson1``: reach the target position, eq. 9 reward, fixed initial state;
* ``lesson2``: reach it with the head level, eq. 10 reward, fixed initial state;
* ``lesson3``: as lesson 2, each episode starts where the previous one ended;
* ``track``: three targets in order within one episode (Fig. 7), eq. 10 reward.

Control timestep 0.008 s (the paper's) = 4 physics steps of 0.002 s.  Episodes
last ``time_limit`` seconds (default 2 s = 250 control steps): the tendon
servos bring the neck to rest in about 1.5 s.  Extra ``task_kwargs`` go to
:class:`robostrich_suite.reach.Reach` (tolerances, reward weights, target pool,
desired attitude); ``arm_spec`` and ``tendon_layout`` swap in another arm.
"""
from __future__ import annotations

from dm_control import mujoco
from dm_control.rl import control
from dm_control.utils import containers

from robostrich_suite import arm as arm_lib
from robostrich_suite import arm_physics, reach
from robostrich_suite.conventions import CONTROL_TIMESTEP, PHYSICS_TIMESTEP
DEFAULT_TIME_LIMIT = 2.0  # s
TRACK_STEPS_PER_TARGET = 250
XML_PRECISION = 10  # significant digits in the generated MJCF (readable, and exact enough)

SUITE = containers.TaggedTasks()


def get_model_and_assets(arm_spec=None, tendon_layout=None):
    """The MJCF of the arm on its frame, generated from Table 1 (no assets)."""
    model = arm_lib.build_frame_arm(arm_spec, tendon_layout)
    model.option.timestep = PHYSICS_TIMESTEP
    return model.to_xml_string(precision=XML_PRECISION), {}


class Physics(arm_physics.ArmPhysicsMixin, mujoco.Physics):
    """Physics with the arm's named accessors (see ``ArmPhysicsMixin``)."""


def _environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs):
    time_limit = reach.check_time_limit(time_limit)
    physics = Physics.from_xml_string(*get_model_and_assets(arm_spec, tendon_layout))
    environment_kwargs = dict(environment_kwargs or {})
    environment_kwargs.setdefault("control_timestep", CONTROL_TIMESTEP)
    return control.Environment(physics, task, time_limit=time_limit, **environment_kwargs)


def _warn_if_other_arm(arm_spec, tendon_layout) -> None:
    """targets.warn_if_other_arm, imported here: a module-level import would put
    robostrich_suite.targets in sys.modules at package import, and
    `python -m robostrich_suite.targets` would print runpy's RuntimeWarning."""
    from robostrich_suite import targets
    targets.warn_if_other_arm(arm_spec, tendon_layout)


def _lesson(reward, initial_state, time_limit, random, environment_kwargs, arm_spec,
            tendon_layout, task_kwargs):
    if "target_pool" not in task_kwargs:
        _warn_if_other_arm(arm_spec, tendon_layout)
    task = reach.Reach(reward=reward, initial_state=initial_state, random=random, **task_kwargs)
    return _environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs)


@SUITE.add("curriculum")
def lesson1(time_limit=DEFAULT_TIME_LIMIT, random=None, environment_kwargs=None,
            arm_spec=None, tendon_layout=None, **task_kwargs):
    """Lesson 1: position only (eq. 9), from the fixed initial pose."""
    return _lesson("lesson1", "fixed", time_limit, random, environment_kwargs, arm_spec,
                   tendon_layout, task_kwargs)


@SUITE.add("curriculum")
def lesson2(time_limit=DEFAULT_TIME_LIMIT, random=None, environment_kwargs=None,
            arm_spec=None, tendon_layout=None, **task_kwargs):
    """Lesson 2: position and level head (eq. 10), from the fixed initial pose."""
    return _lesson("lesson2", "fixed", time_limit, random, environment_kwargs, arm_spec,
                   tendon_layout, task_kwargs)


@SUITE.add("curriculum")
def lesson3(time_limit=DEFAULT_TIME_LIMIT, random=None, environment_kwargs=None,
            arm_spec=None, tendon_layout=None, **task_kwargs):
    """Lesson 3: as lesson 2, each episode continues from the previous final state."""
    return _lesson("lesson2", "continue", time_limit, random, environment_kwargs, arm_spec,
                   tendon_layout, task_kwargs)


@SUITE.add("evaluation")
def track(time_limit=None, random=None, environment_kwargs=None, arm_spec=None,
          tendon_layout=None, targets=None, steps_per_target=TRACK_STEPS_PER_TARGET,
          **task_kwargs):
    """Reach three targets in order (Fig. 7); per-step errors are in the observation."""
    if targets is None:
        _warn_if_other_arm(arm_spec, tendon_layout)
    task = reach.Track(targets=targets, steps_per_target=steps_per_target, random=random,
                       **task_kwargs)
    if time_limit is None:
        time_limit = len(task.targets) * steps_per_target * CONTROL_TIMESTEP
    return _environment(task, time_limit, arm_spec, tendon_layout, environment_kwargs)
