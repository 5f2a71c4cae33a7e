"""What ``robostrich-design`` scores a routing by: the paper's tests and the narrow gap.

* **rolling / lever**: the movement tests' attitude ranges at equal head travel
  (``layout_compare.movement_ratio``, as ``robostrich-layouts``); the paper: well below 1;
* **coverage**: the share of Fig. 6's blue-region cells held level (``coverage.BlueRegion``, as
  ``robostrich-layouts``), estimated on a fixed, spread subset of the cells with one sought pose
  each: every routing gets the same cells, so trials compare;
* **gap column**: the height of the tallest column of level poses through a 7 cm slot
  (:mod:`robostrich_suite.studies.gap_column`).

:class:`Budget` sizes the cheap score of a search trial; :data:`FULL` is the confirmation's.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from robostrich_suite.studies import coverage as coverage_lib
from robostrich_suite.studies import gap_column, layout_compare, pose_seek, workspace

KINEMATIC_SAMPLES = layout_compare.DEFAULT_KINEMATIC_SAMPLES  # the blue region robostrich-layouts uses


@dataclasses.dataclass(frozen=True)
class Budget:
    """Simulation per routing.  ``poses`` sought poses: a third on blue-region cells (coverage),
    the rest on the gap's columns, of which a third grows the tallest column found."""
    poses: int = 36
    seek_time: float = 4.0  # s per sought pose (robostrich-layouts: pose_seek.SEEK_TIME)
    hold_time: float = pose_seek.HOLD_TIME  # s a pose is held from the fixed start: one episode
    movement_iterations: int = 3  # bisection steps matching the lever's head travel (full: 7)
    max_ramps: int = gap_column.MAX_RAMPS

    def split(self) -> tuple[int, int, int]:
        """(coverage cells, coarse column targets, refining targets)."""
        cells = max(1, self.poses // 3)
        gap = max(self.poses - cells, 1)
        refine = gap // 3
        return cells, gap - refine, refine


FULL = Budget(poses=180, seek_time=pose_seek.SEEK_TIME, movement_iterations=7, max_ramps=200)

_regions = {}


def blue_region(spec) -> coverage_lib.BlueRegion:
    """The blue region of ``spec``'s links (computed once per process, as robostrich-layouts does)."""
    key = (spec.joint_names, spec.link_lengths, spec.dorsal_limits_deg, spec.ventral_limits_deg)
    if key not in _regions:
        _regions[key] = coverage_lib.BlueRegion.from_samples(workspace.kinematic_samples(KINEMATIC_SAMPLES, 0, spec))
    return _regions[key]


def chosen_cells(region: coverage_lib.BlueRegion, count: int) -> np.ndarray:
    """``count`` cells spread evenly over the region (all of them when it has fewer)."""
    if count >= region.num_cells:
        return np.arange(region.num_cells)
    return np.unique(np.linspace(0, region.num_cells - 1, count).round().astype(int))


def coverage(spec, layout, cells: int, budget: Budget, interrupted=lambda: False) -> dict:
    """Share of ``cells`` spread blue-region cells where the routing holds a sought pose level."""
    region = blue_region(spec)
    chosen = chosen_cells(region, cells)
    first = np.array([np.flatnonzero(region.cell_of == c)[0] for c in chosen])
    held = []
    for i in first:  # one at a time: Ctrl-C is acted on between poses
        if interrupted():
            raise KeyboardInterrupt
        samples = pose_seek.seek_samples(region.head_position[i:i + 1], region.joint_angles[i:i + 1], spec, layout,
                                         budget.seek_time, budget.hold_time)
        held.append(coverage_lib.held_level_positions(samples))
    covered = region.covered(np.concatenate(held) if held else np.zeros((0, 2)))[chosen]
    return {"coverage": float(covered.mean()), "covered_cells": int(covered.sum()), "cells": len(chosen)}


def movement(spec, layout, budget: Budget) -> dict:
    case = layout_compare.Case("trial", "trial", spec, layout, "search")
    return layout_compare.movement_ratio(case, budget.movement_iterations)


def evaluate(spec, layout, budget: Budget = Budget(), interrupted=lambda: False) -> dict:
    """Every objective of one routing, with what it cost (``interrupted()`` polled between poses:
    True raises KeyboardInterrupt)."""
    start, cpu = time.perf_counter(), time.process_time()
    cells, coarse, refine = budget.split()
    result = movement(spec, layout, budget)
    result.update(coverage(spec, layout, cells, budget, interrupted))
    column, held = gap_column.measure(spec, layout, coarse, refine, budget.seek_time, budget.hold_time,
                                      budget.max_ramps, interrupted)
    result["gap"] = column.summary(held)
    result["gap_column_m"] = result["gap"]["column_height_m"]
    result["gap_level_poses"] = int(held.level().sum())
    result["gap_threading_poses"] = int(gap_column.threading(held).sum())
    result["seconds"] = round(time.perf_counter() - start, 2)
    result["cpu_seconds"] = round(time.process_time() - cpu, 2)
    return result
