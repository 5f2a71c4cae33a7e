"""Console command `robostrich-stabilize`: head stabilisation while walking (Sec. 5.2.1, Fig. 9) for
a trained checkpoint beside zero tendon input and the lookup. The files it writes and the flags it
shares with `robostrich-gap`: applications/reports.py; the episodes and their scores:
applications/stabilization.py."""
import os

from agents.robostrich.applications import figures as application_figures
from agents.robostrich.applications import reports, stabilization
from agents.robostrich.applications.stabilization import GOALS
from robostrich_suite import cli as cli_lib


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


def main(argv=None) -> dict:
    parser = reports.parser("Head stabilisation while walking (Sec. 5.2.1, Fig. 9): head height, vertical velocity, "
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
    gait, policies = reports.setup(args)
    task_kwargs = {k: v for k, v in (("time_limit", args.time_limit), ("distance", args.distance),
                                     ("height", args.height)) if v is not None}
    with reports.progress_bar(args, policies, "head_stabilize") as bar:
        results = stabilization.evaluate(policies, args.seeds, gait, args.settle,
                                         None if args.no_rerun else args.out, bar, **task_kwargs)
    meta = {**reports.meta(args, stabilization.TASK, policies), "settled_from_s": args.settle,
            "goals": {k: {"goal": g, "kind": kind} for k, (g, kind) in GOALS.items()}}
    results, series = reports.split_series(results)
    table = stabilization_table(results, meta)

    def plot(arrays, path):
        application_figures.stabilization_figure(arrays, path, args.settle)
    return reports.report(args, "stabilize", meta, results, series, table, policies, plot)


def cli(argv=None) -> int:
    """Console script `robostrich-stabilize` (exit 0, or 2 with one line)."""
    return cli_lib.run(main, "robostrich-stabilize", argv)
