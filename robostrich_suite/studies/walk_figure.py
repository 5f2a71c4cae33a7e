"""The walk study's figure (:mod:`robostrich_suite.studies.walk`): what the arm gets from the
walking quadruped.  Plotting only."""
from __future__ import annotations

import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from robostrich_suite import atomic_files


def walk_figure(series: dict, title: str = ""):
    """Heights, speeds, head distance ahead of the trunk and angles over time, one panel each;
    the trunk height has its own panel so its dip is not flattened by the head's scale."""
    t = series["time"]
    fig, axes = plt.subplots(5, 1, figsize=(11, 12), sharex=True)
    axes[0].plot(t, series["head_height"], label="head height")
    axes[0].plot(t, series["target_height"], "--", color="k", lw=1, label="target head height")
    axes[0].set_ylabel("height above\nground (m)")
    axes[0].set_title("(A) head height", fontsize=10)
    axes[1].plot(t, series["trunk_height"], color="C1", label="trunk height")
    axes[1].plot(t, series["height_command"], "--", color="C2", label="trunk height command")
    axes[1].set_ylabel("height above\nground (m)")
    axes[1].set_title("(B) trunk height and its command (own scale, so a commanded dip shows)",
                      fontsize=10)
    axes[2].plot(t, series["trunk_speed"], label="trunk forward speed")
    axes[2].plot(t, series["head_speed"], label="head speed (3-D)", alpha=0.8)
    axes[2].plot(t, series["head_vertical_speed"], label="head vertical speed", alpha=0.8)
    axes[2].set_ylabel("speed (m/s)")
    axes[2].set_title("(C) speeds", fontsize=10)
    axes[3].plot(t, series["head_forward_distance"], label="head ahead of trunk centre")
    axes[3].plot(t, series["target_forward"], "--", color="k", lw=1, label="target $P_d$")
    axes[3].set_ylabel("distance (m)")
    axes[3].set_title("(D) head distance ahead of the trunk centre and its target $P_d$",
                      fontsize=10)
    axes[4].plot(t, series["head_attitude"], label="head attitude (90 = level)")
    axes[4].plot(t, series["trunk_pitch"], label="trunk pitch (nose down +)")
    axes[4].set_ylabel("angle (deg)")
    axes[4].set_xlabel("time (s)")
    axes[4].set_title("(E) head attitude and trunk pitch", fontsize=10)
    for axis in axes:
        axis.grid(alpha=0.3)
        axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, frameon=False)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_walk(series: dict, path, title: str = "") -> None:
    """Write :func:`walk_figure` to ``path`` (PNG)."""
    fig = walk_figure(series, title)
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    atomic_files.save_figure(fig, path, dpi=100)
    plt.close(fig)
