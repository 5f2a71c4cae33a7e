"""PNG figures in the manner of the paper's Fig. 7 (matplotlib, Agg backend: no display needed).

``learning_curves_figure``, ``track_figure`` and ``seed_groups_figure`` return the Figure (so
tests can read what a reader sees); ``plot_learning_curves``, ``plot_track`` and
``plot_seed_groups`` write it as a PNG.
"""
import textwrap
from typing import Dict, List

import numpy as np

from robostrich_suite import atomic_files
from robostrich_suite.tasks.conventions import LEVEL_ATTITUDE_DEG, LEVEL_TOLERANCE_DEG, POSITION_TOLERANCE

# A rate: always its whole range, so 0 % reads as 0 %; room above 1 for the lesson names.
SUCCESS_LIMITS = (-0.03, 1.1)
# How a figure names the runs of robostrich-train (its run directories' labels)
RUN_NAMES = {"curriculum": "curriculum SAC", "baseline": "plain SAC (final lesson only)", "lookup": "lookup (no learning)"}


def _subplots(*args, **kwargs):
    """``plt.subplots`` drawing into files (Agg), chosen at plot time: importing this module must
    not switch a notebook's backend. matplotlib is imported here, as the studies' figures do: a
    command that draws nothing (--no-figures, a bad flag) starts without it."""
    import matplotlib
    import matplotlib.pyplot as plt
    matplotlib.use("Agg")
    return plt.subplots(*args, **kwargs)



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


def _save(fig, path: str) -> None:
    import matplotlib.pyplot as plt
    atomic_files.save_figure(fig, path, dpi=110)
    plt.close(fig)


def _tolerances(summaries) -> tuple:
    """(position m, attitude deg) the reports were judged with; the paper's when they do not say."""
    for summary in summaries:
        if summary and "position_tolerance_m" in summary:
            return summary["position_tolerance_m"], summary.get("attitude_tolerance_deg",
                                                                 LEVEL_TOLERANCE_DEG)
    return POSITION_TOLERANCE, LEVEL_TOLERANCE_DEG


def _lesson_names(runs: Dict[str, List[dict]], count: int) -> List[str]:
    """The curriculum's lesson tasks in order, from the run whose records span ``count`` lessons."""
    for records in runs.values():
        names = list(dict.fromkeys(r["task"] for r in records if "task" in r))
        if len(names) == count:
            return names
    return []


def _mark_lessons(axes, boundaries, names, last_step) -> None:
    """Dashed line at each lesson change (one legend entry); lesson names along the top."""
    for ax in axes:
        for i, b in enumerate(boundaries):
            ax.axvline(b, color="grey", lw=0.7, ls="--", label="lesson change" if i == 0 else None)
    if not names:
        return
    edges = [0.0, *boundaries, last_step]
    for ax in axes:
        low, high = ax.get_ylim()
        ax.set_ylim(low, high + 0.08 * (high - low))  # headroom: names above the data
        top = ax.get_xaxis_transform()  # x in data, y in axes units
        shown_left, shown_right = ax.get_xlim()
        for name, left, right in zip(names, edges[:-1], edges[1:]):
            left, right = max(left, shown_left), min(right, shown_right)  # centred on what shows
            ax.text((left + right) / 2, 0.98, name, transform=top, ha="center", va="top",
                    fontsize=8, color="0.35")


