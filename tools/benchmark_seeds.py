"""The main job over several seeds, so a comparison of curriculum, baseline and lookup has a spread.

    python tools/benchmark_seeds.py [--seeds 0,1,2] [--out runs/seeds] [robostrich-train arguments ...]
    python tools/benchmark_seeds.py --seeds 0,1,2 --steps 60000 --her-ratio 0.5

Each seed K runs `robostrich-train --seed K --out DIR/seed_K ...` (curriculum SAC, plain SAC at the
same budget, lookup baseline); any argument this tool does not know goes to the training command.
A seed whose summary.json exists is not re-run, and one with checkpoints but no summary is resumed,
so a killed benchmark continues where it stopped.  Then every seed's summary.json is aggregated
into DIR/seeds.md (Markdown table: mean [min, max] over seeds) and DIR/seeds.json.
"""
import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

LABELS = ("curriculum", "baseline", "lookup")
KINDS = ("heldout", "heldout_moving", "track")
METRICS = (("success_rate", "success rate (%)", 100.0, "{:.1f}"),
           ("precise_success_rate", "success within 1 cm and 2 deg (%)", 100.0, "{:.1f}"),
           ("position_error_median", "median position error (m)", 1.0, "{:.3f}"),
           ("attitude_error_median", "median attitude error (deg)", 1.0, "{:.1f}"))
TIMING_FILE = "benchmark_timing.json"  # wall-clock of the seed's training command, beside its summary


def parse_seeds(text: str):
    try:
        seeds = [int(s) for s in text.split(",") if s.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--seeds wants comma-separated integers, got {text!r}") from None
    if not seeds or len(set(seeds)) != len(seeds):
        raise argparse.ArgumentTypeError(f"--seeds wants distinct integers, got {text!r}")
    return seeds


def build_parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False,
                                epilog="Other arguments are passed to robostrich-train (agents/robostrich/training.py).")
    p.add_argument("--seeds", type=parse_seeds, default=[0, 1, 2], help="comma-separated seeds (default 0,1,2)")
    p.add_argument("--out", default="runs/seeds", help="benchmark directory; seed K trains into OUT/seed_K")
    return p


def _stats(values):
    """Mean, min and max over the seeds that have the number (all None where none has it)."""
    values = [float(v) for v in values if v is not None]
    if not values:
        return {"mean": None, "min": None, "max": None, "values": []}
    return {"mean": sum(values) / len(values), "min": min(values), "max": max(values), "values": values}


