"""Rerun blueprints: the layout a recording opens in, in the native viewer and the web viewer alike.

Without one Rerun guesses a view per entity (a grid of small plots, the 3D view facing the floor).
Every ``.rrd`` the commands write carries its blueprint (``rerun_log.RecordingFile(blueprint=...)``),
so ``rerun FILE.rrd`` and ``robostrich-play --web`` open on the same page: the robot in 3D on the
left, the time series that matter on the right, the side panels folded away.
"""
from __future__ import annotations

from typing import Sequence

import rerun.blueprint as rrb

# The frame arm seen from the side, as the scene's `side` camera sees it (robostrich_suite/scenes.py):
# it moves in the x-z plane, so the eye looks along +y at the middle of its workspace.
SIDE_EYE = rrb.EyeControls3D(position=[0.2, -1.4, 0.5], look_target=[0.2, 0.0, 0.35], eye_up=[0.0, 0.0, 1.0])

# What a rollout's plots hold (agents/robostrich/recording.py): (view title, entities).
ROLLOUT_SERIES = (
    ("Position error (m)", ["plots/position_error_m"]),
    ("Head attitude and its error (deg)", ["plots/head_attitude_deg", "plots/attitude_error_deg"]),
    ("Tendon inputs (hover a line for its tendon)", ["plots/tendon_input"]),
)
ARM_VIEW = "Arm, target and head path"


def robot_and_series(series: Sequence[tuple[str, Sequence[str]]], eye: rrb.EyeControls3D | None = None,
                     timeline: str = "sim_time", robot: str = ARM_VIEW) -> rrb.Blueprint:
    """The robot (everything under ``world``) in 3D beside one time-series view per ``series`` entry;
    ``eye`` None lets Rerun place the camera (the quadruped walks out of any fixed view). A view of
    one entity has no legend: its title names it, and a legend of a batch's lines (the nine tendon
    inputs) covers the small plot; hovering a line names it."""
    plots = [rrb.TimeSeriesView(name=title, origin="/", contents=[f"+ {path}" for path in paths],
                                plot_legend=rrb.PlotLegend(visible=len(paths) > 1))
             for title, paths in series]
    spatial = rrb.Spatial3DView(name=robot, origin="world", eye_controls=eye)
    return rrb.Blueprint(rrb.Horizontal(spatial, rrb.Vertical(*plots), column_shares=[3, 2]),
                         rrb.BlueprintPanel(state="collapsed"), rrb.SelectionPanel(state="collapsed"),
                         rrb.TimePanel(state="collapsed", timeline=timeline))


def rollout(side_view: bool = True) -> rrb.Blueprint:
    """An evaluation rollout (play, evaluate, train's final evaluation, stabilize, gap): the arm,
    the target and the head's path, with position error, attitude and tendon inputs over time.
    ``side_view``: the frame arm's fixed side camera (False on the quadruped)."""
    return robot_and_series(ROLLOUT_SERIES, SIDE_EYE if side_view else None)


def curves(groups: Sequence[tuple[str, str]], timeline: str = "env_steps") -> rrb.Blueprint:
    """Training curves: a grid of time-series views, one per (title, entity folder), every run in each."""
    views = [rrb.TimeSeriesView(name=title, origin=folder) for title, folder in groups]
    return rrb.Blueprint(rrb.Grid(*views), rrb.BlueprintPanel(state="collapsed"),
                         rrb.SelectionPanel(state="collapsed"), rrb.TimePanel(state="collapsed", timeline=timeline))