def learning_curves_figure(runs: Dict[str, List[dict]], evals: Dict[str, List[dict]],
                           lesson_boundaries=None, baselines: Dict[str, dict] = None):
    """Fig. 7b: (a) training return, (b) held-out success at each evaluation (training episodes'
    success faded behind it), (c) held-out position error, curriculum vs SAC.

    `baselines` (label -> held-out summary, e.g. the lookup's) are dashed horizontal lines: the bar to
    clear, held-out against held-out.
    Domains without position errors (e.g. reacher) show the evaluation return instead.
    """
    fig, axes = _subplots(1, 3, figsize=(15, 4.6))
    labels = list(dict.fromkeys(list(runs) + list(evals or {}) + list(baselines or {})))
    color = {label: f"C{i}" for i, label in enumerate(labels)}
    last_step = 0
    for label, records in runs.items():
        if not records:
            continue
        steps = [r["env_steps"] for r in records]
        last_step = max(last_step, steps[-1])
        w = max(1, len(records) // 50)
        axes[0].plot(steps, _smooth([r["return"] for r in records], w), color=color[label], label=_name(label))
        axes[1].plot(steps, _smooth([float(r["success"]) for r in records], w), color=color[label], alpha=0.3,
                     lw=1, label=f"{_name(label)}, training episodes")
    for label, records in (evals or {}).items():
        if records and "success_rate" in records[0]["summary"]:
            axes[1].plot([r["env_steps"] for r in records], [r["summary"]["success_rate"] for r in records], "o-",
                         color=color[label], ms=4, label=f"{_name(label)}, held-out")
    has_errors = _plot_heldout(axes[2], evals or {}, color)
    for label, summary in (baselines or {}).items():
        axes[1].axhline(summary["success_rate"], color=color[label], ls="--", label=f"{_name(label)}, held-out")
        if has_errors:
            axes[2].axhline(summary["position_error_median"], color=color[label], ls="--",
                            label=f"{_name(label)} held-out median")
    if has_errors:
        summaries = [r["summary"] for records in (evals or {}).values() for r in records]
        tolerance = _tolerances(summaries + list((baselines or {}).values()))[0]
        axes[2].axhline(tolerance, color="k", lw=0.8, ls=":",
                        label=f"position tolerance ({1000 * tolerance:.0f} mm)")
        axes[2].set_ylim(bottom=0.0)
    boundaries = list(lesson_boundaries or [])
    _mark_lessons(axes, boundaries, _lesson_names(runs, len(boundaries) + 1), last_step)
    axes[1].set_ylim(*SUCCESS_LIMITS)
    for ax in axes:
        ax.set_xlabel("control steps")
        ax.ticklabel_format(axis="x", style="sci", scilimits=(3, 3))  # "x10^3": no overlapping labels
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="best")
    axes[0].set_title("(a) training episode return", fontsize=10)
    axes[0].set_ylabel("episode return")
    axes[1].set_title("(b) success: held-out targets (training episodes faded)", fontsize=10)
    axes[1].set_ylabel("success rate")
    if has_errors:
        axes[2].set_title("(c) held-out final position error", fontsize=10)
        axes[2].set_ylabel("position error (m)")
    else:
        axes[2].set_title("(c) held-out evaluation return", fontsize=10)
        axes[2].set_ylabel("episode return")
    fig.suptitle("Learning curves: " + " vs ".join(map(_name, runs)) + " (the curriculum's lessons between "
                 "dashed lines)", fontsize=11)
    fig.tight_layout()
    return fig


def _plot_heldout(ax, evals: Dict[str, List[dict]], color) -> bool:
    """Held-out median and p90 position error per evaluation; False (returns drawn) without errors."""
    has_errors = True
    for label, records in evals.items():
        if not records:
            continue
        steps = [r["env_steps"] for r in records]
        if "position_error_median" not in records[0]["summary"]:
            has_errors = False
            ax.plot(steps, [r["summary"]["return_mean"] for r in records], "o-", color=color[label],
                    label=f"{_name(label)} mean return")
            continue
        ax.plot(steps, [r["summary"]["position_error_median"] for r in records], "o-", color=color[label],
                label=f"{_name(label)} median")
        ax.plot(steps, [r["summary"]["position_error_p90"] for r in records], "x--", color=color[label],
                label=f"{_name(label)} p90")
    return has_errors


