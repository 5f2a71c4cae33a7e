"""The figure of `robostrich-robustness`: success against scale s, a line per family, one column
per evaluated policy (the policy, a compared one, the lookup) and one row per evaluation (fixed
start, moving starts, and on the quadruped while it walks), so the policy and the baseline sit side
by side on the same axes' scale."""
import matplotlib
import matplotlib.pyplot as plt

from robostrich_suite import atomic_files

# What each evaluation of robustness.json is, in words (the command, this figure and the results table
# read it): held-out targets from the fixed start, from moving starts, and on the quadruped while it walks.
KINDS = {"heldout": "fixed start", "heldout_moving": "moving starts", "walking": "while walking"}


def plot(report: dict, path) -> None:
    """robustness.png from the robustness.json ``report``."""
    labels = report["labels"]
    names = {"policy": report.get("policy"), "compare": report.get("compare")}  # the policies' own names
    kinds = [k for k in KINDS if any(k in rows[0] for rows in report["results"][labels[0]].values())]
    matplotlib.use("Agg")  # files, never a window (at plot time: importing must not switch a notebook's backend)
    fig, axes = plt.subplots(len(kinds), len(labels), figsize=(4.2 * len(labels), 3.4 * len(kinds)),
                             sharex=True, sharey=True, squeeze=False)
    colours = plt.get_cmap("tab10")
    for column, label in enumerate(labels):
        for row, kind in enumerate(kinds):
            ax = axes[row][column]
            for i, (family, rows) in enumerate(report["results"][label].items()):
                style = dict(color="black", linewidth=2.2) if family == "all" else dict(color=colours(i % 10))
                ax.plot([r["scale"] for r in rows], [100 * r[kind]["success_rate"] for r in rows],
                        marker="o", markersize=3, label=family, **style)
            ax.axhline(90, color="grey", linestyle=":", linewidth=0.8)
            ax.set_title(f"{names.get(label) or label}: held-out, {KINDS[kind]}", fontsize=9)
            ax.set_ylim(-3, 103)
            ax.grid(alpha=0.3)
            if row == len(kinds) - 1:
                ax.set_xlabel("scale s (robostrich_suite/tasks/perturbations.py)")
            if column == 0:
                ax.set_ylabel("success (%)")
    axes[0][-1].legend(fontsize=7, loc="lower left")
    fig.suptitle(f"{report['policy']} on {report['domain']}, {report['num_targets']} held-out targets", fontsize=10)
    fig.tight_layout()
    atomic_files.save_figure(fig, path, dpi=110)
    plt.close(fig)
