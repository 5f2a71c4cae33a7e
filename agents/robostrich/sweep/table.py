"""Mean [min, max] over seeds of robostrich-train summaries: one aggregate per group of runs, and
the Markdown tables of it (the sweep's table, and every evaluation row by row).

``aggregate`` is what the committed records in docs/results/ keep (tools/results_page.py), so its
output keeps its shape: ``{"seeds", "minutes", "steps", "results": {label: {kind: {metric: stats}}}}``.
"""
import os
import shlex

from robostrich_suite import parsing

LABELS = ("curriculum", "baseline", "lookup")
KINDS = ("heldout", "heldout_moving", "new", "new_moving", "track")
METRICS = (("success_rate", "success rate (%)", 100.0, "{:.1f}"),
           ("precise_success_rate", "success within 1 cm and 2 deg (%)", 100.0, "{:.1f}"),
           ("position_error_median", "median position error (m)", 1.0, "{:.3f}"),
           ("attitude_error_median", "median attitude error (deg)", 1.0, "{:.1f}"))
TIMING_FILE = "benchmark_timing.json"  # wall-clock of a run's training command, beside its summary
RUN_TITLES = {"curriculum": "curriculum SAC", "baseline": "plain SAC", "lookup": "lookup"}


def _stats(values):
    """Mean, min and max over the seeds that have the number (all None where none has it)."""
    values = [float(v) for v in values if v is not None]
    if not values:
        return {"mean": None, "min": None, "max": None, "values": []}
    return {"mean": sum(values) / len(values), "min": min(values), "max": max(values), "values": values}


def aggregate(summaries, seeds=None, minutes=None) -> dict:
    """Mean, min and max over seeds of each run's evaluation metrics.

    `summaries` are the seeds' summary.json dicts (agents/robostrich/train/command.py: summary["runs"][label][kind]);
    `seeds` and `minutes` (wall-clock per seed, None where unknown) go into the result as given.
    """
    if not summaries:
        raise ValueError("no summaries to aggregate")
    seeds = list(range(len(summaries))) if seeds is None else list(seeds)
    minutes = [None] * len(summaries) if minutes is None else list(minutes)
    if not len(seeds) == len(minutes) == len(summaries):
        raise ValueError("seeds, minutes and summaries differ in length")
    # the evaluations at the end of each lesson but the last sit beside the final ones
    summaries = [{**s, "runs": {label: {**kinds, **s.get("lesson_ends", {}).get(label, {})}
                                for label, kinds in s["runs"].items()}} for s in summaries]
    present = {label for s in summaries for label in s["runs"]}
    labels = [l for l in LABELS if l in present] + sorted(present - set(LABELS))
    results = {}
    for label in labels:
        kinds_present = {k for s in summaries for k in s["runs"].get(label, {})}
        kinds = [k for k in KINDS if k in kinds_present] + sorted(kinds_present - set(KINDS))
        results[label] = {
            kind: {metric: _stats([s["runs"].get(label, {}).get(kind, {}).get(metric) for s in summaries])
                   for metric, *_ in METRICS}
            for kind in kinds}
        for kind in kinds:
            results[label][kind]["seeds"] = sum(kind in s["runs"].get(label, {}) for s in summaries)
    steps = {label: [s.get("env_steps", {}).get(label) for s in summaries] for label in labels}
    return {"seeds": seeds, "minutes": minutes, "steps": steps, "results": results}


def _training_minutes(summary: dict, label: str):
    timing = (summary.get("timings") or {}).get(label)
    return timing["seconds"] / 60.0 if timing else None


def training_minutes(summaries) -> dict:
    """Per run label, mean [min, max] over seeds of its training minutes (summary["timings"]: the
    last start of the run; a resumed run counts only what it trained after the resume)."""
    labels = sorted({label for s in summaries for label in s.get("timings") or {}})
    return {label: _stats([_training_minutes(s, label) for s in summaries]) for label in labels}


def _spread(stats, scale, fmt, collapse: bool = True) -> str:
    """'12.5 % [10.0, 15.0]' (the unit once), or one value where the seeds agree (``collapse``), or '-'."""
    if not stats or stats["mean"] is None:
        return "-"
    mean, low, high = (fmt.format(stats[k] * scale) for k in ("mean", "min", "max"))
    return mean if collapse and low == high else f"{mean} [{low.split()[0]}, {high.split()[0]}]"


def format_table(agg: dict) -> str:
    """Markdown: one row per run and evaluation, mean [min, max] over seeds; then steps and wall-clock."""
    n = len(agg["seeds"])
    lines = [f"Seeds: {', '.join(str(s) for s in agg['seeds'])} (mean [min, max] over {n} seed{'s' * (n != 1)})", "",
             "| run | evaluation | " + " | ".join(title for _, title, _, _ in METRICS) + " |",
             "|---|---|" + "---|" * len(METRICS)]
    for label, kinds in agg["results"].items():
        for kind, row in kinds.items():
            partial = f" ({row['seeds']}/{n} seeds)" if row["seeds"] != n else ""
            cells = [_spread(row[m], scale, fmt, collapse=False) for m, _, scale, fmt in METRICS]
            lines.append(f"| {label} | {kind}{partial} | " + " | ".join(cells) + " |")
    steps = ", ".join(f"{label} {_join(v)}" for label, v in agg["steps"].items() if any(x is not None for x in v))
    minutes = ", ".join(f"seed {s}: {'-' if m is None else f'{m:.1f}'}" for s, m in zip(agg["seeds"], agg["minutes"]))
    lines += ["", f"Environment steps per run: {steps or '-'}", f"Wall-clock minutes per seed: {minutes}"]
    return "\n".join(lines) + "\n"


