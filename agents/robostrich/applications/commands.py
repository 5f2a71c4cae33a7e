"""Console commands `robostrich-stabilize` and `robostrich-gap`: the application evaluations of
Sec. 5.2 for a trained checkpoint beside zero tendon input and the lookup.

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

from agents.robostrich.applications import figures as application_figures
from agents.robostrich.applications import rollouts as applications
from agents.robostrich.applications import narrow_gap as gap
from agents.robostrich.applications import stabilization
from agents.robostrich.applications.stabilization import GOALS
from robostrich_suite import outputs, progress, web_viewer
from robostrich_suite import cli as cli_lib
from robostrich_suite import atomic_files
from robostrich_suite.tasks import quadruped_tasks
from robostrich_suite.tasks.conventions import CONTROL_TIMESTEP


def _parser(description: str, out: str) -> argparse.ArgumentParser:
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


def _setup(args):
    """Gait, policies and output directory, every input checked before any rollout."""
    outputs.check_directory(args.out)
    web_viewer.check(args)
    gait = applications.load_gait(args.gait)
    policies = applications.policies(args.checkpoint, args.reference, args.layout)
    os.makedirs(args.out, exist_ok=True)
    return gait, policies


def _progress(args, policies, task: str):
    """The bar over every rollout (robostrich_suite/progress.py: cleared if the command stops early)."""
    return progress.bar(not args.no_progress, total=len(policies) * args.seeds, desc=task, unit="rollout",
                        dynamic_ncols=True)


def _meta(args, task: str, policies) -> dict:
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


def _report(args, name: str, meta: dict, results: dict, series: dict, table: str, policies: list,
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


def _split_series(results: dict) -> tuple:
    """(results without the series, label -> seed-0 series as lists)."""
    series = {label: {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in r["series"].items()}
              for label, r in results.items()}
    return {label: {k: v for k, v in r.items() if k != "series"} for label, r in results.items()}, series


# --- head_stabilize ---------------------------------------------------------------------------
def stabilization_table(results: dict, meta: dict) -> str:
    lines = [f"head_stabilize on {meta['domain']}{' (layout ' + meta['layout'] + ')' if meta['layout'] else ''}, "
             f"{meta['seeds']} gait phases, scored from {meta['settled_from_s']} s; mean [worst] over the phases",
             f"{'policy':<10} {'height RMS':>14} {'height max':>14} {'head/trunk vz':>15} {'P_d mean err':>15} "
             f"{'P_d RMS':>14} {'level 5 deg':>14} {'goals met':>9}"]
    for label, r in results.items():
        s, goals = r["summary"], r["goals"]

        def cell(key, scale=1.0, unit="", worst="max", digits=1):
            value = s[key]
            return f"{value['mean'] * scale:.{digits}f} [{value[worst] * scale:.{digits}f}]{unit}"
        lines.append(f"{label:<10} {cell('height_rms_error', 100, ' cm'):>14} {cell('height_max_error', 100, ' cm'):>14} "
                     f"{cell('head_vz_rms_ratio', digits=2):>15} {cell('distance_mean_error', 100, ' cm'):>15} "
                     f"{cell('distance_rms_error', 100, ' cm'):>14} "
                     f"{cell('attitude_within_fraction', 100, ' %', worst='min', digits=0):>14} "
                     f"{sum(g['met'] for g in goals.values())}/{len(goals)}")
        if s["fell"]["max"] > 0:
            lines.append(f"{'':<10} the quadruped fell or the physics diverged in some phases")
    lines.append("goals (every phase): " + ", ".join(
        f"{name} {'<=' if kind == 'max' else '>='} {goal}" for name, (goal, kind) in GOALS.items()))
    return "\n".join(lines) + "\n"


def stabilize_main(argv=None) -> dict:
    parser = _parser("Head stabilisation while walking (Sec. 5.2.1, Fig. 9): head height, vertical velocity, "
                     "distance P_d (the head's desired distance ahead of the trunk centre) and attitude of each "
                     "policy over 12 s of walking with two trunk-height changes.",
                     os.path.join("out", "stabilize"))
    parser.add_argument("--settle", type=cli_lib.seconds(allow_zero=True), default=stabilization.SETTLE,
                        help=f"seconds at the start left out of the metrics (default {stabilization.SETTLE})")
    parser.add_argument("--distance", type=cli_lib.number(-2, 2, " m"), default=None,
                        help="P_d, the head's desired distance ahead of the trunk centre (m; default the task's)")
    parser.add_argument("--height", type=cli_lib.number(-2, 2, " m"), default=None, help="head height above ground (m; default the task's)")
    args = parser.parse_args(argv)
    if args.time_limit is not None and args.time_limit <= args.settle:
        raise ValueError(f"--time-limit {args.time_limit} s leaves nothing to score after --settle {args.settle} s")
    gait, policies = _setup(args)
    task_kwargs = {k: v for k, v in (("time_limit", args.time_limit), ("distance", args.distance),
                                     ("height", args.height)) if v is not None}
    with _progress(args, policies, "head_stabilize") as bar:
        results = stabilization.evaluate(policies, args.seeds, gait, args.settle,
                                         None if args.no_rerun else args.out, bar, **task_kwargs)
    meta = {**_meta(args, stabilization.TASK, policies), "settled_from_s": args.settle,
            "goals": {k: {"goal": g, "kind": kind} for k, (g, kind) in stabilization.GOALS.items()}}
    results, series = _split_series(results)
    table = stabilization_table(results, meta)

    def plot(arrays, path):
        application_figures.stabilization_figure(arrays, path, args.settle)
    return _report(args, "stabilize", meta, results, series, table, policies, plot)


def stabilize_cli(argv=None) -> int:
    """Console script `robostrich-stabilize` (exit 0, or 2 with one line)."""
    return cli_lib.run(stabilize_main, "robostrich-stabilize", argv)


# --- narrow_gap ---------------------------------------------------------------------------
def gap_table(results: dict, meta: dict) -> str:
    lines = [f"narrow_gap on {meta['domain']}{' (layout ' + meta['layout'] + ')' if meta['layout'] else ''}, "
             f"{meta['seeds']} gait phases, sub-targets switch by {meta['switch']}; success = target 6 within "
             f"{meta['position_tolerance'] * 100:.0f} cm and the head never touching the obstacle",
             f"{'policy':<10} {'success':>8} {'6 reached':>9} {'head hit':>8} {'max force':>10}  "
             "per sub-target: reached rate / median time to reach / largest arm contact force"]
    for label, r in results.items():
        s = r["summary"]
        cells = "  ".join(f"{t['target']}: {t['reached_rate'] * 100:.0f}% / "
                          f"{'-' if t['time_to_reach_median_s'] is None else format(t['time_to_reach_median_s'], '.2f') + ' s'} / "
                          f"{t['max_arm_contact_force']:.1f} N" for t in s["targets"])
        lines.append(f"{label:<10} {s['success_rate'] * 100:>7.0f}% {s['final_reached_rate'] * 100:>8.0f}% "
                     f"{s['head_touched_rate'] * 100:>7.0f}% {s['max_arm_contact_force']:>8.1f} N  {cells}")
    return "\n".join(lines) + "\n"


def gap_main(argv=None) -> dict:
    parser = _parser("Reaching through a narrow gap (Sec. 5.2.2, Fig. 12): per sub-target reached, time to reach, "
                     "largest arm-wall contact force; success rate of reaching target 6 without the head touching.",
                     os.path.join("out", "gap"))
    parser.add_argument("--switch", choices=quadruped_tasks.NarrowGap.SWITCHES, default="time",
                        help="when the next sub-target becomes active: 'time' (the task's default, every "
                             "--steps-per-target control steps) or 'reached' (once the head is within 5 cm)")
    parser.add_argument("--steps-per-target", type=cli_lib.whole_number(1, 100_000), default=None,
                        help=f"control steps per sub-target (default {quadruped_tasks.NARROW_GAP_STEPS_PER_TARGET})")
    args = parser.parse_args(argv)
    gait, policies = _setup(args)
    task_kwargs = {k: v for k, v in (("time_limit", args.time_limit), ("steps_per_target", args.steps_per_target),
                                     ("switch", args.switch)) if v is not None}
    with _progress(args, policies, "narrow_gap") as bar:
        results = gap.evaluate(policies, args.seeds, gait, None if args.no_rerun else args.out, bar, **task_kwargs)
    env = applications.make_environment(policies[-1].domain, gap.TASK, 0, 1, gait, **task_kwargs)
    targets, tolerance = env.task.world_targets, env.task.position_tolerance
    rule = (f"every {env.task.steps_per_target} control steps ({env.task.steps_per_target * CONTROL_TIMESTEP:.2f} s), the same "
            "schedule for every policy" if args.switch == "time" else
            f"once the head is within {tolerance * 100:.0f} cm of the current sub-target")
    meta = {**_meta(args, gap.TASK, policies), "switch": args.switch, "switch_rule": rule,
            "position_tolerance": tolerance,
            "steps_per_target": env.task.steps_per_target, "sub_targets": np.asarray(targets).tolist(),
            "scene": gap.scene()}
    results, series = _split_series(results)
    meta["episode_s"] = float(next(iter(series.values()))["time"][-1])
    table = gap_table(results, meta)

    def plot(arrays, path):
        application_figures.gap_figure(arrays, gap.scene(), targets, tolerance, path)
    return _report(args, "gap", meta, results, series, table, policies, plot)


def gap_cli(argv=None) -> int:
    """Console script `robostrich-gap` (exit 0, or 2 with one line)."""
    return cli_lib.run(gap_main, "robostrich-gap", argv)
