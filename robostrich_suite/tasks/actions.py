"""The reaching tasks' action: tendon contractions (m), checked and clipped into the arm's range.

A NaN or an action of the wrong shape or type raises ``ValueError`` naming what was expected;
values outside the range are clipped to it.
"""
from __future__ import annotations

import math

import numpy as np


def _real_vector(action, size: int) -> np.ndarray:
    """``action`` as an array of ``size`` real numbers (not copied), or a ValueError naming
    what was expected and what came (a scalar must not silently drive every tendon, nor 8
    values fail deep inside numpy)."""
    array = np.asarray(action)
    if array.dtype.kind not in "iuf":  # not bool, complex, str, object (None), ...
        raise ValueError(f"action must be {size} real numbers (float), got dtype {array.dtype} "
                         f"({type(action).__name__})")
    if array.shape != (size,):
        raise ValueError(f"action must have shape ({size},), got shape {array.shape}")
    return array


def validate_action(action, size: int) -> np.ndarray:
    """``action`` as a new float64 vector of ``size`` real numbers, or a ValueError naming what
    was expected and what came."""
    return _real_vector(action, size).astype(np.float64)


def check_action(action: np.ndarray, bounds, out: np.ndarray | None = None) -> np.ndarray:
    """Reject actions of the wrong shape or type and NaN/inf; clip the rest into ``bounds``,
    the (low, high) arrays ``physics.arm_control_bounds()`` gives.  The clipped action goes
    into ``out`` where given (the simulation's controls: the per-step path), else a new array;
    nothing is written unless the action is valid."""
    low, high = bounds
    array = _real_vector(action, len(low))
    # One dot product is finite when every entry is (and small enough that squares stay
    # finite, which real tendon inputs are); only otherwise look at each entry.
    if not math.isfinite(array.dot(array)):
        finite = np.isfinite(array)
        if not finite.all():
            bad = np.flatnonzero(~finite).tolist()
            raise ValueError(f"action has non-finite values at indices {bad}: {array}")
    # np.clip's result (in float64 whatever came), by two in-place steps: a third of its cost
    if out is None:
        out = np.empty(len(low))
    np.maximum(array, low, out=out)
    return np.minimum(out, high, out=out)
