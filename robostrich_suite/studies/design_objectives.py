"""What ``robostrich-design`` scores a routing by: the paper's tests and the narrow gap.

* **rolling / lever**: the movement tests' attitude ranges at equal head travel
  (``layout_compare.movement_ratio``, as ``robostrich-layouts``); the paper: well below 1;
* **coverage**: the share of Fig. 6's blue-region cells held level (``coverage.BlueRegion``, as
  ``robostrich-layouts``), estimated on a fixed, spread subset of the cells with one sought pose
  each: every routing gets the same cells, so trials compare;
* **gap column**: the height of the tallest column of level poses through a 7 cm slot
  (:mod:`robostrich_suite.studies.gap_column`);
* **way in** (``--score-passage``): how far up through the slot the head gets from under the
  shelf (:mod:`robostrich_suite.studies.gap_passage` at :data:`PASSAGE_SAMPLES` draws and
  ``PASSAGE_STARTS`` x 2 ramps), :func:`passage_score`.

:class:`Budget` sizes the cheap score of a search trial; :data:`FULL` is the confirmation's.
"""
from __future__ import annotations

import dataclasses
import time

import numpy as np

from robostrich_suite import scenes
from robostrich_suite.studies import coverage as coverage_lib
from robostrich_suite.studies import gap_column, gap_passage, layout_compare, pose_seek, workspace

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


PASSAGE_SAMPLES = 100  # inputs drawn for the poses under the shelf, per trial (confirmation: gap_passage's 600)
PASSAGE_STARTS = 3  # of them ramped into the target, each quick and slow: 6 ramps
# The score of a way in that never brings the head over the slot: the ground, relative to the shelf's
# top (no head over the slot is lower), less how far in x from the slot's edge it stayed (at most 1 m).
PASSAGE_FLOOR = -round(gap_column.SHELF_Z + scenes.GAP_SHELF_THICKNESS + scenes.NOMINAL_MOUNT_HEIGHT, 4)

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


def passage_target(column: gap_column.Column, held: gap_column.HeldPoses, slot_x=None) -> gap_column.Column:
    """What the way in ramps into: the column's lowest pose; without a column, the highest held pose
    whose head is over the slot range (within ``gap_column.COLUMN_TOLERANCE``), level ones first, the
    slot under it; :data:`gap_column.NO_COLUMN` when there is none."""
    if column.scene is not None and column.poses:
        return column
    low, high = (-np.inf, np.inf) if slot_x is None else slot_x
    x = held.head[:, 0]
    over = np.flatnonzero(held.settled & (x >= low - gap_column.COLUMN_TOLERANCE)
                          & (x <= high + gap_column.COLUMN_TOLERANCE))
    if not len(over):
        return gap_column.NO_COLUMN
    top = int(max(over, key=lambda i: (bool(held.level()[i]), held.head[i, 1])))
    return gap_column.Column(gap_column.Scene(float(np.clip(x[top], low, high)), gap_column.SHELF_Z), (top,), 0.0)


def passage_score(passage: dict, column_height: float) -> float:
    """How far up through the slot the head got from under the shelf (m from the shelf's top), with
    the column's height added when a ramp reached it; never over the slot: :data:`PASSAGE_FLOOR` less
    the nearest it came to the slot in x.  Graded everywhere, so the sampler learns even when no way
    in passes."""
    if passage["highest_in_slot_m"] is not None:
        return round(passage["highest_in_slot_m"] + (column_height if passage["clear"] else 0.0), 4)
    nearest = passage.get("nearest_to_slot_m")
    return round(PASSAGE_FLOOR - min(1.0 if nearest is None else nearest, 1.0), 4)


def way_in(spec, layout, column, held, budget: Budget, slot_x=None, interrupted=lambda: False) -> dict:
    """The cheap way in (:func:`passage_target`, :func:`passage_score`) as the trial's result keys."""
    target = passage_target(column, held, slot_x)
    passage = gap_passage.measure(spec, layout, target, held, budget.hold_time, PASSAGE_SAMPLES, PASSAGE_STARTS,
                                  interrupted)
    passage["target"] = ("column" if target is column and column.poses else None if not target.poses else
                         "highest level pose over the slot" if held.level()[target.poses[0]] else
                         "highest pose over the slot (none level)")
    return {"passage": passage, "gap_passage_m": passage_score(passage, target.height)}


def evaluate(spec, layout, budget: Budget = Budget(), interrupted=lambda: False, slot_x=None,
             score_passage: bool = False) -> dict:
    """Every objective of one routing, with what it cost (``interrupted()`` polled between poses:
    True raises KeyboardInterrupt); the gap's slot within ``slot_x`` (None: anywhere); with
    ``score_passage`` the way in too (:func:`way_in`)."""
    start, cpu = time.perf_counter(), time.process_time()
    cells, coarse, refine = budget.split()
    result = movement(spec, layout, budget)
    result.update(coverage(spec, layout, cells, budget, interrupted))
    column, held = gap_column.measure(spec, layout, coarse, refine, budget.seek_time, budget.hold_time,
                                      budget.max_ramps, interrupted, slot_x)
    result["gap"] = column.summary(held)
    result["gap_column_m"] = result["gap"]["column_height_m"]
    result["gap_level_poses"] = int(held.level().sum())
    result["gap_threading_poses"] = int(gap_column.threading(held, slot_x=slot_x).sum())
    if score_passage:
        passage_start = time.perf_counter()
        result.update(way_in(spec, layout, column, held, budget, slot_x, interrupted))
        result["passage"]["seconds"] = round(time.perf_counter() - passage_start, 2)
    result["seconds"] = round(time.perf_counter() - start, 2)
    result["cpu_seconds"] = round(time.process_time() - cpu, 2)
    return result
