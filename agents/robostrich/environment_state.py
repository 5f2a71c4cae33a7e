"""The open episode of a dm_control environment as plain data, so that a checkpoint needs no pickle.

A resumed run continues its open episode bit for bit in a freshly made environment of the same
lesson (same task options, same seed), into which :func:`restore` puts back:

* the simulation: MuJoCo's integration state (``mj_getState``, everything a step reads), its
  warning counts, the model fields the task changed since the environment was made (domain
  randomisation, a target's place), found by comparing with a copy taken then
  (:func:`model_reference`), and the physics' own per-episode variables where it declares them
  (``checkpoint_state``/``restore_checkpoint_state``);
* the task: its RandomState and its per-episode variables.  A task that declares them
  (``checkpoint_state``/``restore_checkpoint_state``, as this package's tasks do: they also hold
  configuration, samplers, gait tables and schedule factories, which their constructor rebuilds
  from the options the fingerprint checks) gives exactly those; any other task (dm_control's
  suite) has every attribute stored, each of which must be plain data, else
  ``checkpoint.NotData`` (the run then stores no episode: a resume starts a fresh one);
* the Environment's step count and reset flag, and the loop's last timestep and flat observation.

Nothing is built from a file's content: values are written into objects the running code made.
"""
from collections.abc import Mapping

import dm_env
import mujoco
import numpy as np

from agents import checkpoint
from agents.checkpoint import NotData

_INTEGRATION = mujoco.mjtState.mjSTATE_INTEGRATION
_RANDOM = "_random"  # dm_control's base.Task keeps its RandomState here


def model_reference(env) -> dict:
    """Copies of ``env``'s model fields as made, before any episode changes them: what
    :func:`capture` compares with, to store only the fields a task changed."""
    return {name: np.array(value) for name, value in _model_fields(env.physics).items()}


def _model_fields(physics) -> dict:
    """The model's arrays and simulation options, by name ("opt.<field>" for an option)."""
    model = physics.model.ptr
    fields = {name: value for name, value in _attributes(model) if isinstance(value, np.ndarray)}
    for name, value in _attributes(model.opt):
        if isinstance(value, (np.ndarray, int, float)) and not isinstance(value, bool):
            fields["opt." + name] = value
    return fields


def _attributes(struct):
    for name in dir(struct):
        if not name.startswith("_"):
            value = getattr(struct, name)
            if not callable(value):
                yield name, value


def capture(env, timestep, flat_observation, reference: dict) -> dict:
    """``env``'s open episode (with the loop's last ``timestep`` and its ``flat_observation``) as
    plain data; ``reference``: :func:`model_reference` of ``env`` when it was made."""
    physics, task = env.physics, env.task
    for name in ("_step_count", "_reset_next_step"):
        if not hasattr(env, name):
            raise NotData(f"{type(env).__name__} is no dm_control control.Environment (no {name})")
    model, data = physics.model.ptr, physics.data.ptr
    integration = np.empty(mujoco.mj_stateSize(model, _INTEGRATION), np.float64)
    mujoco.mj_getState(model, data, integration, _INTEGRATION)
    changed = {}
    for name, value in _model_fields(physics).items():
        nominal = reference.get(name)
        if nominal is None or np.shape(value) != np.shape(nominal) or \
                np.asarray(value).tobytes() != np.asarray(nominal).tobytes():
            changed[name] = np.array(value)
    state = {
        "physics": {"integration": integration, "warnings": np.array(physics.data.warning.number),
                    "model": changed, "variables": _variables(physics, "physics")},
        "task": {"kind": _kind(task), "random": task.random.get_state(), "variables": _variables(task, "task")},
        "step_count": int(env._step_count), "reset_next_step": bool(env._reset_next_step),
        "timestep": None if timestep is None else _timestep(timestep),
        "flat_observation": flat_observation,
    }
    try:
        checkpoint.check_plain(state, "environment")
    except NotData as error:
        raise NotData(f"{type(task).__name__}: {error}") from None
    return state


