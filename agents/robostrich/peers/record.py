"""What tools/benchmark_peers.py writes from its runs' results: peers.json and the learning curves' figure.

Why in one place: the record (docs/results/, via tools/results_page.py add) and the figure must
show the same numbers, mean and [min, max] over the seeds of one command.
"""
import numpy as np

from agents.robostrich.peers import sbx_agents as peers
from agents.robostrich.peers import benchmark as bench


def run_name(label: str) -> str:
    """'SBX TQC, through the lessons' / 'curriculum SAC (ours)'."""
    if label in bench.OURS:
        return bench.OURS[label]
    agent, way = label.rsplit("_", 1)
    return f"SBX {peers.PEERS[agent]}, {peers.WAYS[way]}"


def stats(values: list) -> dict:
    kept = [v for v in values if v is not None]
    if not kept:
        return {"mean": None, "min": None, "max": None, "values": values}
    return {"mean": float(np.mean(kept)), "min": float(min(kept)), "max": float(max(kept)), "values": values}


def mean_curve(curves: list) -> tuple:
    """(steps, success of each seed at them): the evaluation points every seed has."""
    steps = sorted(set.intersection(*(set(s for s, _ in c) for c in curves)))
    return steps, np.array([[dict(map(tuple, c))[s] for s in steps] for c in curves])


def first_reach(curves: list, bar: float = bench.BAR):
    """The first evaluation point where the seeds' mean held-out success is at least ``bar``; None if never."""
    steps, values = mean_curve(curves)
    reached = [s for s, v in zip(steps, values.mean(axis=0)) if v >= bar]
    return int(reached[0]) if reached else None


def aggregate(settings, results: dict) -> dict:
    """{label: the run's record entry}: finals per evaluation, wall-clock and curve, over the seeds."""
    runs = {}
    for label in finished(settings, results):
        seeds = [seed for seed in settings.seeds if results.get((label, seed))]
        rows = [results[(label, seed)] for seed in seeds]
        runs[label] = {
            "name": run_name(label), "seeds": seeds,
            "final": {kind: {field: stats([row["final"].get(kind, {}).get(field) for row in rows])
                             for field in bench.FIELDS}
                      for kind in bench.KINDS if any(kind in row["final"] for row in rows)},
            "minutes": stats([row["train_seconds"] / 60 for row in rows]),
            "env_steps": [row["env_steps"] for row in rows],
            "curves": [row["curve"] for row in rows],
            "reach_bar": first_reach([row["curve"] for row in rows]),
        }
    return runs


def finished(settings, results: dict) -> list:
    """The runs with a finished seed (a record from a stopped command holds only these, each
    over its finished seeds)."""
    return [label for label in bench.job_labels(settings)
            if any(results.get((label, seed)) for seed in settings.seeds)]


def lookup(settings, results: dict) -> dict:
    """The lookup's final evaluation (the same on every seed: it does not learn), from our first run."""
    for label in bench.OURS:
        for seed in settings.seeds:
            row = results.get((label, seed))
            if row and row.get("lookup"):
                return {kind: bench.compact(s) for kind, s in row["lookup"].items()}
    return {}


def record(settings, results: dict, command: str) -> dict:
    """peers.json: the runs, the lookup, the budget and how each run met the lessons."""
    return {"benchmark": "peers", "command": command, "steps": settings.steps, "seeds": list(settings.seeds),
            "bar": bench.BAR, "num_eval_targets": settings.num_eval_targets, "versions": peers.versions(),
            "ways": {way: describe_way(way, settings.steps) for way in settings.ways},
            "runs": aggregate(settings, results), "lookup": lookup(settings, results),
            "unfinished": [f"{run_name(label)} seed {seed}" for label in bench.job_labels(settings)
                           for seed in settings.seeds if not results.get((label, seed))]}


def describe_way(way: str, steps: int) -> str:
    plan = bench.lesson_plan(way, steps)
    return " then ".join(f"{lesson.task} {lesson.steps}" for lesson in plan)


def plot(data: dict, path: str) -> None:
    """Held-out success (fixed start, periodic evaluation) against control steps: a line per run,
    the mean over seeds with its [min, max] shaded; the lookup as a dashed line."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5))
    for label, run in data["runs"].items():
        steps, values = mean_curve(run["curves"])
        line, = ax.plot(steps, values.mean(axis=0) * 100, marker="o", markersize=3, label=run["name"],
                        linestyle="-" if label in bench.OURS or label.endswith("_lessons") else "--")
        ax.fill_between(steps, values.min(axis=0) * 100, values.max(axis=0) * 100, color=line.get_color(), alpha=0.15)
    fixed = data["lookup"].get("heldout", {}).get("success_rate")
    if fixed is not None:
        ax.axhline(fixed * 100, color="black", linestyle=":", label="lookup (no learning)")
    ax.axhline(data["bar"] * 100, color="grey", linewidth=0.5)
    ax.set(xlabel="control steps", ylabel="held-out success, fixed start (%)", ylim=(-2, 102),
           title=f"Peers on the arm: mean and [min, max] over seeds {', '.join(map(str, data['seeds']))}")
    ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
