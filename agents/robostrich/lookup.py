"""The no-learning baseline: nearest stored level pose, hold its inputs.

The reaching task is quasi-static: a constant tendon input brings the head to
rest in about 1.5 s.  `LookupPolicy` holds the shipped input of the stored
level pose (robostrich_suite/data/level_head_poses.npz) nearest to the target,
which is the bar an RL agent must clear.
"""
from typing import Optional

import numpy as np

from robostrich_suite import targets as targets_lib

LABEL = "lookup"


def lookup_table(poses: Optional[dict] = None, heldout=None,
                 exclusion: float = targets_lib.MIN_TARGET_SPACING) -> dict:
    """The stored poses the lookup may use: every pose farther than `exclusion` (1 cm) from each held-out target.

    Why this exclusion: `targets._split` holds out every fifth of a greedy subset
    whose members are >= 1 cm apart (`distinct_indices`), so every held-out
    target is itself a stored pose, and the other stored poses lie within 1 cm
    of some member.  Dropping everything closer than 1 cm to a held-out target
    removes the held-out poses and their near copies, and keeps every training
    target (each >= 1 cm from all held-out ones).  Returns ``head_position``
    (n, 2), ``head_attitude`` (n,) and ``control`` (n, 9).
    """
    poses = targets_lib.level_head_poses() if poses is None else poses
    heldout = targets_lib.heldout_targets() if heldout is None else heldout
    position = np.asarray(poses["head_position"], np.float64)
    heldout = np.asarray(heldout, np.float64).reshape(-1, 2)
    distance = np.linalg.norm(position[:, None, :] - heldout[None, :, :], axis=2).min(axis=1)
    keep = distance >= exclusion
    return {key: np.asarray(poses[key], np.float64)[keep]
            for key in ("head_position", "head_attitude", "control")}


def nearest(table: dict, target) -> int:
    """Index of the table pose nearest to `target` (np.argmin: the first on ties)."""
    distance = np.linalg.norm(np.asarray(table["head_position"], np.float64) - np.asarray(target, np.float64), axis=1)
    return int(np.argmin(distance))


class LookupPolicy:
    """Holds the stored tendon inputs of the table pose nearest to the observed `target_position` (ties: first).

    `select_action(flat_obs)` takes the flattened observation (like the SAC
    actors), so it plugs into agents.robostrich.evaluate.evaluation; `flattener` (an
    agents.replay.ObservationFlattener) says where `target_position` lies.
    """

    def __init__(self, flattener, table: Optional[dict] = None):
        keys = flattener.keys or ()
        if "target_position" not in keys:
            raise ValueError(f"the lookup needs a 'target_position' observation; this one has {list(keys) or 'none'}")
        i = keys.index("target_position")
        start = int(sum(flattener.sizes[:i]))
        if flattener.sizes[i] != 2:
            raise ValueError(f"target_position has {flattener.sizes[i]} values, expected 2 (x, z)")
        self._slice = slice(start, start + 2)
        self.table = lookup_table() if table is None else table

    def control_for(self, target) -> np.ndarray:
        return np.asarray(self.table["control"][nearest(self.table, target)], np.float64).copy()

    def select_action(self, flat_obs) -> np.ndarray:
        return self.control_for(np.asarray(flat_obs, np.float64)[self._slice])
