"""PNG figures in the manner of the paper's Fig. 7 (matplotlib, Agg backend: no display needed)."""
from typing import Dict, List

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from agents import probes  # noqa: E402


def _smooth(x, n):
    x = np.asarray(x, np.float64)
    if x.size < 2 or n <= 1:
        return x
    n = min(n, x.size)
    c = np.cumsum(np.insert(x, 0, 0.0))
    out = np.empty_like(x)
    out[n - 1:] = (c[n:] - c[:-n]) / n
    out[:n - 1] = c[1:n] / np.arange(1, n)
    return out


def plot_learning_curves(runs: Dict[str, List[dict]], evals: Dict[str, List[dict]], path: str,
                         lesson_boundaries=None, baselines: Dict[str, dict] = None):
    """Fig. 7b: training return and success per episode, and held-out position error, curriculum vs SAC.

    `baselines` (label -> held-out summary, e.g. the lookup's) are dashed horizontal lines: the bar to clear.
    Domains without position errors (e.g. reacher) show the evaluation return instead.
    """
    fig, axes = plt.subplots(1, 3, figsize=(15, 4))
    labels = list(dict.fromkeys(list(runs) + list(evals or {}) + list(baselines or {})))
    color = {label: f"C{i}" for i, label in enumerate(labels)}
    for label, records in runs.items():
        if not records:
            continue
        steps = [r["env_steps"] for r in records]
        w = max(1, len(records) // 50)
        axes[0].plot(steps, _smooth([r["return"] for r in records], w), color=color[label], label=label)
        axes[1].plot(steps, _smooth([float(r["success"]) for r in records], w), color=color[label], label=label)
    has_errors = True
    for label, records in (evals or {}).items():
        if records:
            steps = [r["env_steps"] for r in records]
            if "position_error_median" not in records[0]["summary"]:
                has_errors = False
                axes[2].plot(steps, [r["summary"]["return_mean"] for r in records], "o-", color=color[label],
                             label=f"{label} mean return")
                continue
            axes[2].plot(steps, [r["summary"]["position_error_median"] for r in records], "o-", color=color[label],
                         label=f"{label} median")
            axes[2].plot(steps, [r["summary"]["position_error_p90"] for r in records], "x--", color=color[label],
                         label=f"{label} p90")
    for label, summary in (baselines or {}).items():
        axes[1].axhline(summary["success_rate"], color=color[label], ls="--", label=f"{label} held-out success")
        axes[2].axhline(summary["position_error_median"], color=color[label], ls="--",
                        label=f"{label} held-out median")
    if has_errors:
        axes[2].axhline(probes.POSITION_TOLERANCE, color="k", lw=0.8, ls=":")
    for ax in axes:
        for b in lesson_boundaries or []:
            ax.axvline(b, color="grey", lw=0.6, ls="--")
        ax.set_xlabel("environment steps")
        ax.ticklabel_format(axis="x", style="sci", scilimits=(3, 3))  # "x10^3": no overlapping labels
        ax.legend(fontsize=8)
    axes[0].set_ylabel("episode return (training)")
    axes[1].set_ylabel("success rate (training episodes)")
    axes[2].set_ylabel("held-out final position error (m)" if has_errors else "evaluation episode return")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_track(reports: Dict[str, dict], path: str):
    """Fig. 7a, c, d: head path, position error and head attitude over the `track` task."""
    fig, axes = plt.subplots(1, 3, figsize=(15, 4))
    for label, report in reports.items():
        s = report["series"]
        t = np.asarray(s["time"])
        if s.get("head_position"):
            hp = np.asarray(s["head_position"])
            axes[0].plot(hp[:, 0], hp[:, 1], label=label)
        axes[1].plot(t, s["position_error"], label=label)
        if s.get("head_attitude"):
            axes[2].plot(t, s["head_attitude"], label=label)
    any_report = next(iter(reports.values()))
    targets = [seg["target"] for seg in any_report["segments"] if seg.get("target") is not None]
    if targets:
        tg = np.asarray(targets)
        axes[0].plot(tg[:, 0], tg[:, 1], "r*", ms=12, label="targets")
    axes[0].set_xlabel("x (m)"); axes[0].set_ylabel("z (m)"); axes[0].set_aspect("equal", "datalim")
    axes[1].axhline(probes.POSITION_TOLERANCE, color="k", lw=0.8, ls=":")
    axes[1].set_xlabel("time (s)"); axes[1].set_ylabel("position error (m)")
    axes[2].axhspan(probes.LEVEL_ATTITUDE - probes.ATTITUDE_TOLERANCE, probes.LEVEL_ATTITUDE + probes.ATTITUDE_TOLERANCE,
                    color="green", alpha=0.15)
    axes[2].set_xlabel("time (s)"); axes[2].set_ylabel("head attitude (deg)")
    for ax in axes:
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
