"""Target generation: sample the actuated workspace and keep the level-head poses.

The tasks' targets are the level subset of the *actuated* workspace
(:func:`workspace.actuated_samples`), each with the tendon inputs that hold it;
:mod:`robostrich_suite.targets` loads the files written here.  After a change to the
arm that moves few poses (a contact, a limit), re-hold a file's stored inputs and keep
the poses still held level, at their new positions::

    robostrich-targets --recheck --out robostrich_suite/data/level_head_poses_antagonist_pairs.npz --layout antagonist_pairs

The shipped files are random draws plus a sought pose per blue-region sample (docs/layouts.md
names each file's command)::

    robostrich-targets --samples 2000 --blue-samples 600000 --layout ventral_slips --out robostrich_suite/data/level_head_poses.npz

(the command: robostrich_suite/studies/targets.py)
"""
from __future__ import annotations

import pathlib

import numpy as np

from robostrich_suite import atomic_files
from robostrich_suite import parallel
from robostrich_suite import progress as progress_lib
from robostrich_suite import targets
from robostrich_suite import fingerprint as fingerprint_lib
from robostrich_suite.studies import pose_seek, workspace
from robostrich_suite import scenes
from robostrich_suite.studies import coverage

SEEK_LEVEL_TIME = 2.5  # s of dorsal-input tuning per draw before it is held
RECHECK_MIN_KEPT = 0.5  # a recheck that would drop more poses than this leaves the file alone


def generate(num_samples: int, seed: int = 0, path: pathlib.Path = targets.DATA_PATH,
             workers: int = 2, append: bool = False,
             seek_level_time: float = SEEK_LEVEL_TIME, spec=None, layout=None,
             blue_samples: int = 0) -> int:
    """Sample the actuated workspace and save its level subset; returns its size.

    ``seek_level_time`` > 0 tunes each draw's dorsal input towards a level head
    before holding it (:func:`workspace.seek_level`): many more
    level poses per CPU second.  ``blue_samples`` > 0 also seeks one pose per level head
    among that many kinematic samples (the blue region of Fig. 6;
    :func:`pose_seek.seek_samples`), which fills the region random inputs rarely reach.
    Every pose is held from the fixed start for one episode.  With ``append`` the new
    poses are added to those already in ``path`` (which must come from the same arm);
    use another seed.  ``spec`` and ``layout`` (an ``ArmSpec`` and ``TendonLayout``) make
    targets for another arm; write them to another ``path`` and pass
    ``training_targets(path)`` as the tasks' ``target_pool``.
    """
    fingerprint = fingerprint_lib.model_fingerprint(spec, layout)
    old = targets.level_head_poses(path) if append and path.exists() else None  # checked before drawing
    if old is not None and str(old["fingerprint"]) != fingerprint:
        raise ValueError(f"{path} was made with another arm; regenerate without --append")
    parts = []
    if num_samples > 0:
        parts.append(workspace.actuated_samples_parallel(num_samples, seed=seed, workers=workers,
                                                         progress=True,
                                                         seek_level_time=seek_level_time,
                                                         spec=spec, layout=layout))
    if blue_samples > 0:
        parts.append(seek_blue_region(blue_samples, seed, workers, spec, layout))
    if not parts:
        raise ValueError("nothing to draw: give samples and/or blue samples")
    samples = workspace.ActuatedSamples.concatenate(parts)
    level = samples.level()
    if not level.any():  # a target file of no pose would fail every task that loads it
        raise ValueError(f"none of the {len(level)} poses drawn holds the head level: nothing written to {path}; "
                         "draw more (--samples, --blue-samples) or tune towards level (--seek-level-time)")
    new = dict(head_position=samples.head_position[level],
               head_attitude=samples.head_attitude[level], control=samples.control[level])
    if old is not None:
        new = {key: np.concatenate([old[key], value]) for key, value in new.items()}
    return save_level_poses(path, new, fingerprint)


