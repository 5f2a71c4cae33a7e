"""Targets for the reaching tasks: head positions the arm really holds level.

The paper draws targets from the blue region of Fig. 6 (head attitude 90 +- 5
deg).  A kinematic sample of that region includes poses a passive chain under
gravity cannot hold, so we ship instead the level subset of the *actuated*
workspace (:func:`robostrich_suite.workspace.actuated_samples`): every target
comes with the tendon inputs that hold the head there, and a test re-simulates
some of them.  Every fifth pose is held out for evaluation and never used in
training.

Regenerate after changing the default arm with::

    python -m robostrich_suite.targets --samples 4000
"""
from __future__ import annotations

import argparse
import functools
import pathlib

import numpy as np

DATA_PATH = pathlib.Path(__file__).parent / "data" / "level_head_poses.npz"
HELDOUT_EVERY = 5
MIN_TARGET_SPACING = 0.01  # m
SEEK_LEVEL_TIME = 2.5  # s of dorsal-input tuning per draw before it is held


@functools.lru_cache(maxsize=None)
def _load(path: str = str(DATA_PATH)) -> dict:
    path = pathlib.Path(path)
    if not path.exists():
        raise FileNotFoundError(
            f"{path} is missing; regenerate it with `python -m robostrich_suite.targets`")
    with np.load(path) as data:
        return {key: data[key] for key in data.files}


def level_head_poses(path: str | pathlib.Path = DATA_PATH) -> dict:
    """All shipped level-head poses (or those of a file :func:`generate` wrote):
    ``head_position`` (n, 2), ``head_attitude`` (n,), ``control`` (n, tendons) and the
    ``fingerprint`` of the arm they were made with."""
    return _load(str(path))


def distinct_indices(positions: np.ndarray, spacing: float = MIN_TARGET_SPACING) -> np.ndarray:
    """Indices of a greedy subset of ``positions`` whose members are >= ``spacing`` apart."""
    kept: list[int] = []
    for i, position in enumerate(positions):
        if not kept or np.min(np.linalg.norm(positions[kept] - position, axis=1)) >= spacing:
            kept.append(i)
    return np.array(kept, dtype=int)


@functools.lru_cache(maxsize=None)
def _distinct_targets(path: str = str(DATA_PATH)) -> np.ndarray:
    positions = _load(path)["head_position"]
    return positions[distinct_indices(positions)]


def _split(heldout: bool, path: str = str(DATA_PATH)) -> np.ndarray:
    positions = _distinct_targets(str(path))
    mask = (np.arange(len(positions)) % HELDOUT_EVERY == 0)
    return positions[mask if heldout else ~mask].copy()


def training_targets(path: str | pathlib.Path = DATA_PATH) -> np.ndarray:
    """(n, 2) target positions (x, z) the training tasks sample from (from the shipped
    poses, or from a file :func:`generate` wrote for another arm)."""
    return _split(False, str(path))


def heldout_targets(path: str | pathlib.Path = DATA_PATH) -> np.ndarray:
    """(n, 2) target positions (x, z) kept out of training, for evaluation."""
    return _split(True, str(path))


def warn_if_other_arm(spec=None, layout=None) -> bool:
    """Warn (and return True) when the shipped targets were made with another arm than
    ``spec``/``layout``: its level-head poses differ, so some targets may be out of reach
    or not holdable with a level head."""
    from robostrich_suite import workspace
    if spec is None and layout is None:
        return False
    shipped = str(level_head_poses()["fingerprint"])
    if workspace.model_fingerprint(spec, layout) == shipped:
        return False
    import warnings
    warnings.warn(
        "the shipped targets were made with the default arm, not this arm spec/tendon layout; "
        "some may be unreachable. Make targets for it with robostrich_suite.targets.generate("
        "..., spec=..., layout=..., path=FILE) and pass target_pool=training_targets(FILE).",
        stacklevel=3)
    return True


def generate(num_samples: int, seed: int = 0, path: pathlib.Path = DATA_PATH,
             workers: int = 2, append: bool = False,
             seek_level_time: float = SEEK_LEVEL_TIME, spec=None, layout=None) -> int:
    """Sample the actuated workspace and save its level subset; returns its size.

    ``seek_level_time`` > 0 tunes each draw's dorsal input towards a level head
    before holding it (:func:`robostrich_suite.workspace.seek_level`): many more
    level poses per CPU second.  With ``append`` the new poses are added to those
    already in ``path`` (which must come from the same arm); use another seed.
    ``spec`` and ``layout`` (an ``ArmSpec`` and ``TendonLayout``) make targets for
    another arm; write them to another ``path`` and pass
    ``training_targets(path)`` as the tasks' ``target_pool``.
    """
    from robostrich_suite import workspace
    samples = workspace.actuated_samples_parallel(num_samples, seed=seed, workers=workers,
                                                  progress=True,
                                                  seek_level_time=seek_level_time,
                                                  spec=spec, layout=layout)
    level = samples.level()
    fingerprint = workspace.model_fingerprint(spec, layout)
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
    _load.cache_clear()
    _distinct_targets.cache_clear()
    return len(poses["head_position"])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--samples", type=int, default=4000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", type=pathlib.Path, default=DATA_PATH)
    parser.add_argument("--seek-level-time", type=float, default=SEEK_LEVEL_TIME,
                        help="seconds of dorsal tuning towards a level head per draw (0: off)")
    parser.add_argument("--append", action="store_true",
                        help="add to the poses already in --out (use a new --seed)")
    args = parser.parse_args(argv)
    count = generate(args.samples, args.seed, args.out, append=args.append,
                     seek_level_time=args.seek_level_time)
    print(f"wrote {count} level-head poses to {args.out}")


if __name__ == "__main__":
    main()
