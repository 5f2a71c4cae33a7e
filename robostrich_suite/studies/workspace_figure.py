"""Fig. 6 of the workspace study (:mod:`robostrich_suite.studies.workspace`).  Plotting only: it reads
the study's samples and imports nothing of the study (the study imports it)."""
from __future__ import annotations

import pathlib

import numpy as np

from robostrich_suite import atomic_files
from robostrich_suite.tasks.conventions import LEVEL_ATTITUDE_DEG, LEVEL_TOLERANCE_DEG


def plot_workspace(kinematic, actuated, base_xz: np.ndarray, path: str | pathlib.Path) -> pathlib.Path:
    """Fig. 6 (red: all head positions, blue: level head, black: base joint) and, on the
    right, the same kinematic regions faded under the actuated workspace. ``kinematic``:
    workspace.KinematicSamples; ``actuated``: workspace.ActuatedSamples or None."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    panels = 2 if actuated is not None else 1
    fig, axes = plt.subplots(1, panels, figsize=(6.2 * panels, 6.6), sharex=True, sharey=True,
                             squeeze=False)
    level = kinematic.level()
    ax = axes[0, 0]
    ax.scatter(*kinematic.head_position.T, s=1, c="tab:red", alpha=0.25, lw=0, rasterized=True,
               label=f"head positions ({len(level)} samples)")
    ax.scatter(*kinematic.head_position[level].T, s=3, c="tab:blue", lw=0, rasterized=True,
               label=f"attitude {LEVEL_ATTITUDE_DEG:.0f}$\\pm${LEVEL_TOLERANCE_DEG:.0f}$^\\circ$ ({level.sum()})")
    ax.set_title("(A) kinematic workspace (paper Fig. 6)")
    if actuated is not None:
        ax = axes[0, 1]
        ax.scatter(*kinematic.head_position.T, s=1, c="tab:red", alpha=0.06, lw=0,
                   rasterized=True, label="kinematic: all")
        ax.scatter(*kinematic.head_position[level].T, s=2, c="tab:blue", alpha=0.25, lw=0,
                   rasterized=True, label="kinematic: level")
        settled, act_level = actuated.settled, actuated.level()
        ax.scatter(*actuated.head_position[settled].T, s=4, c="0.15", lw=0, rasterized=True,
                   label=f"actuated: settled ({settled.sum()} of {len(settled)})")
        ax.scatter(*actuated.head_position[act_level].T, s=14, c="tab:cyan", edgecolors="navy",
                   linewidths=0.4, label=f"actuated: level ({act_level.sum()})")
        ax.set_title("(B) actuated workspace (tendon inputs held, settled under gravity)")
    for ax in axes[0]:
        ax.plot(*base_xz, "ko", ms=7, label="C18-frame joint")
        ax.set_aspect("equal")
        ax.set_xlabel("x (m, forward)")
        ax.grid(alpha=0.3)
        # below the axes: inside, it hid the workspace's lower edge
        legend = ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=3, fontsize=8,
                           frameon=False)
        for handle in legend.legend_handles:  # readable markers, whatever the point size
            if hasattr(handle, "set_sizes"):
                handle.set_sizes([25])
                handle.set_alpha(1)
    axes[0, 0].set_ylabel("z (m, up)")
    fig.tight_layout()
    atomic_files.save_figure(fig, path, dpi=130, bbox_inches="tight")  # the legends below the axes too
    plt.close(fig)
    return path
