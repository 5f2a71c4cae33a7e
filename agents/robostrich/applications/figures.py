"""PNG figures of the application evaluations, as the paper's Fig. 9 and Fig. 12 (matplotlib, Agg).

Both take the reports of agents/robostrich/applications/stabilization.py / agents/robostrich/applications/narrow_gap.py (label -> report with a
seed-0 `series`) and draw one line per policy; they return the Figure and write it when
given a path.
"""
from typing import Optional

import matplotlib
import matplotlib.patches as mpatches
import matplotlib.pyplot as plt
import numpy as np

from robostrich_suite import atomic_files
from agents.robostrich.applications.narrow_gap import position_error

COLORS = {"trained": "tab:blue", "reference": "tab:green", "zero": "tab:gray", "lookup": "tab:orange"}


def _color(label: str, i: int) -> str:
    return COLORS.get(label, f"C{i}")


def _save(fig, path: Optional[str]):
    if path is not None:
        atomic_files.save_figure(fig, path, dpi=110)
        plt.close(fig)
    return fig


def _height_changes(series) -> list:
    """(start, end) time spans where the trunk height command changes (Fig. 9A's two ramps)."""
    command, time = np.asarray(series["trunk_height_command"]), np.asarray(series["time"])
    moving = np.abs(np.gradient(command, time)) > 1e-6 if len(time) > 2 else np.zeros(len(time), bool)
    spans, start = [], None
    for t, m in zip(time, moving):
        if m and start is None:
            start = t
        elif not m and start is not None:
            spans.append((start, t))
            start = None
    if start is not None:
        spans.append((start, time[-1]))
    return spans


# Panel of Fig. 9 -> the goal it is read against (stabilization.GOALS' metric) and how to say it
_STABILIZATION_GOALS = {0: ("height_rms_error", "height {:.1f} cm RMS off", 100, "cm"),
                        1: ("head_vz_rms_ratio", "velocity RMS {:.2f} of the trunk's", 1, ""),
                        2: ("distance_mean_error", "P_d {:.1f} cm off", 100, "cm"),
                        3: ("attitude_within_fraction", "level {:.0f} % of the time", 100, "%")}


def _against_goal(report: dict, panel: int) -> str:
    """'height 0.8 cm RMS off (goal <= 1.0 cm, met)': a policy's worst seed against a Fig. 9 goal."""
    name, text, scale, unit = _STABILIZATION_GOALS[panel]
    check = report.get("goals", {}).get(name)
    if check is None:
        return ""
    bound = "<=" if check["kind"] == "max" else ">="
    goal = f"{check['goal'] * scale:g}{' ' + unit if unit else ''}"
    return f": {text.format(check['worst'] * scale)} (goal {bound} {goal}, {'met' if check['met'] else 'not met'})"


def stabilization_figure(reports: dict, path: Optional[str] = None, settle: float = 0.0):
    """Fig. 9: (A) head and trunk z, (B) their z velocities, (C) head-trunk distance with P_d,
    (D) head attitude with the desired band; trunk-height ramps shaded grey, the unscored
    first `settle` seconds hatched (B's scale ignores them: the arm's first fall is fast).
    Each policy's legend entry gives its worst seed's metric of that panel against its goal."""
    matplotlib.use("Agg")  # files, never a window (at plot time: importing must not switch a notebook's backend)
    fig, axes = plt.subplots(4, 1, figsize=(9, 10), sharex=True)
    first = next(iter(reports.values()))["series"]
    for ax in axes:
        for start, end in _height_changes(first):
            ax.axvspan(start, end, color="0.9", zorder=0)
        if settle > 0:
            ax.axvspan(0, settle, facecolor="none", hatch="//", edgecolor="0.8", lw=0, zorder=0)
    for i, (label, report) in enumerate(reports.items()):
        s, color = report["series"], _color(label, i)
        axes[0].plot(s["time"], s["head_z"], color=color, lw=1.2, label=f"head ({label}){_against_goal(report, 0)}")
        axes[0].plot(s["time"], s["trunk_z"], color=color, lw=0.8, ls="--", label=f"trunk ({label})")
        axes[1].plot(s["time"], s["head_vz"], color=color, lw=1.0, label=f"head ({label}){_against_goal(report, 1)}")
        axes[2].plot(s["time"], s["distance"], color=color, lw=1.0, label=f"{label}{_against_goal(report, 2)}")
        axes[3].plot(s["time"], s["attitude"], color=color, lw=1.0, label=f"{label}{_against_goal(report, 3)}")
    axes[1].plot(first["time"], first["trunk_vz"], color="k", lw=0.6, alpha=0.6, label="trunk")
    scored = [np.abs(r["series"][key][np.asarray(r["series"]["time"]) >= settle])
              for r in reports.values() for key in ("head_vz", "trunk_vz")]
    top = max((float(v.max()) for v in scored if v.size), default=0.0)
    if top > 0:
        axes[1].set_ylim(-1.3 * top, 1.3 * top)
    axes[0].plot(first["time"], first["desired_height"], "k:", lw=1.2, label="desired head height")
    axes[2].plot(first["time"], first["desired_distance"], "k:", lw=1.2, label="desired $P_d$")
    level, tolerance = float(first["desired_attitude"][0]), float(first["attitude_tolerance"][0])
    axes[3].axhspan(level - tolerance, level + tolerance, color="tab:green", alpha=0.15,
                    label=f"{level:.0f} $\\pm$ {tolerance:.0f} deg")
    axes[3].axhline(level, color="k", ls=":", lw=1.0)
    titles = ("(A) height above ground (m)", "(B) vertical velocity (m/s)",
              "(C) head ahead of trunk centre (m)", "(D) head attitude (deg)")
    for ax, title in zip(axes, titles):
        ax.set_ylabel(title, fontsize=8)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=6, ncol=2, loc="best")
    axes[-1].set_xlabel("time (s); grey: trunk height changing; hatched: not scored")
    fig.suptitle("Head stabilisation while walking (Fig. 9)")
    fig.tight_layout()
    return _save(fig, path)


