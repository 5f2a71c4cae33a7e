"""Checks of the tasks' options (``task_kwargs``), each failure a TypeError or ValueError naming
the option.

Options come from Python and from JSON (robostrich-train --task-kwargs), where a string or a
list lands wherever a number or an object was meant: without these checks it surfaced as an
AttributeError in the first episode, or as numpy's words without the option's name. Every
number has a finite bound, as the commands' flags have (``robostrich_suite.parsing``): a
``time_limit`` of 1e300 s is a typo, not an experiment.
"""
from __future__ import annotations

import math
import numbers

import numpy as np

from robostrich_suite import parsing

MAX_SECONDS = parsing.MAX_SECONDS  # an episode, a settling or release time
MAX_SEED = 2**32 - 1  # numpy's RandomState takes seeds in [0, 2**32)
MAX_WEIGHT = 1e6  # a reward weight: the defaults are 0.02 to 2
MAX_SCALE = 10.0  # a domain-randomisation scale of a nominal parameter
MAX_COUNT = parsing.MAX_COUNT


def shown(value) -> str:
    """``value`` for an error message: its type unless a number, its repr cut to 60 characters."""
    text = repr(value)
    text = text if len(text) <= 60 else text[:57] + "..."
    return text if _is_real(value) else f"{type(value).__name__} {text}"


def _is_real(value) -> bool:
    return isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_))


def real(name: str, value) -> float:
    """``value`` as a float; a TypeError naming ``name`` unless it is a real number (not a bool)."""
    if not _is_real(value):
        raise TypeError(f"{name} must be a number, got {shown(value)}")
    try:
        return float(value)
    except OverflowError:  # an int of 400 digits
        raise ValueError(f"{name} must be a finite number, got {shown(value)}") from None


def number(name: str, value, minimum: float, maximum: float, what: str | None = None,
           above: bool = False) -> float:
    """``value`` as a finite float in [minimum, maximum] ((minimum, maximum] with ``above``);
    ``what`` it must be, bounds included, for the message (default: the bounds alone)."""
    result = real(name, value)
    low_ok = result > minimum if above else result >= minimum
    if not (math.isfinite(result) and low_ok and result <= maximum):
        if what is None:
            what = (f"a number above {minimum:g} and at most {maximum:g}" if above
                    else f"a number from {minimum:g} to {maximum:g}")
        raise ValueError(f"{name} must be {what}, got {shown(value)}")
    return result


def whole(name: str, value, minimum: int, maximum: int, what: str = "a whole number") -> int:
    """``value`` as an int in [minimum, maximum]; a float must be whole (2.0, not 2.5)."""
    result = real(name, value)
    if not (math.isfinite(result) and result == int(result) and minimum <= result <= maximum):
        raise ValueError(f"{name} must be {what} from {minimum} to {maximum}, got {shown(value)}")
    return int(value) if isinstance(value, numbers.Integral) else int(result)


def share(name: str, value) -> float:
    """A share of the episodes, in [0, 1]."""
    return number(name, value, 0.0, 1.0, "a share between 0 and 1")


def seconds(name: str, value, maximum: float = MAX_SECONDS) -> float:
    """A positive, finite duration of at most ``maximum`` seconds."""
    return number(name, value, 0.0, maximum, f"positive seconds, at most {maximum:g}", above=True)


def flag(name: str, value) -> bool:
    """True or False, not a string that reads like one."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be true or false, got {shown(value)}")
    return bool(value)


def seed(name: str, value):
    """None, a ``np.random.RandomState`` or a whole-number seed in [0, 2**32)."""
    if value is None or isinstance(value, np.random.RandomState):
        return value
    if not isinstance(value, numbers.Integral) or isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be a whole-number seed or a numpy RandomState, got {shown(value)}")
    return whole(name, value, 0, MAX_SEED, "a seed")


def array(name: str, value, what: str) -> np.ndarray:
    """``value`` as a float64 array; a ValueError naming ``name`` (and ``what`` it must be) if
    numpy cannot read it as numbers (a string, a ragged list)."""
    try:
        return np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be {what}, got {shown(value)}") from None


def pair(name: str, value, minimum: float, maximum: float, unit: str = "") -> tuple:
    """(low, high), two numbers with minimum <= low <= high <= maximum (``unit`` for the message)."""
    what = f"a number from {minimum:g} to {maximum:g}{unit}"
    try:
        low, high = value
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be (low, high), each {what}, got {shown(value)}") from None
    low, high = number(f"{name}[0]", low, minimum, maximum, what), number(f"{name}[1]", high, minimum, maximum, what)
    if low > high:
        raise ValueError(f"{name} must be (low, high) with low <= high, got {shown(value)}")
    return low, high


def instance(name: str, value, cls):
    """None, a ``cls`` or a dict of its fields (JSON's form) made into one; anything else, or an
    unknown or bad field, is an error naming ``name``."""
    if value is None or isinstance(value, cls):
        return value
    if not isinstance(value, dict):
        raise TypeError(f"{name} must be a {cls.__name__} or a dict of its fields, got {shown(value)}")
    try:
        return cls(**value)
    except TypeError as error:  # an unknown field
        raise TypeError(f"{name}: {error}") from None
    except ValueError as error:
        raise ValueError(f"{name}: {error}") from None


ENVIRONMENT_OPTIONS = ("control_timestep", "n_sub_steps", "flat_observation", "legacy_step")


def environment_kwargs(value) -> dict:
    """dm_control's ``control.Environment`` options, checked (``time_limit`` is the task's own)."""
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise TypeError(f"environment_kwargs must be a dict, got {shown(value)}")
    unknown = sorted(set(map(str, value)) - set(ENVIRONMENT_OPTIONS))
    if unknown:
        raise TypeError(f"environment_kwargs has no option {', '.join(unknown)} "
                        f"(known: {', '.join(ENVIRONMENT_OPTIONS)}; time_limit is the task's)")
    checked = dict(value)
    if "control_timestep" in checked:
        checked["control_timestep"] = seconds("environment_kwargs control_timestep", checked["control_timestep"])
    if "n_sub_steps" in checked:
        checked["n_sub_steps"] = whole("environment_kwargs n_sub_steps", checked["n_sub_steps"], 1, MAX_COUNT)
    for name in ("flat_observation", "legacy_step"):
        if name in checked:
            checked[name] = flag(f"environment_kwargs {name}", checked[name])
    return checked
