"""`robostrich-play`: a shipped policy at work in a minute, with no training.

Runs a policy file (robostrich_suite.policies; default: the default robot's curriculum
policy) on the held-out targets from the fixed start, then on the frame's `track` task or, for a
policy of the arm on the quadruped, on `head_stabilize` (Fig. 9, one gait phase); prints its
success, and writes the reports, a Rerun recording of the second task and its figure, every file
named after the policy (``robostrich_track.rrd``; a policy file's name without ``.npz``), so two
policies played into one folder keep their own files. Each line is printed as its part ends (flushed: a pipe, `| tee`, sees it then). With `--web` it then serves
the recording in the browser until Ctrl-C (robostrich_suite/web_viewer.py).
"""
import os
import pathlib
import re

from agents.robostrich import figures
from agents.robostrich.applications import figures as application_figures
from agents.robostrich.applications import rollouts as applications
from agents.robostrich.evaluate import episodes, evaluation
from agents.robostrich.applications import stabilization
from agents.robostrich.domains import domain_of, TRACK_TASK
from agents.robostrich.recording import open_recorder
from robostrich_suite import atomic_files, outputs, policies, web_viewer
from robostrich_suite import cli as cli_lib

def policy_label(policy: str) -> str:
    """The name that starts a played policy's files: a shipped policy's own, a file's stem."""
    name = policy if policy in policies.SHIPPED else pathlib.Path(policy).stem
    return re.sub(r"[^A-Za-z0-9_.-]", "_", name)[:100] or "policy"


def _stabilize_line(metrics: dict) -> str:
    return (f"head_stabilize: height {metrics['height_rms_error'] * 100:.1f} cm RMS, head / trunk vertical "
            f"velocity {metrics['head_vz_rms_ratio']:.2f}, P_d {metrics['distance_mean_error'] * 100:.1f} cm off, "
            f"level {metrics['attitude_within_fraction'] * 100:.0f} % of the time")


def play_track(policy, domain, args, label: str) -> tuple:
    """`track` (Fig. 7): (its report, the files written in args.out: figure, recording)."""
    written = [f"{label}_track.png"] + ([] if args.no_rerun else [f"{label}_track.rrd"])
    with open_recorder(None if args.no_rerun else os.path.join(args.out, written[-1]), f"{label} track") as recorder:
        report = episodes.evaluate_track(policy, policy.flatten, domain, TRACK_TASK, recorder=recorder)
    figures.plot_track({label: report}, os.path.join(args.out, written[0]))
    print(f"track    {evaluation.outcome_text('track', report['summary'])}", flush=True)
    return report, written


def play_stabilize(policy, domain, args, label: str) -> tuple:
    """`head_stabilize` (Fig. 9) over one gait phase: (its metrics, the files written in args.out)."""
    compared = applications.Policy(label, domain, lambda env, flattener: policy)
    results = stabilization.evaluate([compared], 1, applications.load_gait(),
                                     record_dir=None if args.no_rerun else args.out,
                                     record_name="{label}_head_stabilize.rrd")
    written = [f"{label}_head_stabilize.png"] + ([] if args.no_rerun else [f"{label}_head_stabilize.rrd"])
    application_figures.stabilization_figure(results, os.path.join(args.out, written[0]), stabilization.SETTLE)
    metrics = {k: v for k, v in results[label]["seeds"][0].items() if k != "seed"}
    print(_stabilize_line(metrics), flush=True)
    return {"summary": metrics, "goals": results[label]["goals"]}, written


def main(argv=None) -> dict:
    parser = cli_lib.Parser(description="Run a trained policy on the held-out targets and on track (the arm on "
                                        "its frame) or head_stabilize (on the quadruped): success printed, "
                                        "reports, a .rrd recording and a PNG written.")
    parser.add_argument("--policy", default="robostrich",
                        help=f"a shipped policy ({', '.join(policies.SHIPPED)}) or a .npz policy file "
                             "(written by tools/export_policy.py; default: %(default)s)")
    parser.add_argument("--out", default="out/play", help="directory for the reports, .rrd and PNG, each named "
                                                           "after the policy (default: %(default)s)")
    parser.add_argument("--num-targets", type=evaluation.target_count, default=None,
                        help="held-out targets to try (default: all)")
    parser.add_argument("--no-rerun", action="store_true", help="write no .rrd recording")
    web_viewer.add_flags(parser)
    args = parser.parse_args(argv)
    outputs.check_directory(args.out)
    web_viewer.check(args)
    policy = policies.load_policy(args.policy)
    domain = domain_of(policy.info)
    heldout_task = evaluation.default_heldout_task(domain, TRACK_TASK)
    env = domain.make_environment(heldout_task, 0)
    policy.check(env)
    env.close()
    os.makedirs(args.out, exist_ok=True)
    print(f"{args.policy} ({domain.describe()}, seed {policy.info.get('seed')}, "
          f"{policy.info.get('env_steps')} control steps of training)", flush=True)
    reports = {"heldout": episodes.evaluate_heldout(policy, policy.flatten, domain, heldout_task,
                                                    domain.heldout_targets(args.num_targets), args.num_targets)}
    print(f"heldout  {evaluation.outcome_text('heldout', reports['heldout']['summary'])}", flush=True)
    second, play = ("head_stabilize", play_stabilize) if domain.on_quadruped else ("track", play_track)
    label = policy_label(args.policy)
    reports[second], written = play(policy, domain, args, label)
    for kind, report in reports.items():
        report.update(label=label, policy=args.policy)
        atomic_files.write_json(os.path.join(args.out, f"{label}_{kind}.json"), report)
    print(f"wrote {args.out}/: reports, {', '.join(written)}", flush=True)
    if args.web:
        web_viewer.serve([os.path.join(args.out, name) for name in written if name.endswith(".rrd")], args.web_port)
    return reports


def cli(argv=None) -> int:
    """Console script `robostrich-play`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-play", argv)
