"""Where a command will write, checked before it starts: a path the system cannot take (over
PATH_MAX, a name over NAME_MAX), a file where a directory must be, or a place it may not write in
is one line before any work (a draw of an hour, a training) and before any directory is made.

Every command that takes ``--out`` calls ``check_directory`` or ``check_file`` on it first."""
from __future__ import annotations

import errno
import os
import pathlib

PATH_MAX = 4096  # bytes, the terminating NUL included (Linux)
NAME_MAX = 255  # bytes of one name
# Room kept below PATH_MAX for what a command puts inside a directory it is given (say
# figures/learning_curves.png, or an evaluation's LABEL_heldout_moving.json), and for the temporary
# name a file is written under before it takes its own (robostrich_suite/atomic_files.py).
INSIDE_ROOM = 320
TEMPORARY_ROOM = 32


def check_directory(path, flag: str = "--out") -> pathlib.Path:
    """``path`` as an output directory: it is one, or can be made, and this user may write in it.
    OSError (one line naming ``flag``) otherwise; nothing is made."""
    path = pathlib.Path(path)
    _check_length(path, flag, INSIDE_ROOM)
    if path.exists() and not path.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, f"{flag} {_shown(path)} is a file, not a directory")
    _check_writable(path, flag)
    return path


def check_file(path, flag: str = "--out") -> pathlib.Path:
    """``path`` as an output file: not a directory, and its directory is one (or can be made) that
    this user may write in (a file is replaced by renaming a new one over it). OSError otherwise."""
    path = pathlib.Path(path)
    _check_length(path, flag, TEMPORARY_ROOM)
    if path.is_dir():
        raise IsADirectoryError(errno.EISDIR, f"{flag} {_shown(path)} is a directory, not a file")
    _check_writable(path.parent, flag)
    return path


def _check_length(path: pathlib.Path, flag: str, room: int) -> None:
    """ENAMETOOLONG if ``path`` (as given: the system sees it so) or one of its names is too long."""
    encoded = os.fsencode(str(path))
    if len(encoded) + room >= PATH_MAX:
        raise OSError(errno.ENAMETOOLONG, f"{flag} is {len(encoded)} bytes long: a path the commands write "
                                          f"must be under {PATH_MAX - room} bytes ({_shown(path)})")
    for name in path.parts:
        if len(os.fsencode(name)) > NAME_MAX:
            raise OSError(errno.ENAMETOOLONG, f"{flag}: a name in the path is {len(os.fsencode(name))} bytes "
                                              f"long, over the {NAME_MAX} a file system allows ({_shown(name)})")


def _check_writable(directory: pathlib.Path, flag: str) -> None:
    """The nearest existing directory at or above ``directory`` must be one this user may write in
    (the rest of the path is made there)."""
    existing = directory
    while not os.path.lexists(existing) and existing != existing.parent:
        existing = existing.parent
    if not existing.is_dir():
        raise NotADirectoryError(errno.ENOTDIR, f"{flag} {_shown(directory)}: {_shown(existing)} is a file, "
                                                "not a directory")
    if not os.access(existing, os.W_OK | os.X_OK):
        why = "a read-only file system" if _read_only(existing) else "no permission to write there"
        raise PermissionError(errno.EACCES, f"{flag} {_shown(directory)}: cannot write in {_shown(existing)} ({why})")


def _read_only(directory: pathlib.Path) -> bool:
    try:
        return bool(os.statvfs(directory).f_flag & os.ST_RDONLY)
    except OSError:
        return False


def _shown(path, limit: int = 120) -> str:
    """``path`` for a one-line message: its start and end where it is very long."""
    text = str(path)
    return text if len(text) <= limit else f"{text[:limit // 2]}...{text[-limit // 2:]}"
