"""What ``robostrich-design`` writes: the front as a figure, ``design.json`` and layout files.

Every file is written whole or not at all (:mod:`robostrich_suite.atomic_files`).  ``design.json``
(``"benchmark": "design"``) is what ``tools/results_page.py add`` records.
"""
from __future__ import annotations

import json
import pathlib
import statistics

from robostrich_suite import atomic_files
from robostrich_suite.model import layouts as layouts_lib
from robostrich_suite.studies import design_objectives, design_space, design_study, gap_column


def trial_row(trial, layout_file: str | None = None) -> dict:
    result = trial.user_attrs.get("result", {})
    row = {"trial": trial.number, "coverage": result.get("coverage"), "covered_cells": result.get("covered_cells"),
           "cells": result.get("cells"), "gap_column_m": result.get("gap_column_m"),
           "rolling_lever_ratio": result.get("rolling_lever_ratio"), "gap": result.get("gap"),
           "gap_threading_poses": result.get("gap_threading_poses"), "seconds": result.get("seconds")}
    if "gap_passage_m" in result:  # --score-passage: the way in, the trial's second objective
        row.update(gap_passage_m=result["gap_passage_m"], passage=result.get("passage"))
    if "stiffness" in trial.params:
        row["joint_stiffness"] = round(trial.params["stiffness"], 4)
    if layout_file:
        row["layout_file"] = layout_file
    return row


def write_layouts(front, out: pathlib.Path) -> dict:
    """The front's first ``design_study.FRONT_LAYOUTS`` routings as ``OUT/layouts/trial_N.json``: {number: path}."""
    written = {}
    for trial in front[:design_study.FRONT_LAYOUTS]:
        layout = design_space.layout(trial.params)
        path = out / "layouts" / f"trial_{trial.number}.json"
        atomic_files.write_text(path, json.dumps(layouts_lib.to_dict(layout, f"design_trial_{trial.number}"), indent=1) + "\n")
        written[trial.number] = str(path)
    return written


def rate(trials) -> dict:
    """Trials per hour from the complete trials' own durations (one process): on the clock, and per
    hour of one core (the CPU time they took; the clock's rate falls when others share the core)."""
    seconds = [(t.datetime_complete - t.datetime_start).total_seconds() for t in trials
               if t.datetime_complete and t.datetime_start]
    cpu = [t.user_attrs["result"]["cpu_seconds"] for t in trials if "cpu_seconds" in t.user_attrs.get("result", {})]
    mean = statistics.fmean(seconds) if seconds else 0.0
    mean_cpu = statistics.fmean(cpu) if cpu else 0.0
    return {"seconds_per_trial": round(mean, 2) if mean else None,
            "trials_per_hour": round(3600 / mean, 1) if mean else None,
            "cpu_seconds_per_trial": round(mean_cpu, 2) if mean_cpu else None,
            "trials_per_core_hour": round(3600 / mean_cpu, 1) if mean_cpu else None}


def summary(study, command: str, storage_url: str, layout_files: dict, confirmed: list) -> dict:
    import optuna
    complete = design_study.complete_trials(study)
    front = design_study.pareto_front(study)
    states = [t.state for t in study.get_trials(deepcopy=False)]
    best = max((t.user_attrs.get("result", {}).get("gap_column_m") or 0.0 for t in complete), default=0.0)
    best_feasible = max((t.user_attrs["result"]["gap_column_m"] for t in complete if design_study.feasible(t)),
                        default=0.0)
    settings = design_study.Settings.of(study)
    passage = {}
    if settings.score_passage:
        passage["best_feasible_passage_m"] = max(
            (t.values[1] for t in complete if design_study.feasible(t)), default=design_objectives.PASSAGE_FLOOR - 1.0)
    return {
        "benchmark": "design", "command": command, "study": study.study_name,
        "storage": design_study.redacted(storage_url),
        "pose_budget": study.user_attrs.get("pose_budget"),
        "search_stiffness": study.user_attrs.get("search_stiffness"),
        "slot_x": None if settings.slot_x is None else list(settings.slot_x),
        "tendons": {"dorsal": settings.space.dorsal, "ventral": settings.space.ventral,
                    "max_hole_stride": settings.space.max_stride},
        "gap_objective": "passage" if settings.score_passage else "column",
        "sampler": "multi-objective TPE with constraints (Optuna)",
        "objectives": list(design_study.objectives(settings.score_passage)),
        "ratio_limit": design_study.RATIO_LIMIT,
        "trials": {"complete": len(complete), "feasible": sum(map(design_study.feasible, complete)),
                   "failed": states.count(optuna.trial.TrialState.FAIL),
                   "running": states.count(optuna.trial.TrialState.RUNNING), **rate(complete)},
        "best_gap_column_m": best, "best_feasible_gap_column_m": best_feasible, **passage,
        "need": gap_column.TASK_NEED,
        "front": [trial_row(t, layout_files.get(t.number)) for t in front],
        "confirmed": confirmed,
    }


