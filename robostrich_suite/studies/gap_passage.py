"""The way into a gap column from under the shelf: can the head rise through the slot at all?

The gap column (:mod:`gap_column`) holds level heads above the shelf with necks threading its
slot, and the ramps between them.  The task asks more: the head starts under the shelf (Fig. 10's
sub-targets 1-4) and must get up into that column.  A level head cannot pass the slot, so the way
up may be any pose; but every link that ends above the shelf has to come up through the slot, one
after the other, which a neck bending as a whole may not manage.  This module measures it:

* **under the shelf**: poses held at rest (from inputs drawn uniformly in the servos' range) with
  every capsule below the shelf's underside and clear of the scene (the ground too);
* **a passage**: from each of the :data:`RAMPS` such poses whose heads are nearest the slot in x,
  the inputs are ramped (:func:`gap_column.ramp_path`, over each of :data:`RAMP_TIMES`) to those of
  the column's lowest pose; it passes when no capsule touches the scene on the way and the head
  ends at that pose;
* **how far up through the slot** a ramp got: the highest its head came, over the slot and
  before anything touched, relative to the shelf's top (negative: still under the shelf; none: the
  head was never over the slot), and how near in x to the slot's edge it came when never over it.

Straight ramps between held inputs are one family of ways up, not all: a passage found is a way,
none found is evidence, not proof.
"""
from __future__ import annotations

import numpy as np

from robostrich_suite import scenes
from robostrich_suite.studies import gap_column, workspace

UNDER_SAMPLES = 600  # inputs drawn, held for the poses under the shelf
RAMPS = 20  # poses under the shelf ramped into the column
RAMP_TIMES = (1.0, 3.0)  # s: a quick ramp and a slow one
SEED = 0


def under_shelf(held: gap_column.HeldPoses, scene: gap_column.Scene) -> np.ndarray:
    """(n,) bool: poses at rest with every capsule below the shelf's underside, touching nothing."""
    below = (held.points[..., 1] + held.radii < scene.shelf_z).all(axis=-1)
    return held.settled & below & ~scene.touches(held.points, held.radii)


def measure(spec, layout, column: gap_column.Column, held: gap_column.HeldPoses, hold_time: float,
            samples: int = UNDER_SAMPLES, ramps: int = RAMPS, interrupted=lambda: False) -> dict:
    """The passage into ``column`` (of ``held``, :func:`gap_column.measure` of the routing): module doc."""
    if column.scene is None or not column.poses:
        return {"under_poses": 0, "samples": 0, "ramps": 0, "clear": 0, "highest_in_slot_m": None,
                "nearest_to_slot_m": None}
    physics = scenes.frame_physics(spec, layout)
    base = workspace.base_joint_xz(physics, spec)

    def to_plane(point):
        return np.asarray(point)[[0, 2]] - base

    scene, top = column.scene, held.control[column.poses[0]]
    low, high = physics.model.actuator_ctrlrange.T
    inputs = np.random.default_rng(SEED).uniform(low, high, size=(samples, len(low)))
    under = gap_column.hold_poses(physics, inputs, to_plane, hold_time, interrupted)
    starts = np.flatnonzero(under_shelf(under, scene))
    starts = starts[np.argsort(np.abs(under.head[starts, 0] - scene.slot_x))][:ramps]
    shelf_top = scene.shelf_z + scenes.GAP_SHELF_THICKNESS
    half = scenes.GAP_SLOT_WIDTH / 2
    clear, highest, nearest = 0, -np.inf, np.inf
    for i in starts:
        for ramp_time in RAMP_TIMES:
            if interrupted():
                raise KeyboardInterrupt
            ok, heads = gap_column.ramp_path(physics, under.control[i], top, scene, to_plane, hold_time, ramp_time)
            arrived = ok and np.linalg.norm(heads[-1] - held.head[column.poses[0]]) <= gap_column.ARRIVAL
            clear += int(arrived)
            over_slot = heads[np.abs(heads[:, 0] - scene.slot_x) <= half]
            if len(heads):
                nearest = min(nearest, float(np.abs(heads[:, 0] - scene.slot_x).min()) - half)
            if len(over_slot):
                highest = max(highest, float(over_slot[:, 1].max()) - shelf_top)
    return {"under_poses": int(under_shelf(under, scene).sum()), "samples": samples,
            "ramps": len(starts) * len(RAMP_TIMES), "clear": clear,
            "highest_in_slot_m": None if not np.isfinite(highest) else round(highest, 4),
            "nearest_to_slot_m": None if not np.isfinite(nearest) else round(max(nearest, 0.0), 4)}
