"""The layout comparison's figure: per case, the blue region with the held level poses
(as the paper's Fig. 6) over the routing drawn on a stick figure of the neck."""
from __future__ import annotations

import pathlib

import numpy as np

from robostrich_suite import atomic_files
from robostrich_suite.model import arm as arm_lib
from robostrich_suite import scenes
from robostrich_suite.studies import coverage as coverage_lib
from robostrich_suite.studies import workspace
from robostrich_suite.tasks import conventions

SIDE_COLOURS = {"dorsal": ("#b2182b", "#ef8a62", "#67001f"), "ventral": ("#2166ac", "#67a9cf", "#053061")}


def _region_panel(ax, region: coverage_lib.BlueRegion, held: np.ndarray, covered: np.ndarray,
                  base_xz: np.ndarray) -> None:
    """Blue-region cells (held: filled, not held: outlined), blue samples, held level heads."""
    from matplotlib.patches import Rectangle
    size = coverage_lib.CELL_SIZE
    for cell, is_held in zip(region.cells, covered):
        ax.add_patch(Rectangle(cell * size, size, size, lw=0.6,
                               facecolor="#a6dba0" if is_held else "none",
                               edgecolor="#1b7837" if is_held else "0.55"))
    ax.scatter(*region.head_position.T, s=5, c="tab:blue", lw=0, zorder=3)
    if len(held):
        ax.scatter(*held.T, s=6, c="k", marker="x", lw=0.6, alpha=0.7, zorder=4)
    ax.plot(*base_xz, "ko", ms=5, zorder=5)


def _neck_axis(spec: arm_lib.ArmSpec):
    """Joint positions along the straight neck (m from the base joint), caudal first, and
    each link's hole position."""
    lengths = list(reversed(spec.link_lengths)) + [spec.head_length]  # c18 ... c2, head
    joints = np.concatenate([[0.0], np.cumsum(lengths)])
    names = list(reversed(spec.joint_names))
    holes = {name: joints[i] + spec.hole_fraction * lengths[i] for i, name in enumerate(names)}
    return joints, holes


def _routing_panel(ax, spec: arm_lib.ArmSpec, layout: arm_lib.TendonLayout) -> None:
    """The neck laid straight (base left, head right); each tendon a line on its side,
    one lane each, from its anchor or first hole through its holes to its insertion."""
    joints, holes = _neck_axis(spec)
    ax.plot(joints[:-1], np.zeros(len(joints) - 1), "-", color="0.35", lw=3, solid_capstyle="butt")
    ax.plot(joints[-2:], [0, 0], "-", color="#e08214", lw=5, solid_capstyle="butt")  # head
    ax.plot(joints[:-1], np.zeros(len(joints) - 1), "|", color="k", ms=7)
    lanes = {"dorsal": 0, "ventral": 0}
    anchor = -0.03
    for tendon in layout.tendons:
        lanes[tendon.side] += 1
        sign = 1 if tendon.side == "dorsal" else -1
        y = sign * lanes[tendon.side]
        colour = SIDE_COLOURS[tendon.side][(lanes[tendon.side] - 1) % 3]
        xs = [holes[link] for link in tendon.links]
        start = anchor if tendon.on_base else xs[0]
        ax.plot([start, xs[-1]], [y, y], "-", color=colour, lw=1.6)
        ax.plot(xs[:-1], [y] * (len(xs) - 1), "o", color=colour, ms=2.5)
        ax.plot(xs[-1], y, ">", color=colour, ms=5)
        if tendon.on_base:
            ax.plot(start, y, "s", color=colour, ms=4)
        ax.text(xs[-1] + 0.012, y, tendon.name, va="center", fontsize=7, color=colour)
    top = max(lanes.values()) + 0.8
    ax.set_ylim(-lanes["ventral"] - 0.8, lanes["dorsal"] + 0.8 if lanes["dorsal"] else top)
    ax.set_xlim(anchor - 0.02, joints[-1] + 0.2)
    ax.axhline(0, color="none")
    ax.set_yticks([])
    ax.set_xticks([0, joints[-2]], ["C18\n(base)", "atlas"], fontsize=7)
    ax.text(anchor - 0.015, lanes["dorsal"] + 0.3, "dorsal", fontsize=6, color=SIDE_COLOURS["dorsal"][0],
            va="bottom")
    ax.text(anchor - 0.015, -lanes["ventral"] - 0.3, "ventral", fontsize=6,
            color=SIDE_COLOURS["ventral"][0], va="top")
    for spine in ("left", "right", "top"):
        ax.spines[spine].set_visible(False)


