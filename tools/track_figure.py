"""The README's figure: a shipped policy on `track` (the paper's Fig. 7) beside the lookup.

    python tools/track_figure.py [--policy robostrich] [--out docs/track_ventral_slips.png]

Each run's legend entry says how many of the three targets it reached (the goal: all) and, for
the policy, the seed and the control steps it was trained with, from the policy file. Plain SAC
ships no policy: its numbers over seeds are the results table's (docs/results.md).
"""
import argparse
import sys

from agents.replay import ObservationFlattener
from agents.robostrich import figures
from agents.robostrich.evaluate import episodes
from agents.robostrich.domains import TRACK_TASK, as_domain, domain_of
from agents.robostrich.lookup import LookupPolicy
from robostrich_suite import cli as cli_lib
from robostrich_suite import policies


def main(argv=None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--policy", default="robostrich",
                        help="a shipped policy or a .npz policy file (default: %(default)s)")
    parser.add_argument("--out", default="docs/track_ventral_slips.png", help="the PNG (default: %(default)s)")
    args = parser.parse_args(argv)
    policy = policies.load_policy(args.policy)
    domain = domain_of(policy.info)
    reports = {"curriculum": episodes.evaluate_track(policy, policy.flatten, domain, TRACK_TASK)}
    flattener = ObservationFlattener(as_domain(domain).make_environment(TRACK_TASK, 0).observation_spec())
    reports["lookup"] = episodes.evaluate_track(LookupPolicy(flattener, domain.lookup_table()), flattener,
                                                  domain, TRACK_TASK)
    steps = policy.info.get("env_steps")
    notes = {"curriculum": f"seed {policy.info.get('seed')}, "
                           + (f"{steps // 1000}k control steps" if steps else "its training's steps unknown")}
    figures.plot_track(reports, args.out, notes)
    print(f"wrote {args.out}")
    return reports


if __name__ == "__main__":
    sys.exit(cli_lib.run(main, "track_figure.py"))
