"""Targets for the reaching tasks: head positions the arm really holds level.

The paper draws targets from the blue region of Fig. 6 (head attitude 90 +- 5
deg).  A kinematic sample of that region includes poses a passive chain under
gravity cannot hold, so we ship instead the level subset of the *actuated*
workspace (:func:`robostrich_suite.studies.workspace.actuated_samples`): every target
comes with the tendon inputs that hold the head there, and a test re-simulates
some of them.  Every fifth pose is held out for evaluation and never used in
training.

This module only loads them; :mod:`robostrich_suite.studies.target_generation` makes them
(its docstring has the shipped files' commands, and ``--recheck`` for a change to the arm).
"""
from __future__ import annotations

import functools
import pathlib
import zipfile
import zlib

import numpy as np

DATA_PATH = pathlib.Path(__file__).parent / "data" / "level_head_poses.npz"
HELDOUT_EVERY = 5
MIN_TARGET_SPACING = 0.01  # m
FIELDS = ("head_position", "head_attitude", "control", "fingerprint")  # of a target file


@functools.lru_cache(maxsize=None)
def _load(path: str = str(DATA_PATH)) -> dict:
    path = pathlib.Path(path)
    if not path.exists():
        raise FileNotFoundError(
            f"{path} is missing; regenerate it with `robostrich-targets --out {path}`")
    try:
        with np.load(path) as data:
            poses = {key: data[key] for key in data.files}
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error) as error:
        raise ValueError(f"{path} is not a target file (a damaged or truncated .npz?): "
                         f"{type(error).__name__}: {error}") from None
    missing = [key for key in FIELDS if key not in poses]
    if missing:
        raise ValueError(f"{path} is not a target file: it lacks {missing} (it holds {sorted(poses)})")
    count = len(poses["head_position"])
    if (poses["head_position"].shape != (count, 2) or poses["head_attitude"].shape != (count,)
            or poses["control"].ndim != 2 or len(poses["control"]) != count):
        raise ValueError(f"{path} is not a target file: head_position {poses['head_position'].shape}, head_attitude "
                         f"{poses['head_attitude'].shape} and control {poses['control'].shape} do not match")
    return poses


def level_head_poses(path: str | pathlib.Path = DATA_PATH) -> dict:
    """All shipped level-head poses (or those of a file ``target_generation.generate`` wrote):
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
    poses, or from a file ``target_generation.generate`` wrote for another arm)."""
    return _split(False, str(path))


def heldout_targets(path: str | pathlib.Path = DATA_PATH, count: int | None = None) -> np.ndarray:
    """(n, 2) target positions (x, z) kept out of training, for evaluation: all of them, or
    ``count`` spread evenly over them (:func:`spread_indices`)."""
    pool = _split(True, str(path))
    return pool if count is None else pool[spread_indices(len(pool), count)]


def spread_indices(count: int, wanted: int) -> np.ndarray:
    """`wanted` indices spread evenly over range(count) (all of them if wanted >= count).

    Why: the held-out targets are stored in generation order, which runs through the workspace
    region by region; the first 20 of 44 on `antagonist_pairs` miss its upper targets, where a
    policy can fail while the periodic evaluation reads 95 %."""
    if wanted >= count:
        return np.arange(count)
    return np.unique(np.round(np.linspace(0, count - 1, max(int(wanted), 1))).astype(int))


def clear_cache() -> None:
    """Forget the files read so far: a rewritten target file is read anew."""
    _load.cache_clear()
    _distinct_targets.cache_clear()
