"""Console command `robostrich-targets`: a target file of level-head poses, drawn or re-held
(robostrich_suite/studies/target_generation.py makes them)."""
from __future__ import annotations

import pathlib

from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs
from robostrich_suite.model import layouts
from robostrich_suite.studies import target_generation


def main(argv=None) -> None:
    parser = cli_lib.Parser(prog="robostrich-targets", description=target_generation.__doc__.split("\n")[0])
    parser.add_argument("--samples", type=cli_lib.whole_number(0), default=4000,
                        help="random held inputs (default: %(default)s)")
    parser.add_argument("--blue-samples", type=cli_lib.whole_number(0), default=0,
                        help="kinematic samples whose level heads (the blue region) each get a sought "
                             "pose (default: %(default)s)")
    parser.add_argument("--seed", type=cli_lib.seed, default=0,
                        help="random seed of the held inputs and samples (default: %(default)s)")
    parser.add_argument("--out", type=pathlib.Path, required=True,
                        help="target file to write (the shipped one: robostrich_suite/data/level_head_poses.npz)")
    parser.add_argument("--seek-level-time", type=cli_lib.seconds(allow_zero=True), default=target_generation.SEEK_LEVEL_TIME,
                        help="seconds of dorsal tuning towards a level head per draw (0: off; default: %(default)s)")
    parser.add_argument("--append", action="store_true",
                        help="add to the poses already in --out (use a new --seed)")
    parser.add_argument("--recheck", action="store_true",
                        help="draw nothing: re-hold the stored inputs of --out on today's arm and keep "
                             "the poses still held level, at their new positions")
    parser.add_argument("--layout", default=None, metavar="NAME",
                        help="built-in tendon layout of the arm (default: the tasks' own)")
    parser.add_argument("--workers", type=cli_lib.whole_number(1, cli_lib.MAX_WORKERS), default=2,
                        help="processes drawing poses (default: %(default)s)")
    args = parser.parse_args(argv)
    outputs.check_file(args.out)
    layout = None
    if args.layout is not None:
        layout = layouts.build(args.layout)
    if args.recheck:
        if not args.out.exists():
            raise FileNotFoundError(f"--recheck: no target file at {args.out}")
        kept, stored = target_generation.recheck(args.out, layout=layout, progress=True)
        print(f"kept {kept} of {stored} level-head poses in {args.out}")
        return
    count = target_generation.generate(args.samples, args.seed, args.out, workers=args.workers, append=args.append,
                     seek_level_time=args.seek_level_time, layout=layout, blue_samples=args.blue_samples)
    print(f"wrote {count} level-head poses to {args.out}")


def cli(argv=None) -> int:
    """Console script `robostrich-targets`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-targets", argv)


if __name__ == "__main__":
    import sys
    sys.exit(cli())