def plot(study, front, path: pathlib.Path) -> pathlib.Path:
    """Coverage against the gap column, every complete trial (infeasible ones grey), the front joined."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    trials = design_study.complete_trials(study)
    fig, ax = plt.subplots(figsize=(7, 5))
    ok = [t for t in trials if design_study.feasible(t)]
    bad = [t for t in trials if not design_study.feasible(t)]
    if bad:
        ax.scatter([t.values[0] for t in bad], [100 * t.values[1] for t in bad], c="0.7", marker="x", s=18,
                   label=f"rolling/lever > {design_study.RATIO_LIMIT} ({len(bad)})")
    if ok:
        points = ax.scatter([t.values[0] for t in ok], [100 * t.values[1] for t in ok], s=22, cmap="viridis",
                            c=[t.user_attrs["result"]["rolling_lever_ratio"] for t in ok],
                            label=f"feasible ({len(ok)})")
        fig.colorbar(points, ax=ax, label="rolling / lever attitude ratio")
    if front:
        line = sorted(front, key=lambda t: t.values[0])
        ax.plot([t.values[0] for t in line], [100 * t.values[1] for t in line], "r-o", mfc="none", ms=9,
                label=f"Pareto front ({len(front)})")
        for t in front[:10]:
            ax.annotate(str(t.number), (t.values[0], 100 * t.values[1]), fontsize=7, xytext=(4, 4),
                        textcoords="offset points")
    if design_study.Settings.of(study).score_passage:
        ax.axhline(0.0, color="k", ls="--", lw=0.8, label="the shelf's top")
        ax.set_ylabel("way in: head's height through the slot (cm from the shelf's top)")
    else:
        ax.axhline(100 * gap_column.TASK_NEED["column_height_m"], color="k", ls="--", lw=0.8,
                   label="column the narrow gap needs above the shelf")
        ax.set_ylabel("gap column height (cm)")
    ax.set_xlabel("coverage of the blue region's sampled cells (held level)")
    ax.set_title(f"{study.study_name}: {len(trials)} routings, pose budget {study.user_attrs.get('pose_budget')}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    fig.tight_layout()
    atomic_files.save_figure(fig, path, dpi=90)
    plt.close(fig)
    return path


def write(study, out: pathlib.Path, command: str, storage_url: str, confirmed: list) -> dict:
    front = design_study.pareto_front(study)
    layout_files = write_layouts(front, out)
    result = summary(study, command, storage_url, layout_files, confirmed)
    atomic_files.write_text(out / "design.json", json.dumps(result, indent=1) + "\n")
    plot(study, front, out / "front.png")
    return result


def passage_text(passage) -> str:
    if not passage or not passage["ramps"]:
        return ""
    return f", into the column from under the shelf {passage['clear']} of {passage['ramps']} ramps clear"


def print_summary(result: dict, out: pathlib.Path) -> None:
    trials = result["trials"]
    rate_text = (f", {trials['trials_per_hour']} trials/hour ({trials['trials_per_core_hour']} per hour of one "
                 "core's CPU time)" if trials["trials_per_hour"] and trials["trials_per_core_hour"] else "")
    print(f"{trials['complete']} complete trials ({trials['feasible']} feasible, {trials['failed']} failed)"
          f"{rate_text}; front of {len(result['front'])}")
    for row in result["front"][:10]:
        way_in = (f", way in {100 * row['gap_passage_m']:+.1f} cm from the shelf's top" if "gap_passage_m" in row
                  else "")
        print(f"  trial {row['trial']}: coverage {row['coverage']:.0%}, gap column {100 * row['gap_column_m']:.1f} cm"
              f"{way_in}, rolling/lever {row['rolling_lever_ratio']:.2f}")
    need = result["need"]["column_height_m"]
    print(f"best gap column {100 * result['best_feasible_gap_column_m']:.1f} cm among routings whose rolling/lever "
          f"attitude ratio is <= {result['ratio_limit']:g} (the paper's 'well below 1'), "
          f"{100 * result['best_gap_column_m']:.1f} cm of any routing (the narrow gap needs "
          f"{100 * need:.0f} cm above its shelf)")
    for row in result["confirmed"]:
        print(f"  confirmed trial {row['trial']}: coverage {row['coverage']:.0%}, gap column "
              f"{100 * row['gap_column_m']:.1f} cm, rolling/lever {row['rolling_lever_ratio']:.2f}"
              + passage_text(row.get("passage")))
    for name in ("design.json", "front.png"):
        print(f"wrote {out / name}")
    if result["front"]:
        print(f"wrote {out / 'layouts'}/ (the front's routings as layout files)")
