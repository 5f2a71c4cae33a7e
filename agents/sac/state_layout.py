"""A stored learner state of an earlier layout, laid out as this version's learner keeps it.

Checkpoints store the learner's state as named arrays (agents/trees.py). Two layouts came before
this one, and a run stored in them resumes here unchanged:

- the twin critics as two networks, ``q1`` and ``q2`` (``'q1/~/linear_0'``, or ``'q1_linear_0'``,
  ``'q1_norm_0'``, ``'q1_head'`` with layer norm); now one set of parameters stacked on a leading
  axis of 2 (agents/sac/networks.py: ``CRITIC``), the first critic first;
- Adam's moments as one array per parameter; now one vector per parameter group
  (``optax.flatten``), the parameters' arrays raveled and concatenated in their tree order.

The numbers are the same numbers: a stored run continues as it would have in its own layout, up to
the rounding of the new order of operations.
"""
import re

import numpy as np

from agents.sac.networks import CRITIC

_TWINS = ("q1", "q2")
_CRITIC_GROUPS = (".q_params", ".target_q_params")
_MOMENT = re.compile(r"^(\.(?:policy|q)_opt_state\[\d+\]\.(?:mu|nu))\['([^']*)'\]\['([^']*)'\]$")
_PARAMETER = re.compile(r"^(\.[a-z_]+)\['([^']*)'\]\['([^']*)'\]$")


def upgrade(arrays: dict) -> dict:
    """``arrays`` ({path: array}, agents/trees.py) in this version's layout; already in it, as given.
    Anything else about them (a missing array, a shape) is left for the rebuild to name."""
    if not isinstance(arrays, dict):
        return arrays
    return _ravel_moments(_stack_twin_critics(arrays))


def _twin_module(module: str):
    """(index of the twin, the stacked module's name) of an earlier critic module, else None."""
    for index, twin in enumerate(_TWINS):
        if module.startswith(twin + "/") or module.startswith(twin + "_"):
            return index, CRITIC + module[len(twin):]
    return None


def _stack_twin_critics(arrays: dict) -> dict:
    pairs, out = {}, {}
    for path, value in arrays.items():
        match = _PARAMETER.match(path) or _MOMENT.match(path)
        twin = match and _twin_module(match.group(2))
        in_critics = match and (match.group(1) in _CRITIC_GROUPS or match.group(1).startswith(".q_opt_state"))
        if not twin or not in_critics:
            out[path] = value
            continue
        index, module = twin
        pairs.setdefault(f"{match.group(1)}['{module}']['{match.group(3)}']", [None, None])[index] = value
    for path, (first, second) in pairs.items():
        if first is None or second is None:
            raise ValueError(f"the stored learner has one twin critic's {path} without the other's")
        out[path] = np.stack([np.asarray(first), np.asarray(second)])
    return out


def _ravel_moments(arrays: dict) -> dict:
    groups, out = {}, {}
    for path, value in arrays.items():
        match = _MOMENT.match(path)
        if match is None:
            out[path] = value
        else:
            groups.setdefault(match.group(1), []).append(((match.group(2), match.group(3)), value))
    for prefix, leaves in groups.items():  # a tree's leaves in jax's order: each dict's keys sorted
        out[prefix] = np.concatenate([np.ravel(value) for _, value in sorted(leaves, key=lambda leaf: leaf[0])])
    return out
