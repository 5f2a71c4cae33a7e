"""Figs. 4-5 of a movement test (:mod:`robostrich_suite.studies.movement`): tendon inputs,
head attitude and stick figures of the arm.  Plotting only; the movement computes nothing here.
It reads a finished ``movement.Movement`` and imports nothing of the study (the study imports it)."""
from __future__ import annotations

import pathlib

import numpy as np

from robostrich_suite import atomic_files


def movement_figure(movement, num_sticks: int = 12):
    """Figs. 4-5 as a matplotlib Figure: (A) tendon inputs, (B) head attitude, (C) the arm."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(13, 5.6))
    grid = fig.add_gridspec(2, 2, width_ratios=[1.25, 1])
    ax_in, ax_att, ax_arm = fig.add_subplot(grid[0, 0]), fig.add_subplot(grid[1, 0]), \
        fig.add_subplot(grid[:, 1])
    _plot_inputs(ax_in, movement)
    _plot_attitude(ax_att, movement)
    for ax in (ax_in, ax_att):
        ax.grid(alpha=0.3)
        ax.set_xlim(movement.time[0], movement.time[-1])
    _plot_arm(fig, ax_arm, movement, num_sticks)
    fig.tight_layout()
    return fig


def _plot_inputs(ax, movement) -> None:
    import matplotlib.pyplot as plt
    colors = plt.cm.viridis(np.linspace(0, 0.95, len(movement.tendon_names)))
    for i, name in enumerate(movement.tendon_names):
        style = (dict(color="tab:red", lw=2.0) if movement.tendon_sides[i] == "dorsal"
                 else dict(color=colors[i]))
        ax.plot(movement.time, 1000 * movement.control[:, i], label=name, **style)
    dorsal = movement.tendon_sides.index("dorsal")
    if movement.config.dorsal_hold == "length":
        ax.plot(movement.time, 1000 * movement.contraction[:, dorsal], "--", color="tab:red",
                lw=1, label="dorsal, measured contraction")
    ax.set_ylabel("tendon input (mm)")
    low, high = ax.get_ylim()
    ax.set_ylim(low, high + 0.9 * (high - low))  # headroom for the legend
    ax.legend(fontsize=7, ncol=4, loc="upper left")
    span = movement.config.ventral_span
    tendons = "ventral tendons from the base" if span is None else f"ventral slips of {span} joints"
    ax.set_title(f"(A) tendon inputs, {movement.config.pattern} pattern ({tendons}, dorsal "
                 f"{movement.config.dorsal_hold} held)\nventral inputs up to "
                 f"{movement.amplitude_text()}", fontsize=10)


def _plot_attitude(ax, movement) -> None:
    ax.plot(movement.time, movement.head_attitude, color="k")
    ax.axvspan(0, movement.settle_time, color="0.9", label="settling to the start pose")
    summary = movement.summary()
    ax.set_title(f"(B) head attitude: range {summary['attitude_range_deg']:.1f} deg, "
                 f"head travel {1000 * summary['head_travel_m']:.0f} mm", fontsize=10)
    ax.set_ylabel("attitude (deg, 90 = level)")
    ax.set_xlabel("time (s)")
    ax.legend(fontsize=7, loc="lower right")


def _plot_arm(fig, ax, movement, num_sticks: int) -> None:
    """Stick figures coloured by time (with a colourbar), the head path and the base joint."""
    import matplotlib.colors as mcolors
    import matplotlib.pyplot as plt
    import matplotlib.transforms as mtransforms
    from mpl_toolkits.axes_grid1 import make_axes_locatable
    frames = np.flatnonzero(movement.moving)
    picks = frames[np.linspace(0, len(frames) - 1, num_sticks).astype(int)]
    # plasma without its palest yellow, which vanishes on white
    cmap = mcolors.ListedColormap(plt.cm.plasma(np.linspace(0, 0.85, 256)))
    norm = mcolors.Normalize(movement.time[picks[0]], movement.time[picks[-1]])
    for frame in picks:
        shade = cmap(norm(movement.time[frame]))
        pts = movement.joint_points[frame]
        ax.plot(pts[:-1, 0], pts[:-1, 1], "-o", color=shade, ms=2, lw=1.2)
        ax.plot(pts[-2:, 0], pts[-2:, 1], "-", color=shade, lw=3.5)  # the head
    ax.plot(*movement.head_position[movement.moving].T, ":", color="k", lw=1, label="head path")
    ax.plot(*movement.joint_points[0, 0], "s", color="k", mec="w", ms=9, zorder=5,
            label="C18-frame joint (base)")
    ax.plot([], [], "-", color="0.4", lw=3.5, label="head")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m, forward)")
    ax.set_ylabel("z (m, up)")
    ax.grid(alpha=0.3)
    # Below the x label (a fixed 36 pt under the axes, whatever their height): inside the
    # axes the legend hid the base joint.
    below = mtransforms.offset_copy(ax.transAxes, fig=fig, y=-36, units="points")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=below,
              ncol=3, frameon=False)
    # A colourbar as tall as the (equal-aspect) axes.
    colorbar_axes = make_axes_locatable(ax).append_axes("right", size="4%", pad=0.1)
    colorbar_axes.set_label("<colorbar>")  # the label matplotlib gives the colourbars it places
    colorbar = fig.colorbar(plt.cm.ScalarMappable(norm=norm, cmap=cmap), cax=colorbar_axes)
    colorbar.set_label("time (s)")
    ax.set_title(f"(C) the arm every {np.diff(movement.time[picks]).mean():.1f} s "
                 "while the ventral tendons move", fontsize=10)


def plot_movement(movement, path: str | pathlib.Path, num_sticks: int = 12
                  ) -> pathlib.Path:
    """Write :func:`movement_figure` to ``path`` (PNG)."""
    import matplotlib.pyplot as plt
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig = movement_figure(movement, num_sticks)
    atomic_files.save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path


def comparison_figure(movements: dict):
    """Rolling beside lever on one scale: (A) head attitude over time from the ramps' start, (B)
    the head's paths; the title gives their attitude ranges, their ratio and the goal it is read
    against (the paper's: rolling keeps the attitude steadier, a ratio below 1)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_att, ax_path) = plt.subplots(1, 2, figsize=(12, 4.8))
    colors = {"rolling": "tab:blue", "lever": "tab:orange"}
    for pattern, movement in movements.items():
        moving = movement.moving
        summary = movement.summary()
        label = (f"{pattern}: range {summary['attitude_range_deg']:.1f} deg, "
                 f"head travel {1000 * summary['head_travel_m']:.0f} mm")
        ax_att.plot(movement.time[moving] - movement.settle_time, movement.head_attitude[moving],
                    color=colors.get(pattern), label=label)
        path = 1000 * movement.head_position[moving]
        ax_path.plot(path[:, 0], path[:, 1], color=colors.get(pattern), label=pattern)
        ax_path.plot(*path[0], "o", color=colors.get(pattern), mfc="w")
    ax_att.axhline(90, color="green", lw=0.8, ls=":", label="level head (90 deg)")
    ax_att.set_xlabel("time since the ramps started (s)")
    ax_att.set_ylabel("head attitude (deg, 90 = level)")
    ax_att.set_title("(A) head attitude, both patterns on one scale", fontsize=10)
    ax_path.set_xlabel("x (mm, forward)")
    ax_path.set_ylabel("z (mm, up)")
    ax_path.set_aspect("equal", "datalim")
    ax_path.set_title("(B) head path (circle: start)", fontsize=10)
    for ax in (ax_att, ax_path):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    if {"rolling", "lever"} <= set(movements):
        ratio = movements["rolling"].attitude_range() / max(movements["lever"].attitude_range(), 1e-9)
        fig.suptitle(f"Attitude range rolling / lever at equal head travel: {ratio:.2f} (goal, the paper's "
                     "Sec. 4.3: below 1, rolling keeps the head steadier)", fontsize=11)
    fig.tight_layout()
    return fig


def plot_comparison(movements: dict, path: str | pathlib.Path) -> pathlib.Path:
    """Write :func:`comparison_figure` to ``path`` (PNG)."""
    import matplotlib.pyplot as plt
    path = pathlib.Path(path)
    fig = comparison_figure(movements)
    atomic_files.save_figure(fig, path, dpi=120)
    plt.close(fig)
    return path
