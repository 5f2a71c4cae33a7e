"""`robostrich-play`: a shipped policy at work in a minute, with no training.

Runs a policy file (robostrich_suite.policies; default: the default robot's curriculum
policy) on the held-out targets from the fixed start and on the `track` task, prints
its success, and writes the reports, a Rerun recording of `track` and the track figure.
"""
import os

from agents.robostrich import evaluation, figures
from agents.robostrich.domains import TRACK_TASK, as_domain
from agents.robostrich.recording import open_recorder
from robostrich_suite import cli as cli_lib
from robostrich_suite import policies

LABEL = "policy"


def _line(kind: str, summary: dict) -> str:
    return (f"{kind:8s} {summary['success_rate'] * 100:5.1f} % reached "
            f"({summary['precise_success_rate'] * 100:.1f} % within 1 cm and 2 deg), "
            f"median error {summary['position_error_median'] * 100:.2f} cm, "
            f"{summary['attitude_error_median']:.2f} deg, {summary['episodes']} targets")


def main(argv=None) -> dict:
    parser = cli_lib.Parser(description="Run a trained policy on the held-out targets and the track task: "
                                        "success printed, reports, a .rrd recording and a PNG written.")
    parser.add_argument("--policy", default="robostrich",
                        help=f"a shipped policy ({', '.join(policies.SHIPPED)}) or a .npz policy file "
                             "(written by tools/export_policy.py)")
    parser.add_argument("--out", default="robostrich_play", help="directory for the reports, .rrd and PNG")
    parser.add_argument("--num-targets", type=evaluation.target_count, default=None,
                        help="held-out targets to try (default: all)")
    parser.add_argument("--no-rerun", action="store_true", help="write no .rrd recording")
    args = parser.parse_args(argv)
    policy = policies.load_policy(args.policy)
    domain = as_domain(policy.info.get("domain", "robostrich"), policy.info.get("layout"))
    heldout_task = evaluation.default_heldout_task(domain, TRACK_TASK)
    env = evaluation.make_environment(domain, heldout_task, 0)
    policy.check(env)
    env.close()
    os.makedirs(args.out, exist_ok=True)
    reports = {"heldout": evaluation.evaluate_heldout(policy, policy.flatten, domain, heldout_task, args.num_targets)}
    with open_recorder(None if args.no_rerun else os.path.join(args.out, f"{LABEL}_track.rrd"),
                       f"{LABEL} track") as recorder:
        reports["track"] = evaluation.evaluate_track(policy, policy.flatten, domain, TRACK_TASK, recorder=recorder)
    for kind, report in reports.items():
        report.update(label=LABEL, policy=args.policy)
        evaluation.write_json(os.path.join(args.out, f"{LABEL}_{kind}.json"), report)
    figures.plot_track({LABEL: reports["track"]}, os.path.join(args.out, f"{LABEL}_track.png"))
    print(f"{args.policy} ({domain.describe()}, seed {policy.info.get('seed')}, "
          f"{policy.info.get('env_steps')} control steps of training)")
    for kind, report in reports.items():
        print(_line(kind, report["summary"]))
    print(f"wrote {args.out}/: reports, {LABEL}_track.png" + ("" if args.no_rerun else f", {LABEL}_track.rrd"))
    return reports


def cli(argv=None) -> int:
    """Console script `robostrich-play`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-play", argv)
