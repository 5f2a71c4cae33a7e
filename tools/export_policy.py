"""Write a trained run's policy as a package policy file (robostrich_suite/policies.py).

    python tools/export_policy.py runs/main/curriculum/checkpoint.ckpt \
        --out robostrich_suite/data/policies/robostrich_curriculum.npz \
        --command "robostrich-train --seed 2 --out runs/main"

The file holds the actor's evaluation parameters, the observation layout, the action
bounds, the model fingerprint and how the run was made (--command, its seed and plan).
"""
import os
import sys

from agents.robostrich.evaluate.policy_export import export_policy
from robostrich_suite import cli as cli_lib


def main(argv=None):
    parser = cli_lib.Parser(description=__doc__.splitlines()[0])
    parser.add_argument("checkpoint", help="checkpoint.ckpt written by robostrich-train")
    parser.add_argument("--out", required=True, help="policy file to write (.npz)")
    parser.add_argument("--command", default="", help="the training command that made the run (recorded)")
    args = parser.parse_args(argv)
    if not args.out.endswith(".npz"):
        raise ValueError(f"--out {args.out!r}: a policy file ends in .npz")
    policy = export_policy(args.checkpoint, args.out, args.command)
    size = os.path.getsize(args.out)
    print(f"wrote {args.out} ({size / 1024:.0f} KiB): {policy.info['domain']}, layout {policy.info['layout']}, "
          f"seed {policy.info['seed']}, {policy.info['env_steps']} control steps, model {policy.fingerprint}")


if __name__ == "__main__":
    sys.exit(cli_lib.run(main, "export_policy.py"))