def aggregate(summaries, seeds=None, minutes=None) -> dict:
    """Mean, min and max over seeds of each run's evaluation metrics.

    `summaries` are the seeds' summary.json dicts (agents/robostrich/training.py: summary["runs"][label][kind]);
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


def _cell(stats, scale, fmt):
    if stats["mean"] is None:
        return "-"
    mean, low, high = (fmt.format(stats[k] * scale) for k in ("mean", "min", "max"))
    return f"{mean} [{low}, {high}]"


def format_table(agg: dict) -> str:
    """Markdown: one row per run and evaluation, mean [min, max] over seeds; then steps and wall-clock."""
    n = len(agg["seeds"])
    lines = [f"Seeds: {', '.join(str(s) for s in agg['seeds'])} (mean [min, max] over {n} seed{'s' * (n != 1)})", "",
             "| run | evaluation | " + " | ".join(title for _, title, _, _ in METRICS) + " |",
             "|---|---|" + "---|" * len(METRICS)]
    for label, kinds in agg["results"].items():
        for kind, row in kinds.items():
            partial = f" ({row['seeds']}/{n} seeds)" if row["seeds"] != n else ""
            lines.append(f"| {label} | {kind}{partial} | "
                         + " | ".join(_cell(row[m], scale, fmt) for m, _, scale, fmt in METRICS) + " |")
    steps = ", ".join(f"{label} {_join(v)}" for label, v in agg["steps"].items() if any(x is not None for x in v))
    minutes = ", ".join(f"seed {s}: {'-' if m is None else f'{m:.1f}'}" for s, m in zip(agg["seeds"], agg["minutes"]))
    lines += ["", f"Environment steps per run: {steps or '-'}", f"Wall-clock minutes per seed: {minutes}"]
    return "\n".join(lines) + "\n"


def _join(values):
    distinct = sorted({v for v in values if v is not None})
    return "/".join(str(v) for v in distinct)


def write_atomic(path: str, text: str) -> None:
    from robostrich_suite.files import write_text  # the project's one atomic writer
    write_text(path, text)


def run_seed(seed: int, seed_dir: str, passthrough) -> float:
    """Train one seed (resuming its checkpoints if any); returns wall-clock minutes."""
    from agents.robostrich import training
    has_checkpoint = any(os.path.exists(os.path.join(seed_dir, label, "checkpoint.pkl"))
                         for label in ("curriculum", "baseline"))
    argv = list(passthrough) + ["--seed", str(seed), "--out", seed_dir]
    if has_checkpoint and "--resume" not in argv:
        argv.append("--resume")
    start = time.time()
    training.main(argv)  # may return the summary dict; only the files count here
    minutes = (time.time() - start) / 60.0
    write_atomic(os.path.join(seed_dir, TIMING_FILE),
                 json.dumps({"minutes": minutes, "resumed": has_checkpoint, "argv": argv}, indent=1))
    return minutes


def seed_minutes(seed_dir: str, summary: dict):
    """Minutes this tool measured; else the training's own timings of its last start (None if neither)."""
    path = os.path.join(seed_dir, TIMING_FILE)
    if os.path.exists(path):
        with open(path) as f:
            return json.load(f)["minutes"]
    timings = summary.get("timings") or {}
    return sum(t["seconds"] for t in timings.values()) / 60.0 if timings else None


def main(argv=None) -> int:
    args, passthrough = build_parser().parse_known_args(argv)
    for flag in ("--seed", "--out"):
        if any(a == flag or a.startswith(flag + "=") for a in passthrough):
            print(f"error: {flag} is set per seed by this tool; use --seeds / --out", file=sys.stderr)
            return 2
    os.makedirs(args.out, exist_ok=True)
    summaries, minutes = [], []
    for i, seed in enumerate(args.seeds):
        seed_dir = os.path.join(args.out, f"seed_{seed}")
        summary_path = os.path.join(seed_dir, "summary.json")
        if os.path.exists(summary_path):
            print(f"seed {seed} ({i + 1}/{len(args.seeds)}): {summary_path} exists, not re-run", flush=True)
        else:
            print(f"seed {seed} ({i + 1}/{len(args.seeds)}): training into {seed_dir}", flush=True)
            try:
                run_seed(seed, seed_dir, passthrough)
            except ValueError as e:
                print(f"error: seed {seed}: {e}", file=sys.stderr)
                return 1
            except SystemExit as e:  # the training's argument parser rejected something (it said what)
                if e.code:
                    return e.code if isinstance(e.code, int) else 2
                raise
            if not os.path.exists(summary_path):
                print(f"error: seed {seed}: training wrote no {summary_path}", file=sys.stderr)
                return 1
        with open(summary_path) as f:
            summaries.append(json.load(f))
        minutes.append(seed_minutes(seed_dir, summaries[-1]))
    agg = aggregate(summaries, args.seeds, minutes)
    agg["training_arguments"] = passthrough
    table = format_table(agg)
    write_atomic(os.path.join(args.out, "seeds.json"), json.dumps(agg, indent=1))
    write_atomic(os.path.join(args.out, "seeds.md"), table)
    print(table)
    print(f"wrote {os.path.join(args.out, 'seeds.md')} and seeds.json")
    return 0


if __name__ == "__main__":
    sys.exit(main())
