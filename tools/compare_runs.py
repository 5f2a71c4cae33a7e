"""Compare training configurations over seeds in one figure (docs/log/learning.md's pictures).

    python tools/compare_runs.py --out docs/her_lesson1.png \
        "eq. 10 + precision=runs/P1_s*" "+ HER in lesson 1=runs/P1_H1_s*"

Each GROUP is ``LABEL=GLOB``: the glob names robostrich-train output directories (one per seed;
their curriculum/evals.jsonl, config.json and summary.json are read). Writes a PNG (periodic
held-out success and position error along training, final success per seed, the lookup's level
dashed) and prints each group's final numbers as agents/robostrich/sweep/table.py tabulates them
(mean [min, max] over its seeds).
"""
import argparse
import glob
import json
import os

import numpy as np

from agents.robostrich import figures
from agents.robostrich.sweep import table as sweep_table
from agents.robostrich.run_spec import parse_plan

KINDS = ("heldout", "heldout_moving")


def load_run(run_dir: str) -> dict:
    """One seed's periodic and final evaluations (the curriculum run of a robostrich-train directory)."""
    try:
        with open(os.path.join(run_dir, "config.json")) as f:
            config = json.load(f)
        with open(os.path.join(run_dir, "summary.json")) as f:
            summary = json.load(f)
        runs = summary["runs"]
        with open(os.path.join(run_dir, "curriculum", "evals.jsonl")) as f:
            evals = [json.loads(line) for line in f if line.strip()]
        return {"seed": int(config["seed"]), "evals": evals, "plan": config["plans"]["curriculum"],
                "summary": summary, "minutes": sweep_table.run_minutes(run_dir, summary),
                "final": {k: runs["curriculum"][k] for k in KINDS if k in runs["curriculum"]},
                "lookup": {k: runs["lookup"][k]["success_rate"] for k in KINDS if k in runs.get("lookup", {})}}
    except (OSError, ValueError, KeyError) as e:
        raise SystemExit(f"compare_runs: error: {run_dir} is not a finished robostrich-train run ({e})")


def parse_group(text: str):
    label, sep, pattern = text.partition("=")
    if not sep or not label or not pattern:
        raise argparse.ArgumentTypeError(f"a group is LABEL=GLOB, got {text!r}")
    dirs = sorted(glob.glob(pattern))
    if not dirs:
        raise argparse.ArgumentTypeError(f"no run directory matches {pattern!r}")
    return label, dirs


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("groups", nargs="+", type=parse_group, metavar="LABEL=GLOB")
    parser.add_argument("--out", required=True, help="PNG to write")
    args = parser.parse_args(argv)
    groups = {label: [load_run(d) for d in dirs] for label, dirs in args.groups}
    runs = [run for seeds in groups.values() for run in seeds]
    lookup = next((r["lookup"] for r in runs if r["lookup"]), None)
    boundaries = np.cumsum([lesson.steps for lesson in parse_plan(runs[0]["plan"])])[:-1]
    figures.plot_seed_groups(groups, args.out, lookup, list(boundaries))
    for label, seeds in groups.items():
        print(f"## {label}\n")
        print(sweep_table.format_table(sweep_table.aggregate(
            [s["summary"] for s in seeds], [s["seed"] for s in seeds], [s["minutes"] for s in seeds])))
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
