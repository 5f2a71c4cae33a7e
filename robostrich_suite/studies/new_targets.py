"""New targets: level poses a policy never trained near, to judge it between the stored poses.

The held-out targets are a fifth of the pool the agent trains on, drawn from the same file, so a
policy that has learned the list and one that has learned the arm read alike there. New targets
are what a researcher gives it: level poses the project's own generator (held random inputs tuned
towards a level head, :func:`workspace.actuated_samples`) makes with a seed no target file uses,
each kept at least ``targets.MIN_TARGET_SPACING`` (1 cm) from every pose of the routing's target
file and from each other. Draws come in fixed chunks of their own seeds, so a set depends on the
seed alone, not on how many processes drew it, and a smaller set is the start of a larger one. A
set is made once per routing and seed and read from a cache after that (the default routing's ships
in ``robostrich_suite/data/new_targets/``); a larger count than it holds is made anew from the
first draw, and starts with the smaller set.
"""
from __future__ import annotations

import hashlib
import os
import pathlib

import numpy as np

from robostrich_suite import parallel, targets
from robostrich_suite import progress as progress_lib
from robostrich_suite.studies import target_generation, workspace

SEED = 700_000  # of the first draw chunk; target files are drawn from small seeds (docs/layouts.md)
COUNT = 120  # targets of a set: at 1 cm apart the default routing's gaps hold a few hundred
DRAW_CHUNK = 250  # held inputs per chunk (its seed: SEED + chunk index)
MAX_DRAWS = 40_000  # a routing whose gaps hold fewer targets stops here, with what it found
SHIPPED_DIR = pathlib.Path(__file__).resolve().parent.parent / "data" / "new_targets"
FORMAT = 1  # of a cached set: a change to how sets are made changes every key


def cache_dir() -> pathlib.Path:
    """Where made sets are kept: $ROBOSTRICH_CACHE, else $XDG_CACHE_HOME/robostrich_suite, else
    ~/.cache/robostrich_suite."""
    root = os.environ.get("ROBOSTRICH_CACHE")
    if root:
        return pathlib.Path(root)
    return pathlib.Path(os.environ.get("XDG_CACHE_HOME") or pathlib.Path.home() / ".cache") / "robostrich_suite"


def set_name(target_file: pathlib.Path, seed: int = SEED) -> str:
    """The file name of a set: a digest of the routing's target file (its arm and poses), the seed
    and how sets are made."""
    poses = targets.level_head_poses(target_file)
    digest = hashlib.sha256()
    digest.update(str(poses["fingerprint"]).encode())
    digest.update(np.ascontiguousarray(poses["head_position"], np.float64).tobytes())
    digest.update(repr((FORMAT, seed, DRAW_CHUNK, MAX_DRAWS, targets.MIN_TARGET_SPACING,
                        target_generation.SEEK_LEVEL_TIME)).encode())
    return f"new_targets_{digest.hexdigest()[:16]}.npz"


def new_targets(target_file: pathlib.Path, layout=None, seed: int = SEED, count: int = COUNT,
                workers: int = 2, progress: bool = True) -> np.ndarray:
    """(n, 2) new targets (x, z) of the routing whose target file is ``target_file`` (``layout``
    its TendonLayout; None: the default), n = ``count`` unless the routing's gaps hold fewer:
    the start of the shipped or cached set, else made now (``workers`` processes, a progress bar)
    and cached."""
    name = set_name(target_file, seed)
    for path in (SHIPPED_DIR / name, cache_dir() / name):
        if path.is_file():
            stored = targets.level_head_poses(path)
            if len(stored["head_position"]) >= count or bool(stored.get("exhausted", False)):
                return stored["head_position"][:count].copy()
    poses = make(target_file, layout, seed, count, workers, progress)
    fingerprint = str(targets.level_head_poses(target_file)["fingerprint"])
    try:
        target_generation.save_level_poses(cache_dir() / name, poses, fingerprint,
                                           extra={"exhausted": poses["exhausted"]})
    except OSError:  # a read-only home: the set is made again next time, and is the same
        pass
    return poses["head_position"].copy()


def make(target_file: pathlib.Path, layout=None, seed: int = SEED, count: int = COUNT, workers: int = 2,
         progress: bool = True) -> dict:
    """Draw chunks of held inputs (chunk k from seed ``seed + k``), keep their level poses at least
    1 cm from every pose of ``target_file`` and from the poses kept before, until ``count`` are
    kept or ``MAX_DRAWS`` inputs are drawn; ``head_position``, ``head_attitude``, ``control`` and
    ``exhausted`` (whether the draws ran out first)."""
    stored = targets.level_head_poses(target_file)["head_position"]
    kept = {"head_position": [], "head_attitude": [], "control": []}
    chunk = 0
    with progress_lib.bar(progress, total=count, desc="new targets", unit="target") as bar:
        while len(kept["head_position"]) < count and chunk * DRAW_CHUNK < MAX_DRAWS:
            jobs = [(DRAW_CHUNK, seed + chunk + i, workspace.SETTLE_TIME, target_generation.SEEK_LEVEL_TIME,
                     None, layout) for i in range(max(1, workers))]
            chunk += len(jobs)
            drawn = (parallel.map_processes(workspace._actuated_chunk, jobs) if len(jobs) > 1
                     else [workspace._actuated_chunk(jobs[0])])
            for samples in drawn:  # in seed order, so the set does not depend on the workers
                before = len(kept["head_position"])
                _keep_far(samples, stored, kept, count)
                if bar is not None:
                    bar.update(len(kept["head_position"]) - before)
    if not kept["head_position"]:
        raise ValueError(f"no level pose at least {targets.MIN_TARGET_SPACING * 100:g} cm from every pose of "
                         f"{target_file} in {chunk * DRAW_CHUNK} draws: this routing has no new targets")
    return {**{key: np.array(value) for key, value in kept.items()},
            "exhausted": np.array(len(kept["head_position"]) < count)}


def _keep_far(samples: workspace.ActuatedSamples, stored: np.ndarray, kept: dict, count: int) -> None:
    """Add to ``kept`` each level pose of ``samples`` 1 cm or more from ``stored`` and from ``kept``."""
    for i in np.flatnonzero(samples.level()):
        if len(kept["head_position"]) >= count:
            return
        position = samples.head_position[i]
        others = np.concatenate([stored, np.reshape(kept["head_position"], (-1, 2))])
        if np.min(np.linalg.norm(others - position, axis=1)) >= targets.MIN_TARGET_SPACING:
            kept["head_position"].append(position)
            kept["head_attitude"].append(samples.head_attitude[i])
            kept["control"].append(samples.control[i])
