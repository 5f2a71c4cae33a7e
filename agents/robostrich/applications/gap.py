"""Console command `robostrich-gap`: reaching through a narrow gap (Sec. 5.2.2, Fig. 12) for a trained
checkpoint beside zero tendon input and the lookup. The files it writes and the flags it shares with
`robostrich-stabilize`: applications/reports.py; the scene, episodes and scores:
applications/narrow_gap.py."""
import os

import numpy as np

from agents.robostrich.applications import figures as application_figures
from agents.robostrich.applications import narrow_gap
from agents.robostrich.applications import reports
from agents.robostrich.applications import rollouts as applications
from robostrich_suite import cli as cli_lib
from robostrich_suite.tasks import quadruped_tasks
from robostrich_suite.tasks.conventions import CONTROL_TIMESTEP


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


def main(argv=None) -> dict:
    parser = reports.parser("Reaching through a narrow gap (Sec. 5.2.2, Fig. 12): per sub-target reached, time to reach, "
                     "largest arm-wall contact force; success rate of reaching target 6 without the head touching.",
                     os.path.join("out", "gap"))
    parser.add_argument("--switch", choices=quadruped_tasks.NarrowGap.SWITCHES, default="time",
                        help="when the next sub-target becomes active: 'time' (the task's default, every "
                             "--steps-per-target control steps) or 'reached' (once the head is within 5 cm)")
    parser.add_argument("--steps-per-target", type=cli_lib.whole_number(1, 100_000), default=None,
                        help=f"control steps per sub-target (default {quadruped_tasks.NARROW_GAP_STEPS_PER_TARGET})")
    args = parser.parse_args(argv)
    gait, policies = reports.setup(args)
    task_kwargs = {k: v for k, v in (("time_limit", args.time_limit), ("steps_per_target", args.steps_per_target),
                                     ("switch", args.switch)) if v is not None}
    with reports.progress_bar(args, policies, "narrow_gap") as bar:
        results = narrow_gap.evaluate(policies, args.seeds, gait, None if args.no_rerun else args.out, bar, **task_kwargs)
    env = applications.make_environment(policies[-1].domain, narrow_gap.TASK, 0, 1, gait, **task_kwargs)
    targets, tolerance = env.task.world_targets, env.task.position_tolerance
    rule = (f"every {env.task.steps_per_target} control steps ({env.task.steps_per_target * CONTROL_TIMESTEP:.2f} s), the same "
            "schedule for every policy" if args.switch == "time" else
            f"once the head is within {tolerance * 100:.0f} cm of the current sub-target")
    meta = {**reports.meta(args, narrow_gap.TASK, policies), "switch": args.switch, "switch_rule": rule,
            "position_tolerance": tolerance,
            "steps_per_target": env.task.steps_per_target, "sub_targets": np.asarray(targets).tolist(),
            "scene": narrow_gap.scene()}
    results, series = reports.split_series(results)
    meta["episode_s"] = float(next(iter(series.values()))["time"][-1])
    table = gap_table(results, meta)

    def plot(arrays, path):
        application_figures.gap_figure(arrays, narrow_gap.scene(), targets, tolerance, path)
    return reports.report(args, "gap", meta, results, series, table, policies, plot)


def cli(argv=None) -> int:
    """Console script `robostrich-gap` (exit 0, or 2 with one line)."""
    return cli_lib.run(main, "robostrich-gap", argv)