def _kind(owner) -> str:
    return f"{type(owner).__module__}.{type(owner).__qualname__}"


def _variables(owner, what: str) -> dict:
    """What ``owner`` declares with ``checkpoint_state``; else, for a task, all its attributes."""
    if hasattr(owner, "checkpoint_state"):
        return {"declared": owner.checkpoint_state()}
    if what == "physics":
        return {"declared": None}
    return {"attributes": {name: value for name, value in vars(owner).items() if name != _RANDOM}}


def _timestep(timestep) -> dict:
    observation = timestep.observation
    return {"step_type": int(timestep.step_type), "reward": timestep.reward, "discount": timestep.discount,
            "observation": dict(observation) if isinstance(observation, Mapping) else observation}


def restore(env, state: dict, reference: dict):
    """Put the episode :func:`capture` stored into ``env``, freshly made for the same lesson;
    returns (timestep, flat observation). ValueError naming what does not fit."""
    physics, task = env.physics, env.task
    if state["task"]["kind"] != _kind(task):
        raise ValueError(f"the stored episode is one of {state['task']['kind']}, this environment's task is "
                         f"{_kind(task)}")
    model, data = physics.model.ptr, physics.data.ptr
    stored = state["physics"]
    fields = _model_fields(physics)
    for name, value in stored["model"].items():
        live = fields.get(name)
        if name not in reference or live is None or np.shape(value) != np.shape(live):
            raise ValueError(f"the stored model field {name!r} does not fit this environment's model")
        if name.startswith("opt.") and not isinstance(live, np.ndarray):
            setattr(model.opt, name[4:], type(live)(value))
        else:
            np.copyto(live, value, casting="same_kind")
    integration = np.asarray(stored["integration"], np.float64)
    if integration.shape != (mujoco.mj_stateSize(model, _INTEGRATION),):
        raise ValueError(f"the stored simulation state has {integration.size} numbers, this model's "
                         f"{mujoco.mj_stateSize(model, _INTEGRATION)}")
    mujoco.mj_setState(model, data, integration, _INTEGRATION)
    # What the last step computed after integrating (dm_control's step ends with mj_step1 and
    # begins the next with mj_step2, which reads it), from the state it computed it from.
    mujoco.mj_step1(model, data)
    np.copyto(physics.data.warning.number, stored["warnings"])
    _restore_variables(physics, stored["variables"], "physics")
    random_state = state["task"]["random"]
    if not (isinstance(random_state, tuple) and len(random_state) == 5 and random_state[0] == "MT19937"):
        raise ValueError("the stored task RNG state is not a RandomState's")
    task.random.set_state(random_state)
    _restore_variables(task, state["task"]["variables"], "task")
    env._step_count, env._reset_next_step = int(state["step_count"]), bool(state["reset_next_step"])
    stored_timestep = state["timestep"]
    timestep = None if stored_timestep is None else dm_env.TimeStep(
        dm_env.StepType(stored_timestep["step_type"]), stored_timestep["reward"], stored_timestep["discount"],
        stored_timestep["observation"])
    return timestep, state["flat_observation"]


def _restore_variables(owner, variables: dict, what: str) -> None:
    if "declared" in variables:
        declared = variables["declared"]
        if (declared is None) != (not hasattr(owner, "restore_checkpoint_state")):
            raise ValueError(f"the stored {what} state does not fit {type(owner).__name__}")
        if declared is not None:
            owner.restore_checkpoint_state(declared)
        return
    attributes = variables["attributes"]
    live = {name for name in vars(owner) if name != _RANDOM}
    if hasattr(owner, "restore_checkpoint_state") or set(attributes) != live:
        raise ValueError(f"the stored {what} attributes {sorted(attributes)} do not fit {type(owner).__name__}'s "
                         f"{sorted(live)}")
    for name, value in attributes.items():
        setattr(owner, name, value)