MAX_COLUMNS = 4  # cases side by side; more wrap onto further rows (a figure readable at page width)


def plot(cases, region: coverage_lib.BlueRegion, results, path) -> pathlib.Path:
    """Per case, blue region with held level poses over its routing; at most MAX_COLUMNS cases
    side by side, more wrapping onto further rows."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    columns = min(len(cases), MAX_COLUMNS)
    rows = -(-len(cases) // columns)
    fig, axes = plt.subplots(2 * rows, columns, figsize=(max(3.4 * columns, 10.0), 5.0 * rows + 1.2),
                             squeeze=False, gridspec_kw=dict(height_ratios=[2.2, 1.3] * rows))
    for index in range(len(cases), rows * columns):  # an unfilled last row
        axes[2 * (index // columns), index % columns].set_visible(False)
        axes[2 * (index // columns) + 1, index % columns].set_visible(False)
    base_xz = workspace.base_joint_xz(scenes.frame_physics(cases[0].spec, cases[0].layout),
                                      cases[0].spec)
    everything = np.concatenate([region.head_position] + [r["held"] for r in results]
                                + [base_xz[None]])
    low, high = everything.min(axis=0) - 0.03, everything.max(axis=0) + 0.03
    for index, (case, result) in enumerate(zip(cases, results)):
        row, column = result["row"], index % columns
        ax = axes[2 * (index // columns), column]
        _region_panel(ax, region, result["held"], result["covered"], base_xz)
        ax.set_xlim(low[0], high[0])
        ax.set_ylim(low[1], high[1])
        ax.set_aspect("equal")
        ax.grid(alpha=0.25)
        ax.set_title(f"{case.label} ({len(case.layout)} tendons)\ncoverage {row['coverage']:.0%} "
                     f"({row['covered_cells']}/{row['blue_cells']} cells), "
                     f"{row['distinct_targets']} targets", fontsize=9.5)
        ax.set_xlabel("x (m, forward)", fontsize=9)
        ax.tick_params(labelsize=8)
        if column == 0:
            ax.set_ylabel("z (m, up)", fontsize=9)
        _routing_panel(axes[2 * (index // columns) + 1, column], case.spec, case.layout)
    level = f"{conventions.LEVEL_ATTITUDE_DEG:g}$\\pm${conventions.LEVEL_TOLERANCE_DEG:g}$^\\circ$"
    handles = [
        Line2D([], [], ls="", marker="o", ms=3, color="tab:blue", label=f"kinematic head, attitude {level} (blue region)"),
        Patch(facecolor="#a6dba0", edgecolor="#1b7837",
              label=f"{coverage_lib.CELL_SIZE * 100:g} cm cell held level within "
                    f"{coverage_lib.HOLD_DISTANCE * 100:g} cm"),
        Patch(facecolor="none", edgecolor="0.55", label="cell not held"),
        Line2D([], [], ls="", marker="x", ms=5, color="k", label="level head held by the actuated arm"),
        Line2D([], [], ls="", marker="o", ms=5, color="k", label="C18-frame joint"),
        Line2D([], [], color=SIDE_COLOURS["dorsal"][0], label="dorsal tendon"),
        Line2D([], [], color=SIDE_COLOURS["ventral"][0], label="ventral tendon"),
        Line2D([], [], ls="", marker="s", ms=4, color="0.3", label="anchor on the base"),
        Line2D([], [], ls="", marker=">", ms=5, color="0.3", label="insertion (dots: holes passed)"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=3, fontsize=8.5, frameon=False)
    fig.suptitle("Tendon layouts on the Table 1 links: blue region of Fig. 6 held level "
                 "(above), routing on the straightened neck (below)", fontsize=11)
    fig.tight_layout(rect=(0, 0.1 / rows, 1, 1 - 0.03 / rows))
    atomic_files.save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path
