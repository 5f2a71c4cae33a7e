"""The main job over several seeds: robostrich-sweep with one group (agents/robostrich/sweep/command.py).

    python tools/benchmark_seeds.py [--seeds 0,1,2] [--out runs/seeds] [robostrich-train arguments ...]
    python tools/benchmark_seeds.py --seeds 0,1,2 --steps 60000 --her-ratio 0.5

is `robostrich-sweep` with the same arguments (and --out runs/seeds unless given): seed K trains
into OUT/runs/default/seed_K as Ray tasks, a finished seed is not re-run, a killed one resumes,
and OUT/sweep.md and OUT/sweep.json hold mean [min, max] over the seeds. The records in
docs/results/ name this command. The aggregation lives in agents/robostrich/sweep/table.py.
"""
import sys

from agents.robostrich.sweep.table import aggregate, format_table  # noqa: F401  (tests and older callers)
from agents.robostrich.sweep import command as sweep

DEFAULT_OUT = "runs/seeds"


def main(argv=None) -> int:
    """robostrich-sweep's exit status: 0, 1 when a seed failed, 2 on a bad input, 130 on Ctrl-C."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if not any(a == "--out" or a.startswith("--out=") for a in argv):
        argv += ["--out", DEFAULT_OUT]
    return sweep.cli(argv)


if __name__ == "__main__":
    sys.exit(main())