def _join(values):
    distinct = sorted({v for v in values if v is not None})
    return "/".join(str(v) for v in distinct)


# The sweep's columns: (evaluation, metric, scale, format); the last column is the training time.
GROUP_COLUMNS = (("success, fixed start", "heldout", "success_rate", 100.0, "{:.1f} %"),
                 ("moving starts", "heldout_moving", "success_rate", 100.0, "{:.1f} %"),
                 ("new targets, fixed start", "new", "success_rate", 100.0, "{:.1f} %"),
                 ("new targets, moving starts", "new_moving", "success_rate", 100.0, "{:.1f} %"),
                 ("`track`", "track", "success_rate", 100.0, "{:.1f} %"),
                 ("within 1 cm and 2 deg", "heldout", "precise_success_rate", 100.0, "{:.1f} %"),
                 ("new targets within 1 cm and 2 deg", "new", "precise_success_rate", 100.0, "{:.1f} %"),
                 ("median position error", "heldout", "position_error_median", 100.0, "{:.2f} cm"),
                 ("median attitude error", "heldout", "attitude_error_median", 1.0, "{:.2f} deg"))


def group_table(agg: dict, minutes: dict) -> list:
    """Markdown rows of one group: curriculum, plain SAC and lookup (the ones it has), each with its
    success from the fixed and the moving starts (held-out and new targets), on `track`, the precise share, the median errors
    (fixed start) and its training minutes, mean [min, max] over the group's seeds; an evaluation
    no run has (the new targets of runs made before them) gets no column."""
    present = {kind for kinds in agg["results"].values() for kind in kinds}
    columns = [c for c in GROUP_COLUMNS if c[1] in present or c[1] == "heldout"]  # no column no run has
    lines = ["| run | " + " | ".join(c[0] for c in columns) + " | minutes |",
             "|---|" + "---|" * (len(columns) + 1)]
    seeds = len(agg["seeds"])
    for label, kinds in agg["results"].items():
        counted = kinds.get("heldout", {}).get("seeds", seeds)
        partial = f" ({counted} of {seeds} seeds)" if counted != seeds else ""
        cells = [_spread(kinds.get(kind, {}).get(metric), scale, fmt) for _, kind, metric, scale, fmt in columns]
        cells.append(_spread(minutes.get(label), 1.0, "{:.1f}"))
        lines.append(f"| {RUN_TITLES.get(label, label)}{partial} | " + " | ".join(cells) + " |")
    return lines


def run_minutes(run_dir: str, summary: dict):
    """Wall-clock minutes of the run's last training command (its timing file); else the training's
    own timings of its last start (None if neither)."""
    path = os.path.join(run_dir, TIMING_FILE)
    if os.path.exists(path):
        minutes = parsing.read_json(path)
        if not isinstance(minutes, dict) or not isinstance(minutes.get("minutes"), (int, float)):
            raise ValueError(f"{path}: not a timing file of robostrich-sweep (no number 'minutes')")
        return minutes["minutes"]
    timings = summary.get("timings") or {}
    return sum(t["seconds"] for t in timings.values()) / 60.0 if timings else None


def _group_lines(name: str, group: dict) -> list:
    agg = group["aggregate"]
    lines = [f"## {name}", "", f"`{shlex.join(['robostrich-train', *group['arguments']])}` and each run's --seed, --out",
             ""]
    if agg is None:
        return lines + [f"No finished run yet (seeds {', '.join(map(str, group['seeds']))}).", ""]
    n = len(agg["seeds"])
    wall = _stats(agg["minutes"])
    lines += [f"Seeds {', '.join(map(str, agg['seeds']))} ({n} of {len(group['seeds'])} finished); "
              f"mean [min, max] over them; minutes: training of each run's last start; wall-clock per run: "
              f"{_spread(wall, 1.0, '{:.1f}')} min.", ""]
    return lines + group_table(agg, group["training_minutes"]) + [""]


def sweep_markdown(result: dict) -> str:
    """The sweep's table file: per group its runs' mean [min, max] over seeds (group_table), then
    every failed run with its one-line error."""
    failed = result["failed"]
    lines = ["# Sweep", "", f"`{shlex.join(result['command'])}`: {result['finished']} of {result['total']} runs "
             f"finished, {len(failed)} failed. Success is the paper's (the head within 5 cm and 5 deg of level); "
             "the errors are from the fixed start.", ""]
    for name, group in result["groups"].items():
        lines += _group_lines(name, group)
    if failed:
        lines += ["## Failed runs", ""] + [f"- {f['group']} seed {f['seed']}: {f['error']}" for f in failed] + [""]
    return "\n".join(lines)
