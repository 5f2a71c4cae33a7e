"""Gait generation: sample the open-loop trot (:class:`gait.TrotGait`) into a gait file.

The walking tasks replay the shipped file ``robostrich_suite/data/a1_trot.csv``
(:class:`gait.GaitReplay`); regenerate it with::

    robostrich-gait --out robostrich_suite/data/a1_trot.csv
"""
from __future__ import annotations

import pathlib

import numpy as np

from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs
from robostrich_suite.model import legs
from robostrich_suite.tasks import gait as gait_lib


def sample_trot(gait: gait_lib.TrotGait | None = None, cycles: int = 1, rate: float = 100.0):
    """Sample ``cycles`` periods of a trot at ``rate`` Hz, last sample = first (closed loop)."""
    gait = gait or gait_lib.TrotGait()
    count = int(round(cycles * gait.period * rate))
    times = np.linspace(0.0, cycles * gait.period, count + 1)
    return times, gait.joint_targets(times)


def main(argv=None) -> None:
    parser = cli_lib.Parser(prog="robostrich-gait", description="Write a trot as a gait file (CSV).")
    parser.add_argument("--out", type=pathlib.Path, required=True,
                        help="gait file to write (the shipped one: robostrich_suite/data/a1_trot.csv)")
    parser.add_argument("--frequency", type=cli_lib.number(0.1, 20, " Hz"), default=gait_lib.TrotGait.frequency,
                        help="gait cycles per second, 0.1-20 (default: %(default)s)")
    parser.add_argument("--stride", type=cli_lib.number(0, 0.2, " m"), default=gait_lib.TrotGait.stride,
                        help="foot travel relative to the hip during stance, 0-0.2 m (default: %(default)s)")
    parser.add_argument("--lift", type=cli_lib.number(0, 0.1, " m"), default=gait_lib.TrotGait.lift,
                        help="swing foot height, 0-0.1 m (default: %(default)s)")
    parser.add_argument("--trunk-height", default=gait_lib.TrotGait.trunk_height,
                        type=cli_lib.number(legs.MIN_TRUNK_HEIGHT, legs.MAX_TRUNK_HEIGHT, " m"),
                        help=f"trunk height the legs hold, {legs.MIN_TRUNK_HEIGHT}-{legs.MAX_TRUNK_HEIGHT} m "
                             "(default: %(default)s)")
    parser.add_argument("--rate", type=cli_lib.number(1, 10_000, " samples/s"), default=100.0,
                        help="samples per second, 1-10000 (default: %(default)s)")
    args = parser.parse_args(argv)
    outputs.check_file(args.out)
    gait = gait_lib.TrotGait(args.frequency, args.stride, args.lift, args.trunk_height)
    times, targets = sample_trot(gait, rate=args.rate)
    gait_lib.write_gait_file(args.out, times, targets, comment=(
        f"A1-like trot from robostrich_suite.tasks.gait.TrotGait: frequency {gait.frequency} Hz, "
        f"stride {gait.stride} m, lift {gait.lift} m, trunk height {gait.trunk_height} m.\n"
        "Columns: time (s), then 12 joint targets (rad). Loops with period time[-1] - time[0]."))
    print(f"wrote {len(times)} samples to {args.out}")


def cli(argv=None) -> int:
    """Console script `robostrich-gait`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-gait", argv)


if __name__ == "__main__":
    import sys
    sys.exit(cli())
