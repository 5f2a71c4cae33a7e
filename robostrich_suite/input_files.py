"""Users' files read as what they claim to be: a regular file of bounded size, and ``.npz``
archives whose members are checked before numpy unpacks them.

Opening a FIFO for reading waits for a writer that may never come, ``/dev/zero`` reads without
end, a 3 MB archive can unpack to gigabytes, and an array header can claim 10^12 entries, which
numpy allocates before it reads one: each is one ValueError here that names the file and what is
wrong with it, which the commands turn into their one-line error.
"""
from __future__ import annotations

import io
import os
import stat
import zipfile
import zlib

import numpy as np

MAX_TEXT_BYTES = 64 << 20  # a JSON, TOML or CSV file a person or this project writes


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket")):
        if test(mode):
            return name
    return "not a regular file"


def read_bytes(path, max_bytes: int, what: str = "file") -> bytes:
    """The content of the regular file ``path``, at most ``max_bytes`` long: opened without
    waiting (a FIFO is refused, not waited on), its size checked before it is read, and read
    with a bound (a file that grows while it is read is refused too). A missing or unreadable
    file is the OSError that names it."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise ValueError(f"{os.fspath(path)}: {_kind(info.st_mode)}, not a {what} (a regular file)")
        if info.st_size > max_bytes:
            raise ValueError(f"{os.fspath(path)}: {info.st_size} bytes, more than a {what} may hold ({max_bytes})")
        os.set_blocking(fd, True)
        with os.fdopen(fd, "rb") as handle:
            fd = None
            data = handle.read(max_bytes + 1)
    finally:
        if fd is not None:
            os.close(fd)
    if len(data) > max_bytes:
        raise ValueError(f"{os.fspath(path)}: more than a {what} may hold ({max_bytes} bytes)")
    return data


def check_npz(archive_file, source, max_unpacked: int) -> None:
    """ValueError naming ``source`` unless every member of the ``.npz`` archive ``archive_file`` (a
    seekable binary file) is an array whose header's shape and type fit the size the archive
    declares for it, and those sizes add up to at most ``max_unpacked`` bytes."""
    try:
        with zipfile.ZipFile(archive_file) as archive:
            members = archive.infolist()
            total = sum(member.file_size for member in members)
            if total > max_unpacked:
                raise ValueError(f"{source}: its arrays unpack to {total} bytes, more than {max_unpacked}")
            for member in members:
                try:
                    with archive.open(member) as handle:
                        shape, dtype = _header(handle)
                except ValueError as error:
                    raise ValueError(f"{source}: member {member.filename!r} is not a numpy array ({error})") from None
                needed = int(np.prod(shape, dtype=object)) * dtype.itemsize
                if needed > member.file_size:
                    raise ValueError(f"{source}: array {member.filename!r} claims shape {tuple(shape)} of {dtype}, "
                                     f"{needed} bytes, more than the {member.file_size} it holds")
    except (zipfile.BadZipFile, EOFError, OSError, zlib.error) as error:
        raise ValueError(f"{source}: not an .npz archive ({type(error).__name__}: {error})") from None
    finally:
        archive_file.seek(0)


def _header(handle) -> tuple:
    """(shape, dtype) of the .npy stream ``handle``, from its header alone."""
    version = np.lib.format.read_magic(handle)
    read = {(1, 0): np.lib.format.read_array_header_1_0, (2, 0): np.lib.format.read_array_header_2_0}.get(version)
    if read is None:
        raise ValueError(f"array header version {version}")
    shape, _, dtype = read(handle)
    return shape, dtype


def npz_bytes(path, max_bytes: int, max_unpacked: int, what: str = "file") -> io.BytesIO:
    """The ``.npz`` archive ``path`` in memory (``read_bytes``), its members checked (``check_npz``):
    ready for ``np.load(..., allow_pickle=False)``."""
    data = io.BytesIO(read_bytes(path, max_bytes, what))
    if not zipfile.is_zipfile(data):  # numpy would read anything else as one array, or a pickle it refuses
        raise ValueError(f"{os.fspath(path)}: not a {what} (not an .npz archive"
                         f"{', it is empty' if not data.getbuffer().nbytes else ''})")
    check_npz(data, os.fspath(path), max_unpacked)
    return data
