"""The full measures of a search's best routings: what ``robostrich-layouts`` measures, and the
gap column at :data:`design_objectives.FULL`, so a cheap trial's score is checked before it is believed,
and whether the head can get up into that column from under the shelf (:mod:`gap_passage`)."""
from __future__ import annotations

import pathlib

from robostrich_suite.studies import coverage as coverage_lib
from robostrich_suite.studies import design_objectives, design_space, gap_column, gap_passage, layout_compare, workspace
from robostrich_suite import cli as cli_lib


def confirm(trials, out: pathlib.Path, show_progress: bool = True, slot_x=None):
    """Yields per trial, as each is measured: coverage of every blue cell (random and sought poses), distinct targets, the
    movement tests at full bisection, and the gap column with the full pose budget (slot within ``slot_x``)."""
    from tqdm import tqdm
    full = design_objectives.FULL
    for trial in tqdm(trials, desc="confirming", unit="routing", disable=not show_progress):
        spec, layout = design_space.spec(trial.params), design_space.layout(trial.params)
        case = layout_compare.Case(f"trial_{trial.number}", f"trial_{trial.number}", spec, layout, "robostrich-design")
        region = coverage_lib.BlueRegion.from_samples(
            workspace.kinematic_samples(layout_compare.DEFAULT_KINEMATIC_SAMPLES, 0, spec))
        options = layout_compare.Options(out=out / "confirm")
        measured = layout_compare.measure(case, region, options)["row"]
        if cli_lib.interrupted():
            raise KeyboardInterrupt
        yield {"trial": trial.number, **{k: measured[k] for k in (
            "coverage", "covered_cells", "blue_cells", "level_poses", "distinct_targets", "rolling_lever_ratio",
            "rolling_range_deg", "lever_range_deg", "head_travel_mm", "target_file")}, **gap_measures(trial, slot_x)}


def gap_measures(trial, slot_x=None) -> dict:
    """The gap column of ``trial``'s routing at the full budget (slot within ``slot_x``), and the
    passage into it."""
    full = design_objectives.FULL
    spec, layout = design_space.spec(trial.params), design_space.layout(trial.params)
    cells, coarse, refine = full.split()
    column, held = gap_column.measure(spec, layout, coarse + cells, refine, full.seek_time, full.hold_time,
                                      full.max_ramps, cli_lib.interrupted, slot_x)
    passage = gap_passage.measure(spec, layout, column, held, full.hold_time, interrupted=cli_lib.interrupted)
    return {"gap_column_m": column.height, "gap": column.summary(held), "passage": passage}