def plot_learning_curves(runs: Dict[str, List[dict]], evals: Dict[str, List[dict]], path: str,
                         lesson_boundaries=None, baselines: Dict[str, dict] = None):
    """Write :func:`learning_curves_figure` to ``path`` (PNG)."""
    _save(learning_curves_figure(runs, evals, lesson_boundaries, baselines), path)


def _target_changes(report: dict) -> List[float]:
    """Times (s) at which the track moves on to its next target."""
    time = report["series"]["time"]
    starts = [seg.get("start_step") for seg in report["segments"][1:]]
    return [time[s] for s in starts if s is not None and 0 <= s < len(time)]


def _plot_targets_in_order(ax, report: dict) -> None:
    """The targets as numbered stars joined in the order the head must visit them."""
    targets = [seg["target"] for seg in report["segments"] if seg.get("target") is not None]
    if not targets:
        return
    tg = np.asarray(targets)
    ax.plot(tg[:, 0], tg[:, 1], "--", color="r", lw=0.8, alpha=0.6)
    ax.plot(tg[:, 0], tg[:, 1], "r*", ms=13, label="targets, in order")
    for number, (x, z) in enumerate(tg, start=1):
        ax.annotate(str(number), (x, z), xytext=(6, 6), textcoords="offset points", color="r",
                    fontsize=10, fontweight="bold")


def _name(label: str) -> str:
    return RUN_NAMES.get(label, label)


def _track_label(label: str, report: dict, note: str = None) -> str:
    """'curriculum SAC (seed 2, 600k control steps): 3 of 3 reached': the run against the goal."""
    segments = report.get("segments", [])
    reached = sum(bool(seg.get("success")) for seg in segments)
    name = _name(label) + (f" ({note})" if note else "")
    return f"{name}: {reached} of {len(segments)} reached" if segments else name


def track_figure(reports: Dict[str, dict], notes: Dict[str, str] = None):
    """Fig. 7a, c, d: (a) head path, (b) position error and (c) head attitude over the `track` task.
    Each run's legend entry says how many targets it reached (the goal: all); ``notes`` (label ->
    text, e.g. its seed and budget) are added to its name."""
    fig, axes = _subplots(1, 3, figsize=(15, 4.6))
    runs = {}  # legend label -> its line in (b)
    for i, (label, report) in enumerate(reports.items()):
        s = report["series"]
        t = np.asarray(s["time"])
        label = _track_label(label, report, (notes or {}).get(label))
        if s.get("head_position"):
            hp = np.asarray(s["head_position"])
            axes[0].plot(hp[:, 0], hp[:, 1], color=f"C{i}", label=label)
            axes[0].plot(*hp[0], "o", color=f"C{i}", mfc="w", ms=7)
        runs[label], = axes[1].plot(t, s["position_error"], color=f"C{i}", label=label)
        if s.get("head_attitude"):
            axes[2].plot(t, s["head_attitude"], color=f"C{i}", label=label)
    any_report = next(iter(reports.values()))
    axes[0].plot([], [], "o", color="k", mfc="w", label="start")
    _plot_targets_in_order(axes[0], any_report)
    position_tolerance, attitude_tolerance = _tolerances(r.get("summary") for r in reports.values())
    axes[1].axhline(position_tolerance, color="k", lw=0.8, ls=":",
                    label=f"position tolerance ({1000 * position_tolerance:.0f} mm)")
    axes[1].set_ylim(bottom=0.0)
    axes[2].axhspan(LEVEL_ATTITUDE_DEG - attitude_tolerance, LEVEL_ATTITUDE_DEG + attitude_tolerance,
                    color="green", alpha=0.15,
                    label=f"level head ({LEVEL_ATTITUDE_DEG:.0f} $\\pm$ {attitude_tolerance:.0f} deg)")
    for ax in axes[1:]:
        for j, change in enumerate(_target_changes(any_report)):
            ax.axvline(change, color="grey", lw=0.7, ls="--", label="next target" if j == 0 else None)
    axes[0].set_xlabel("x (m, forward)"); axes[0].set_ylabel("z (m, up)"); axes[0].set_aspect("equal", "datalim")
    axes[0].set_title("(a) head path", fontsize=10)
    axes[1].set_xlabel("time (s)"); axes[1].set_ylabel("position error (m)")
    axes[1].set_title("(b) distance from the current target", fontsize=10)
    axes[2].set_xlabel("time (s)"); axes[2].set_ylabel("head attitude (deg, 90 = level)")
    axes[2].set_title("(c) head attitude", fontsize=10)
    for ax in axes:  # the panels' own marks; the runs, with their outcome, in one legend below
        ax.grid(alpha=0.3)
        handles, labels = ax.get_legend_handles_labels()
        ax.legend([h for h, l in zip(handles, labels) if l not in runs],
                  [l for l in labels if l not in runs], fontsize=8, loc="best")
    fig.legend(list(runs.values()), list(runs), loc="lower center", ncol=len(runs), fontsize=9, frameon=False)
    where = f"{any_report['domain']}/{any_report['task']}" if "task" in any_report else "track"
    fig.suptitle(f"Tracking ({where}): the head visits {len(any_report['segments'])} targets in turn; goal: "
                 f"each reached, within {1000 * position_tolerance:.0f} mm and {attitude_tolerance:.0f} deg of level "
                 "at the end of its turn", fontsize=11)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    return fig


