"""The lookup baseline's final evaluation, kept once it is made: the lookup does not learn, so for the
same routing, targets, tasks and code its reports are the same in every run, and the main job would
spend a core's minute on them each time (on the critical path: it runs once the first run is done).

A kept evaluation is found by a digest of everything its result depends on: the domain and the
tasks, the held-out count, the new targets, whether a recording is written, the routing's target
file, the versions of MuJoCo, dm_control and numpy, and the source of both packages (any change to
the code makes a new one). It sits in the new targets' cache folder (studies/new_targets.py),
under ``lookup/DIGEST/``: the report files, and ``done`` written last, so a half-kept one is never read.
"""
import functools
import hashlib
import os
import pathlib
from typing import Optional

import dm_control
import mujoco
import numpy as np

import agents
import robostrich_suite
from robostrich_suite import atomic_files
from robostrich_suite.studies import new_targets

FORMAT = 1
DONE = "done"


@functools.lru_cache(maxsize=1)
def _source_digest() -> str:
    """sha256 of every .py file of both packages, in path order (a few ms)."""
    digest = hashlib.sha256()
    for package in (agents, robostrich_suite):
        root = pathlib.Path(package.__file__).parent
        for path in sorted(root.rglob("*.py")):
            digest.update(str(path.relative_to(root)).encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def key(domain, heldout_task: str, track_task: Optional[str], num_targets: Optional[int], new, record: bool) -> str:
    """The digest that names a kept evaluation of the lookup on ``domain`` (module doc)."""
    digest = hashlib.sha256()
    digest.update(repr((FORMAT, domain.info(), heldout_task, track_task, num_targets, record, mujoco.__version__,
                        dm_control.__version__ if hasattr(dm_control, "__version__") else "", np.__version__,
                        _source_digest())).encode())
    digest.update(b"" if new is None else np.ascontiguousarray(new, np.float64).tobytes())
    digest.update(pathlib.Path(domain.target_file()).read_bytes())
    return digest.hexdigest()[:24]


def folder(digest: str) -> pathlib.Path:
    return new_targets.cache_dir() / "lookup" / digest


def restore(digest: str, out_dir: str) -> Optional[list]:
    """Copy a kept evaluation's files into ``out_dir``; their names, or None if none is kept."""
    kept = folder(digest)
    if not (kept / DONE).is_file():
        return None
    names = sorted(p.name for p in kept.iterdir() if p.name != DONE)
    os.makedirs(out_dir, exist_ok=True)
    for name in names:
        with atomic_files.replaced_atomically(os.path.join(out_dir, name)) as handle:
            handle.write((kept / name).read_bytes())
    return names


def keep(digest: str, out_dir: str, names) -> None:
    """Keep the files ``names`` of ``out_dir`` under ``digest``; a cache that cannot be written is
    skipped (the evaluation is made again next time)."""
    kept = folder(digest)
    try:
        kept.mkdir(parents=True, exist_ok=True)
        for name in names:
            with atomic_files.replaced_atomically(kept / name) as handle:
                handle.write(pathlib.Path(out_dir, name).read_bytes())
        atomic_files.write_text(kept / DONE, "\n".join(names))
    except OSError:
        pass
