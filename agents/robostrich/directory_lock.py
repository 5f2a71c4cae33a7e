"""One command owns an output directory at a time: an exclusive flock on ``DIR/.lock``.

Two runs (or two sweeps) writing one directory would interleave their records and overwrite each
other's checkpoints and tables; the second is refused before it changes anything. The lock is
released by the kernel when its holder ends, however it ends (a SIGKILL included).
"""
import fcntl
import os


def lock_directory(out: str, prog: str):
    """Make ``out`` this process's; returns the open lock file, to be kept open while the work
    lasts. A directory in use is a ValueError naming its owner's process, and changes nothing."""
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, ".lock")
    handle = open(path, "a+")
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        handle.seek(0)
        owner = handle.read().strip()
        handle.close()
        raise ValueError(f"{out} is in use by another {prog} ({path} is locked"
                         f"{', process ' + owner if owner else ''}); wait for it to end or choose another --out") from None
    handle.seek(0)
    handle.truncate()
    handle.write(f"{os.getpid()}\n")
    handle.flush()
    return handle
