"""One command owns an output directory at a time: an exclusive flock on ``DIR/.lock``.

Two runs (or two sweeps) writing one directory would interleave their records and overwrite each
other's checkpoints and tables; the second is refused before it changes anything. The lock is
released by the kernel when its holder ends, however it ends (a SIGKILL included); a holder that
ends normally also removes the file (``with lock_directory(...)``), so a finished directory holds
only its results.
"""
import fcntl
import os


class DirectoryLock:
    """The open, locked ``DIR/.lock``; a context manager that releases it and removes the file."""

    def __init__(self, path: str, handle):
        self.path, self.handle = path, handle

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.release()

    def release(self) -> None:
        """Remove the file while still holding it (one that a newer holder made is left alone), then unlock."""
        if self.handle.closed:
            return
        try:
            if os.stat(self.path).st_ino == os.fstat(self.handle.fileno()).st_ino:
                os.unlink(self.path)
        except FileNotFoundError:
            pass
        self.handle.close()


def lock_directory(out: str, prog: str) -> DirectoryLock:
    """Make ``out`` this process's; returns the lock, to be held while the work lasts. A
    directory in use is a ValueError naming its owner's process, and changes nothing."""
    os.makedirs(out, exist_ok=True)
    path = os.path.join(out, ".lock")
    while True:
        handle = open(path, "a+")
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            owner = handle.read().strip()
            handle.close()
            raise ValueError(f"{out} is in use by another {prog} ({path} is locked"
                             f"{', process ' + owner if owner else ''}); wait for it to end or choose another --out") from None
        try:  # the file a holder removed as it ended is no lock: lock the one at the path now
            current = os.stat(path).st_ino
        except FileNotFoundError:
            current = None
        if current == os.fstat(handle.fileno()).st_ino:
            break
        handle.close()
    handle.seek(0)
    handle.truncate()
    handle.write(f"{os.getpid()}\n")
    handle.flush()
    return DirectoryLock(path, handle)