def plot_track(reports: Dict[str, dict], path: str, notes: Dict[str, str] = None):
    """Write :func:`track_figure` to ``path`` (PNG)."""
    _save(track_figure(reports, notes), path)


def seed_groups_figure(groups: Dict[str, List[dict]], lookup: Dict[str, float] = None,
                       lesson_boundaries=None):
    """Training configurations compared over seeds, the way docs/log/learning.md reads them:
    (a) periodic held-out success and (b) held-out median position error along training (mean
    over seeds, the min-max band shaded), (c) the final held-out success of every seed, from the
    fixed start and from moving starts.

    ``groups``: label -> one dict per seed, ``{"seed": int, "evals": [evals.jsonl records],
    "final": {kind: summary}}`` (kind ``heldout`` and optionally ``heldout_moving``);
    ``lookup``: kind -> the lookup's final success rate, drawn dashed (the bar to clear).
    """
    fig, axes = _subplots(1, 3, figsize=(15, 4.6), gridspec_kw={"width_ratios": [1.2, 1.2, 1.0]})
    last_step = 0
    for index, (label, seeds) in enumerate(groups.items()):
        last_step = max(last_step, _plot_seed_curves(axes[:2], label, seeds, f"C{index}"))
        _plot_final_rates(axes[2], index, seeds, f"C{index}")
    for kind, style in (("heldout", "--"), ("heldout_moving", ":")):
        if lookup and kind in lookup:
            where = "fixed start" if kind == "heldout" else "moving starts"
            axes[2].axhline(lookup[kind], color="k", ls=style, lw=1, label=f"lookup, {where}")
            if kind == "heldout":
                axes[0].axhline(lookup[kind], color="k", ls=style, lw=1, label="lookup (all held-out targets)")
    _dress_seed_groups(fig, axes, list(groups), lesson_boundaries, last_step)
    return fig


def _plot_seed_curves(axes, label: str, seeds: List[dict], color: str) -> int:
    """(a) and (b): the mean over seeds with the min-max band; returns the last step every seed reached."""
    curves = [s["evals"] for s in seeds if s["evals"]]
    if not curves:
        return 0
    length = min(len(c) for c in curves)  # the steps every seed has reached
    steps = np.array([r["env_steps"] for r in curves[0][:length]])
    for ax, metric in zip(axes, ("success_rate", "position_error_median")):
        values = np.array([[r["summary"][metric] for r in c[:length]] for c in curves])
        ax.plot(steps, values.mean(axis=0), "o-", color=color, ms=3, label=f"{label} (mean of {len(curves)} seeds)")
        ax.fill_between(steps, values.min(axis=0), values.max(axis=0), color=color, alpha=0.15)
    return int(steps[-1])