def gap_figure(reports: dict, scene: dict, targets, position_tolerance: float,
               path: Optional[str] = None):
    """Fig. 12: (A) head path in the x-z plane with wall, shelf, slot and sub-targets;
    (B) position error and (C) head attitude over time, sub-target switches marked."""
    matplotlib.use("Agg")  # files, never a window (at plot time: importing must not switch a notebook's backend)
    fig = plt.figure(figsize=(11, 8))
    grid = fig.add_gridspec(2, 2, width_ratios=[1, 1.3])
    path_ax = fig.add_subplot(grid[:, 0])
    error_ax = fig.add_subplot(grid[0, 1])
    attitude_ax = fig.add_subplot(grid[1, 1], sharex=error_ax)
    for name in ("wall", "shelf_near", "shelf_far"):
        x0, z0, x1, z1 = scene[name]
        path_ax.add_patch(mpatches.Rectangle((x0, z0), x1 - x0, z1 - z0, color="tan", ec="saddlebrown"))
    x0, z0, x1, z1 = scene["slot"]
    path_ax.annotate("slot", ((x0 + x1) / 2, z0), textcoords="offset points", xytext=(35, -30), fontsize=8,
                     arrowprops=dict(arrowstyle="->", lw=0.6))
    for k, (x, z) in enumerate(np.asarray(targets)):
        path_ax.add_patch(mpatches.Circle((x, z), position_tolerance, fill=False, color="tab:red", lw=0.5,
                                          alpha=0.5))
        path_ax.plot(x, z, ".", color="tab:red")
        path_ax.annotate(str(k + 1), (x, z), textcoords="offset points", xytext=(-9, -3), color="tab:red",
                         fontsize=8)
    for i, (label, report) in enumerate(reports.items()):
        s, color = report["series"], _color(label, i)
        path_ax.plot(s["head_x"], s["head_z"], color=color, lw=1.0, label=label)
        error_ax.plot(s["time"], position_error(s), color=color, lw=1.0, label=label)
        attitude_ax.plot(s["time"], s["attitude"], color=color, lw=1.0, label=label)
        switches = np.flatnonzero(np.diff(s["target_index"]) != 0) + 1
        for j in switches:
            for ax in (error_ax, attitude_ax):
                ax.axvline(s["time"][j], color=color, ls=":", lw=0.8)
            error_ax.annotate(str(int(s["target_index"][j]) + 1), (s["time"][j], 1.0), color=color, fontsize=7,
                              xycoords=("data", "axes fraction"), xytext=(2, -10), textcoords="offset points")
    error_ax.axhline(position_tolerance, color="k", ls="--", lw=0.8, label=f"{position_tolerance * 100:.0f} cm")
    attitude_ax.axhspan(85, 95, color="tab:green", alpha=0.15, label="90 $\\pm$ 5 deg")
    path_ax.set_aspect("equal")
    path_ax.set_xlim(min(scene["wall"][0] - 0.35, path_ax.get_xlim()[0]), scene["shelf_far"][2] + 0.05)
    path_ax.set_ylim(0.2, max(0.9, path_ax.get_ylim()[1]))
    path_ax.set_xlabel("x (m, world)")
    path_ax.set_ylabel("z (m, height above ground)")
    path_ax.set_title(f"(A) head path, sub-targets 1-6 (circles: {position_tolerance * 100:.0f} cm)", fontsize=9)
    error_ax.set_ylabel("(B) position error (m)", fontsize=8)
    attitude_ax.set_ylabel("(C) head attitude (deg)", fontsize=8)
    attitude_ax.set_xlabel("time (s); dotted: sub-target switches (number = new sub-target)")
    for ax in (path_ax, error_ax, attitude_ax):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="best")
    fig.suptitle("Reaching through a narrow gap (Fig. 12)")
    fig.tight_layout()
    return _save(fig, path)
