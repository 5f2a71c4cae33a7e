"""robostrich_suite: dm_control domains for the tendon-driven Robostrich arm.

    import robostrich_suite
    env = robostrich_suite.load("robostrich", "lesson2")

``load`` mirrors ``dm_control.suite.load`` for this package's domains (which
dm_control's own registry does not know about).
"""
from __future__ import annotations

import collections
import os


def _choose_headless_renderer():
    """Without a display and without MUJOCO_GL, dm_control tries GLFW first and prints a GLFW
    error at import. Pick a backend that can work here instead: EGL, else OSMesa, else none
    (simulation needs no renderer). A MUJOCO_GL the user set is left alone."""
    if os.environ.get("MUJOCO_GL") or os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        return
    import ctypes.util
    for backend, library in (("egl", "EGL"), ("osmesa", "OSMesa")):
        if ctypes.util.find_library(library):
            os.environ["MUJOCO_GL"] = backend
            return
    os.environ["MUJOCO_GL"] = "disable"


_choose_headless_renderer()

_RENDERER_HINTS = {
    "osmesa": "OSMesa needs the OSMesa library (Debian/Ubuntu: apt-get install libosmesa6)",
    "egl": "EGL needs libEGL with a GPU driver or Mesa (Debian/Ubuntu: apt-get install libegl1)",
    "glfw": "GLFW needs a display (DISPLAY) and libglfw",
}


def _renderer_error(error: BaseException) -> ImportError:
    """dm_control loads the MUJOCO_GL backend at import; when that fails deep inside PyOpenGL
    (osmesa without libOSMesa: "'NoneType' object has no attribute 'glGetError'"), say which
    backend failed and what to do."""
    backend = os.environ.get("MUJOCO_GL", "")
    hint = _RENDERER_HINTS.get(backend.lower(), "see MuJoCo's rendering documentation")
    return ImportError(
        f"dm_control could not load the MUJOCO_GL={backend!r} renderer "
        f"({type(error).__name__}: {error}). {hint}; or set MUJOCO_GL=egl, or unset MUJOCO_GL and "
        f"robostrich_suite picks a headless backend that is installed (simulation needs none)")


try:
    # After the renderer choice: the domains import dm_control.
    from robostrich_suite import robostrich, robostrich_a1  # noqa: E402
except (ImportError, AttributeError, OSError) as _error:
    import traceback
    if any("_render" in frame.filename for frame in traceback.extract_tb(_error.__traceback__)):
        raise _renderer_error(_error) from _error
    raise

from robostrich_suite.policies import load_policy  # noqa: E402,F401  (a shipped trained policy)
from robostrich_suite.model import layouts
from robostrich_suite.tasks import lessons

_DOMAINS = collections.OrderedDict([("robostrich", robostrich), ("robostrich_a1", robostrich_a1)])

ALL_TASKS = tuple((domain, task) for domain, module in _DOMAINS.items()
                  for task in module.SUITE)
TASKS_BY_DOMAIN = collections.OrderedDict(
    (domain, tuple(module.SUITE)) for domain, module in _DOMAINS.items())
CURRICULUM_TASKS = tuple((domain, task) for domain, module in _DOMAINS.items()
                         for task in module.SUITE.tagged(lessons.CURRICULUM))
def mount(domain_name: str) -> str:
    """What ``domain_name``'s arm stands on: ``"frame"`` (immobile) or ``"quadruped"`` (walking)."""
    return _domain_module(domain_name).MOUNT


def tasks_tagged(domain_name: str, tag: str) -> tuple:
    """The tasks of ``domain_name`` with ``tag`` (robostrich_suite/tasks/lessons.py names the tags:
    ``heldout``, ``moving_start``, ``track``, ``draws_targets``, ``curriculum``, ``evaluation``),
    in registry order; an unknown domain is a ValueError naming the known ones."""
    return tuple(_domain_module(domain_name).SUITE.tagged(tag))


def targets_from_frame(domain_name: str, frame_targets):
    """(x, z) targets of the arm on its frame in ``domain_name``'s coordinates (the trunk frame on
    the quadruped), as its tasks take them."""
    return _domain_module(domain_name).targets_from_frame(frame_targets)


def _domain_module(domain_name: str):
    if domain_name not in _DOMAINS:
        raise ValueError(f"unknown domain {domain_name!r}; use one of {list(_DOMAINS)}")
    return _DOMAINS[domain_name]


def _register_gymnasium_environments() -> list[str]:
    """With gymnasium installed (the ``gym`` extra), ``gymnasium.make("robostrich/lesson2-v0")``
    works after ``import robostrich_suite``: every task as ``DOMAIN/TASK-v0``, made by
    ``robostrich_suite.gym_adapter.make``, which gymnasium imports by name when one is made (so
    the package never imports its adapter, which imports the package). Returns the ids."""
    try:
        import gymnasium
    except ImportError:
        return []
    ids = []
    for domain, task in ALL_TASKS:
        env_id = f"{domain}/{task}-v0"
        if env_id not in gymnasium.registry:
            gymnasium.register(id=env_id, entry_point="robostrich_suite.gym_adapter:make",
                               kwargs=dict(domain_name=domain, task_name=task))
        ids.append(env_id)
    return ids


_register_gymnasium_environments()


def load(domain_name, task_name, task_kwargs=None, environment_kwargs=None, visualize_reward=False):
    """Returns an environment from a domain name, task name and optional settings.

    Args:
      domain_name: e.g. ``"robostrich"``; see ``TASKS_BY_DOMAIN``.
      task_name: e.g. ``"lesson2"``.
      task_kwargs: keyword arguments of the task factory (``random`` seeds it); a
        ``tendon_layout`` may be a built-in layout's name (the layout alone; with its own
        targets: ``task_kwargs=robostrich_suite.model.layouts.task_kwargs(name)``) or the
        path of a layout file (``.json``/``.toml``, ``robostrich-design`` writes them).
      environment_kwargs: keyword arguments of ``dm_control.rl.control.Environment``.
      visualize_reward: accepted for ``dm_control.suite.load`` compatibility; unused.
    """
    del visualize_reward
    if domain_name not in _DOMAINS:
        raise ValueError(f"unknown domain {domain_name!r}; domains are {list(_DOMAINS)}")
    domain = _DOMAINS[domain_name]
    if task_name not in domain.SUITE:
        raise ValueError(f"domain {domain_name!r} has no task {task_name!r}; "
                         f"tasks are {list(domain.SUITE)}")
    if task_kwargs is not None and not isinstance(task_kwargs, dict):
        raise TypeError(f"task_kwargs must be a dict of the task's options, got {type(task_kwargs).__name__}")
    task_kwargs = dict(task_kwargs or {})
    if isinstance(task_kwargs.get("tendon_layout"), str):  # a built-in layout by name, or a layout file
        try:
            name = task_kwargs["tendon_layout"]
            task_kwargs["tendon_layout"] = (layouts.read_file(name)[1] if name.lower().endswith((".json", ".toml"))
                                            else layouts.build(name))
        except ValueError as error:
            raise ValueError(f"tendon_layout: {error}") from None
    if environment_kwargs is not None:
        task_kwargs["environment_kwargs"] = environment_kwargs
    return domain.SUITE[task_name](**task_kwargs)
