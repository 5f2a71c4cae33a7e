"""How much of the paper's blue region an arm really holds level (the layout comparison's metric).

The blue region of Fig. 6 is the set of kinematic head positions with the head
level (:meth:`workspace.KinematicSamples.level`).  We count it in square cells of
:data:`CELL_SIZE`; a cell is *covered* when the actuated arm holds its head level
(:meth:`workspace.ActuatedSamples.level`) within :data:`HOLD_DISTANCE` of one of
the cell's blue samples.  Coverage is the covered share of the cells.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from robostrich_suite.studies import workspace

CELL_SIZE = 0.02  # m, side of a blue-region cell
HOLD_DISTANCE = 0.02  # m, how near a held level head must come to a blue sample


@dataclasses.dataclass(frozen=True)
class BlueRegion:
    """The kinematic level samples and the cells they fall in."""
    head_position: np.ndarray  # (n, 2) x, z of the level kinematic samples
    joint_angles: np.ndarray  # (n, num_joints) rad, Table 1 order
    cell_of: np.ndarray  # (n,) index into ``cells`` of each sample
    cells: np.ndarray  # (m, 2) integer cell coordinates (floor(position / CELL_SIZE))

    @classmethod
    def from_samples(cls, samples: workspace.KinematicSamples) -> "BlueRegion":
        level = samples.level()
        position = samples.head_position[level]
        cells, cell_of = np.unique(np.floor(position / CELL_SIZE).astype(int), axis=0,
                                   return_inverse=True)
        return cls(position, samples.joint_angles[level], cell_of.reshape(-1),
                   cells.reshape(-1, 2))

    @property
    def num_cells(self) -> int:
        return len(self.cells)

    def cell_centres(self) -> np.ndarray:
        return (self.cells + 0.5) * CELL_SIZE

    def covered(self, held_positions) -> np.ndarray:
        """(m,) bool: cells with a held level head within HOLD_DISTANCE of one of their samples."""
        held = np.asarray(held_positions, np.float64).reshape(-1, 2)
        covered = np.zeros(self.num_cells, bool)
        if len(held) == 0 or len(self.head_position) == 0:
            return covered
        near = np.zeros(len(self.head_position), bool)
        for start in range(0, len(held), 2048):  # bounded memory for large pose sets
            chunk = held[start:start + 2048]
            distance = np.linalg.norm(self.head_position[:, None] - chunk[None], axis=2)
            near |= distance.min(axis=1) <= HOLD_DISTANCE
        np.logical_or.at(covered, self.cell_of, near)
        return covered

    def coverage(self, held_positions) -> float:
        """Share of the cells covered (0 for an empty region)."""
        return float(self.covered(held_positions).mean()) if self.num_cells else 0.0


def held_level_positions(samples: workspace.ActuatedSamples) -> np.ndarray:
    """(k, 2) head positions of the settled, level poses of ``samples``."""
    return samples.head_position[samples.level()]
