"""What `robostrich-stabilize` (applications/stabilize.py) and `robostrich-gap` (applications/gap.py),
the application evaluations of Sec. 5.2 for a trained checkpoint beside zero tendon input and the
lookup, share: their common flags, inputs, progress bar and output files.

Each writes into `--out` a JSON report (`*_report.json`: per policy the summary over seeds
and every seed's numbers), the seed-0 series (`*_series.json`), a short text table
(`*_summary.txt`, also printed), a figure (`*.png`, Fig. 9 / Fig. 12) and a Rerun recording
of each policy's seed-0 rollout (`*_LABEL.rrd`), which `--web` then serves in the browser until
Ctrl-C (robostrich_suite/web_viewer.py).  Without a checkpoint only the two
references run (what a trained policy has to beat).  Errors exit 2 with one line
(robostrich_suite.cli).
"""
import argparse
import os

import numpy as np

from agents.robostrich.applications import rollouts as applications
from robostrich_suite import outputs, progress, web_viewer
from robostrich_suite import cli as cli_lib
from robostrich_suite import atomic_files


def parser(description: str, out: str) -> argparse.ArgumentParser:
    parser = cli_lib.Parser(description=description)
    parser.add_argument("checkpoint", nargs="?", default=None,
                        help="checkpoint.ckpt of robostrich-train on robostrich_a1 (label 'trained'); "
                             "without it only zero input and the lookup run")
    parser.add_argument("--reference", default=None, metavar="CHECKPOINT",
                        help="a second checkpoint to compare (label 'reference'), e.g. lessons 1-3 without lesson 4")
    parser.add_argument("--layout", default=None, help="built-in tendon layout (default: the checkpoints', else the tasks' own)")
    parser.add_argument("--seeds", type=cli_lib.whole_number(1, 1_000), default=5,
                        help="gait phases: seed k of N starts the gait k/(2N) of its period later (default 5)")
    parser.add_argument("--gait", default=None, metavar="CSV",
                        help="gait file of recorded motor data (format: robostrich_suite/tasks/gait.py); "
                             "default: the shipped robostrich_suite/data/a1_trot.csv")
    parser.add_argument("--time-limit", type=cli_lib.seconds(), default=None, help="episode length (s), for short runs")
    parser.add_argument("--out", default=out, help=f"output directory (default {out})")
    parser.add_argument("--no-rerun", action="store_true", help="no .rrd recordings")
    parser.add_argument("--no-figures", action="store_true", help="no PNG figure")
    parser.add_argument("--no-progress", action="store_true", help="no progress bar")
    web_viewer.add_flags(parser)
    return parser


def setup(args):
    """Gait, policies and output directory, every input checked before any rollout."""
    outputs.check_directory(args.out)
    web_viewer.check(args)
    gait = applications.load_gait(args.gait)
    policies = applications.policies(args.checkpoint, args.reference, args.layout)
    os.makedirs(args.out, exist_ok=True)
    return gait, policies


def progress_bar(args, policies, task: str):
    """The bar over every rollout (robostrich_suite/progress.py: cleared if the command stops early)."""
    return progress.bar(not args.no_progress, total=len(policies) * args.seeds, desc=task, unit="rollout",
                        dynamic_ncols=True)


def meta(args, task: str, policies) -> dict:
    domain = policies[-1].domain
    return {"task": task, "domain": domain.name, "layout": domain.layout, "seeds": args.seeds,
            "seed_meaning": "seed k of N starts the gait k/(2N) of its period later (a trot's halves are mirror images)",
            "gait": os.path.abspath(args.gait) if args.gait else "robostrich_suite/data/a1_trot.csv (shipped)",
            "checkpoint": args.checkpoint, "reference": args.reference,
            "policies": [p.label for p in policies]}


def _write(out: str, name: str, report: dict, series: dict, table: str) -> list:
    paths = [os.path.join(out, f"{name}_report.json"), os.path.join(out, f"{name}_series.json"),
             os.path.join(out, f"{name}_summary.txt")]
    atomic_files.write_json(paths[0], report)
    atomic_files.write_json(paths[1], series)
    atomic_files.write_text(paths[2], table)
    return paths


def report(args, name: str, meta: dict, results: dict, series: dict, table: str, policies: list,
            plot) -> dict:
    """Write NAME's report, series and table into ``args.out``, the figure (``plot(series as
    arrays, path)``) unless --no-figures, print the table and every file written (the
    evaluation already wrote each policy's NAME_LABEL.rrd unless --no-rerun), then with --web
    serve those recordings until Ctrl-C."""
    written = _write(args.out, name, {**meta, "policies": results}, series, table)
    if not args.no_figures:
        written.append(os.path.join(args.out, f"{name}.png"))
        plot({k: {"series": {n: np.asarray(v) for n, v in s.items()}} for k, s in series.items()}, written[-1])
    recordings = [] if args.no_rerun else [os.path.join(args.out, f"{name}_{p.label}.rrd") for p in policies]
    print(table + "wrote " + ", ".join(written + recordings), flush=True)
    if args.web:
        web_viewer.serve(recordings, args.web_port)
    return {"meta": meta, "policies": results}


def split_series(results: dict) -> tuple:
    """(results without the series, label -> seed-0 series as lists)."""
    series = {label: {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in r["series"].items()}
              for label, r in results.items()}
    return {label: {k: v for k, v in r.items() if k != "series"} for label, r in results.items()}, series
