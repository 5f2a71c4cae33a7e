"""Target generation: sample the actuated workspace and keep the level-head poses.

The tasks' targets are the level subset of the *actuated* workspace
(:func:`workspace.actuated_samples`), each with the tendon inputs that hold it;
:mod:`robostrich_suite.targets` loads the files written here.  Regenerate the shipped
file after changing the default arm with::

    robostrich-targets --samples 4000 --out robostrich_suite/data/level_head_poses.npz
"""
from __future__ import annotations

import argparse
import pathlib

import numpy as np

from robostrich_suite import cli as cli_lib
from robostrich_suite import targets
from robostrich_suite.model import fingerprint as fingerprint_lib
from robostrich_suite.studies import workspace

SEEK_LEVEL_TIME = 2.5  # s of dorsal-input tuning per draw before it is held


def generate(num_samples: int, seed: int = 0, path: pathlib.Path = targets.DATA_PATH,
             workers: int = 2, append: bool = False,
             seek_level_time: float = SEEK_LEVEL_TIME, spec=None, layout=None) -> int:
    """Sample the actuated workspace and save its level subset; returns its size.

    ``seek_level_time`` > 0 tunes each draw's dorsal input towards a level head
    before holding it (:func:`workspace.seek_level`): many more
    level poses per CPU second.  With ``append`` the new poses are added to those
    already in ``path`` (which must come from the same arm); use another seed.
    ``spec`` and ``layout`` (an ``ArmSpec`` and ``TendonLayout``) make targets for
    another arm; write them to another ``path`` and pass
    ``training_targets(path)`` as the tasks' ``target_pool``.
    """
    samples = workspace.actuated_samples_parallel(num_samples, seed=seed, workers=workers,
                                                  progress=True,
                                                  seek_level_time=seek_level_time,
                                                  spec=spec, layout=layout)
    level = samples.level()
    fingerprint = fingerprint_lib.model_fingerprint(spec, layout)
    new = dict(head_position=samples.head_position[level],
               head_attitude=samples.head_attitude[level], control=samples.control[level])
    if append and path.exists():
        with np.load(path) as old:
            if str(old["fingerprint"]) != fingerprint:
                raise ValueError(f"{path} was made with another arm; regenerate without --append")
            new = {key: np.concatenate([old[key], value]) for key, value in new.items()}
    return save_level_poses(path, new, fingerprint)


def save_level_poses(path: pathlib.Path, poses: dict, fingerprint: str) -> int:
    """Write ``poses`` (``head_position``, ``head_attitude``, ``control``) as a target file
    of the arm with ``fingerprint``; returns how many.  Readers of ``path`` see the new file."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, fingerprint=np.array(fingerprint),
                        **{key: np.asarray(poses[key]) for key in ("head_position", "head_attitude",
                                                                  "control")})
    targets.clear_cache()
    return len(poses["head_position"])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(prog="robostrich-targets", description=__doc__.split("\n")[0])
    parser.add_argument("--samples", type=int, default=4000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=pathlib.Path, required=True,
                        help="target file to write (the shipped one: robostrich_suite/data/level_head_poses.npz)")
    parser.add_argument("--seek-level-time", type=float, default=SEEK_LEVEL_TIME,
                        help="seconds of dorsal tuning towards a level head per draw (0: off)")
    parser.add_argument("--append", action="store_true",
                        help="add to the poses already in --out (use a new --seed)")
    args = parser.parse_args(argv)
    count = generate(args.samples, args.seed, args.out, append=args.append,
                     seek_level_time=args.seek_level_time)
    print(f"wrote {count} level-head poses to {args.out}")


def cli(argv=None) -> int:
    """Console script `robostrich-targets`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-targets", argv)


if __name__ == "__main__":
    import sys
    sys.exit(cli())