def _seek_chunk(args) -> workspace.ActuatedSamples:
    positions, angles, spec, layout = args
    return pose_seek.seek_samples(positions, angles, spec, layout)


def seek_blue_region(kinematic_samples: int, seed: int = 0, workers: int = 2, spec=None,
                     layout=None) -> workspace.ActuatedSamples:
    """One sought pose (held from the fixed start) per level head among ``kinematic_samples``
    kinematic samples, split over ``workers`` processes."""
    region = coverage.BlueRegion.from_samples(workspace.kinematic_samples(kinematic_samples, seed, spec))
    chunks = [(p, a, spec, layout) for p, a in zip(np.array_split(region.head_position, workers),
                                                  np.array_split(region.joint_angles, workers)) if len(p)]
    if not chunks:
        raise ValueError(f"no level head among {kinematic_samples} kinematic samples; draw more")
    if len(chunks) == 1:
        return _seek_chunk(chunks[0])
    return workspace.ActuatedSamples.concatenate(parallel.map_processes(_seek_chunk, chunks))


def recheck(path: pathlib.Path, spec=None, layout=None, settle_time: float = pose_seek.HOLD_TIME,
            progress: bool = False) -> tuple[int, int]:
    """Hold every stored pose's inputs in ``path`` from reset on today's arm (``spec``,
    ``layout``) and rewrite the file with the poses that still come to rest level, at
    the positions they reach now; returns ``(kept, stored)``.  Where fewer than half are
    kept the file is most likely another arm's: ValueError, and the file stays."""
    poses = targets.level_head_poses(path)
    physics = scenes.frame_physics(spec, layout)
    if poses["control"].shape[1] != physics.model.nu:
        raise ValueError(f"{path} holds inputs for {poses['control'].shape[1]} tendons, the arm has "
                         f"{physics.model.nu}: pass the layout it was made with")
    count = len(poses["control"])
    held = workspace.ActuatedSamples(np.zeros((count, 2)), np.zeros(count), np.array(poses["control"]),
                                     np.zeros(count, bool))
    with progress_lib.bar(progress, total=count, desc="recheck", unit="pose", mininterval=1.0) as bar:
        for i in range(count):
            held.settled[i] = workspace.settle(physics, held.control[i], settle_time)
            held.head_position[i] = physics.head_position()[[0, 2]]
            held.head_attitude[i] = physics.head_attitude()
            if bar is not None:
                bar.update()
    level = held.level()  # the level rule every target file is made with
    kept = dict(head_position=held.head_position[level], head_attitude=held.head_attitude[level],
                control=held.control[level])
    if len(kept["control"]) < RECHECK_MIN_KEPT * count:  # most likely another arm's file: keep it
        raise ValueError(f"only {len(kept['control'])} of {count} poses of {path} are held level by this arm "
                         "(is the layout the one the file was made with?); the file is left as it was")
    save_level_poses(path, kept, fingerprint_lib.model_fingerprint(spec, layout))
    return len(kept["control"]), count


def save_level_poses(path: pathlib.Path, poses: dict, fingerprint: str, allow_empty: bool = False,
                     extra: dict | None = None) -> int:
    """Write ``poses`` (``head_position``, ``head_attitude``, ``control``) as a target file
    of the arm with ``fingerprint``, with the arrays ``extra`` beside them; returns how many.
    Readers of ``path`` see the new file."""
    path = pathlib.Path(path)
    if not len(poses["head_position"]) and not allow_empty:  # a layout compared may hold none
        raise ValueError(f"no level-head pose to write to {path}: a target file holds at least one")
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_files.replaced_atomically(path) as handle:  # whole or not at all (Ctrl-C, a full disk)
        np.savez_compressed(handle, fingerprint=np.array(fingerprint), **(extra or {}),
                            **{key: np.asarray(poses[key]) for key in ("head_position", "head_attitude", "control")})
    targets.clear_cache()
    return len(poses["head_position"])
