"""How precisely must the tendon inputs be right? Hold each stored input with a constant error.

    python tools/input_sensitivity.py [--errors 0,0.01,0.03,0.1] [--every 4] [--draws 3] [--out runs/sensitivity]

For every `--every`-th training target, the stored input that holds the head there (the
lookup table, agents/robostrich/lookup.py) is held for one `lesson2` episode from the fixed start, with a
constant Gaussian error added to each tendon (standard deviation = a fraction of that tendon's
half-range), `--draws` times per error size.  Success is the task's (0.05 m, 5 deg at the episode's
end).  It tells what an agent that outputs absolute inputs must achieve: why a policy network whose
outputs are off by a percent of the range loses most targets
(docs/log/learning.md#why-the-learner-stays-below-the-lookup-the-arm-asks-for-inputs-right-to-1--2026-11-30).  Writes OUT/
sensitivity.md (Markdown table) and sensitivity.json.
"""
import argparse
import os
import sys

import numpy as np
from agents.robostrich.lookup import lookup_table, nearest
from robostrich_suite import atomic_files
from robostrich_suite import targets
import robostrich_suite


def _fractions(text: str):
    try:
        values = [float(s) for s in text.split(",") if s.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"--errors wants comma-separated fractions, got {text!r}") from None
    if not values or not all(np.isfinite(v) and 0 <= v <= 1 for v in values):
        raise argparse.ArgumentTypeError(f"--errors wants fractions in [0, 1] of the half-range, got {text!r}")
    return values


def build_parser():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    p.add_argument("--errors", type=_fractions, default=[0.0, 0.01, 0.03, 0.1],
                   help="standard deviations of the constant input error, as fractions of each half-range")
    p.add_argument("--every", type=int, default=4, help="use every N-th training target (default 4)")
    p.add_argument("--draws", type=int, default=3, help="random errors per target and size (default 3)")
    p.add_argument("--seed", type=int, default=0, help="seed of the input errors' draws (default: %(default)s)")
    p.add_argument("--out", default="runs/sensitivity", help="writes sensitivity.json and sensitivity.md here")
    return p


def measure(errors, every: int = 4, draws: int = 3, seed: int = 0) -> list:
    """One row per error size: episodes, success rate, median and 90th-percentile errors."""
    from tqdm import tqdm

    if every < 1 or draws < 1:
        raise ValueError(f"--every and --draws must be >= 1, got {every} and {draws}")
    table = lookup_table()
    chosen = targets.training_targets()[::every]
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=seed, target_pool=chosen[:1]))
    spec = env.action_spec()
    half_range = 0.5 * (spec.maximum - spec.minimum)
    rng = np.random.default_rng(seed)
    rows = []
    with tqdm(total=len(errors) * len(chosen) * draws, desc="episodes", unit="ep") as bar:
        for fraction in errors:
            position, attitude = [], []
            for target in chosen:
                stored = table["control"][nearest(table, target)]
                for _ in range(draws):
                    held = np.clip(stored + fraction * half_range * rng.normal(size=stored.shape),
                                   spec.minimum, spec.maximum)
                    env.task.target_pool = target[None]
                    timestep = env.reset()
                    while not timestep.last():
                        timestep = env.step(held)
                    measured = env.task.measure(env.physics)  # lesson2's own reading
                    position.append(measured.position_error)
                    attitude.append(abs(measured.attitude_error))
                    bar.update()
            position, attitude = np.array(position), np.array(attitude)
            tolerance, attitude_tolerance = measured.position_tolerance, measured.attitude_tolerance
            rows.append({"error_fraction": fraction, "episodes": len(position),
                         "success_rate": float(np.mean((position <= tolerance) & (attitude <= attitude_tolerance))),
                         "position_error_median": float(np.median(position)),
                         "position_error_p90": float(np.percentile(position, 90)),
                         "attitude_error_median": float(np.median(attitude)),
                         "attitude_error_p90": float(np.percentile(attitude, 90))})
    return rows


def markdown(rows) -> str:
    lines = ["| input error (std, share of half-range) | episodes | success | median position error | "
             "median attitude error | 90th pct position | 90th pct attitude |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {100 * r['error_fraction']:.0f} % | {r['episodes']} | {100 * r['success_rate']:.0f} % | "
                     f"{r['position_error_median']:.3f} m | {r['attitude_error_median']:.1f} deg | "
                     f"{r['position_error_p90']:.3f} m | {r['attitude_error_p90']:.1f} deg |")
    return "\n".join(lines) + "\n"


def main(argv=None):
    args = build_parser().parse_args(argv)
    rows = measure(args.errors, args.every, args.draws, args.seed)
    os.makedirs(args.out, exist_ok=True)
    atomic_files.write_json(os.path.join(args.out, "sensitivity.json"), rows)
    atomic_files.write_text(os.path.join(args.out, "sensitivity.md"), markdown(rows))
    print(markdown(rows), end="")
    return 0


if __name__ == "__main__":
    from robostrich_suite.cli import run
    sys.exit(run(main, "input_sensitivity", sys.argv[1:]))