def _plot_final_rates(ax, index: int, seeds: List[dict], color: str) -> None:
    """(c): every seed's final success from the fixed start and from moving starts, the mean as a bar."""
    for offset, (kind, marker) in enumerate((("heldout", "o"), ("heldout_moving", "^"))):
        rates = [(s["seed"], s["final"][kind]["success_rate"]) for s in seeds if kind in s.get("final", {})]
        if not rates:
            continue
        x = index + (offset - 0.5) * 0.3
        ax.scatter([x] * len(rates), [r for _, r in rates], color=color, marker=marker,
                   label="fixed start" if index == 0 and kind == "heldout" else
                   ("moving starts" if index == 0 else None), zorder=3)
        for seed, rate in rates:
            ax.annotate(str(seed), (x, rate), xytext=(4, 0), textcoords="offset points",
                        fontsize=7, va="center", color="0.3")
        mean = float(np.mean([r for _, r in rates]))
        ax.plot([x - 0.1, x + 0.1], [mean, mean], color=color, lw=2)


def _dress_seed_groups(fig, axes, labels_of_groups: List[str], lesson_boundaries, last_step: int) -> None:
    """Limits, scales, lesson marks, ticks, titles and the shared legend of the seed-groups figure."""
    axes[0].set_ylim(*SUCCESS_LIMITS)
    axes[2].set_ylim(*SUCCESS_LIMITS)
    axes[1].set_yscale("log")
    axes[1].axhline(0.01, color="k", lw=0.8, ls=":", label="1 cm goal")
    boundaries = list(lesson_boundaries or [])
    _mark_lessons(axes[:2], boundaries, [f"lesson {i + 1}" for i in range(len(boundaries) + 1)]
                  if boundaries else [], last_step)
    for ax in axes[:2]:
        ax.set_xlabel("control steps")
        ax.ticklabel_format(axis="x", style="sci", scilimits=(3, 3))
    axes[2].set_xticks(range(len(labels_of_groups)))
    axes[2].set_xticklabels([textwrap.fill(label, 12) for label in labels_of_groups], fontsize=8)
    axes[2].set_xlim(-0.6, len(labels_of_groups) - 0.4)
    for ax in axes:
        ax.grid(alpha=0.3)
    # (a) and (b) share their lines: one legend under both, off the data; (c) keeps its markers'.
    handles, labels = axes[0].get_legend_handles_labels()
    extra = [(h, l) for h, l in zip(*axes[1].get_legend_handles_labels()) if l not in labels]
    fig.legend(handles + [h for h, _ in extra], labels + [l for _, l in extra], loc="lower center",
               ncol=min(4, len(labels) + len(extra)), fontsize=8, frameon=False)
    axes[2].legend(fontsize=7, loc="lower left")
    axes[0].set_title("(a) periodic held-out success (spread targets)", fontsize=10)
    axes[0].set_ylabel("success rate")
    axes[1].set_title("(b) periodic held-out median position error", fontsize=10)
    axes[1].set_ylabel("position error (m)")
    axes[2].set_title("(c) final held-out success per seed (bar: mean)", fontsize=10)
    axes[2].set_ylabel("success rate")
    fig.suptitle("Configurations over seeds: mean line, min-max band", fontsize=11)
    legend_rows = -(-(len(labels) + len(extra)) // 4)
    fig.tight_layout(rect=(0, 0.04 + 0.045 * legend_rows, 1, 1))


def plot_seed_groups(groups: Dict[str, List[dict]], path: str, lookup: Dict[str, float] = None,
                     lesson_boundaries=None):
    """Write :func:`seed_groups_figure` to ``path`` (PNG)."""
    _save(seed_groups_figure(groups, lookup, lesson_boundaries), path)
