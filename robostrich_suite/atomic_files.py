"""Output files written whole or not at all: a reader (or a Ctrl-C, a full disk) never leaves a
half-written target file, figure, table or recording behind, only the old file or the new one."""
from __future__ import annotations

import contextlib
import hashlib
import json
import os
import pathlib
import tempfile

NAME_MAX = 255  # bytes of one file name (Linux, macOS)
_SUFFIX = ".partial"
_RANDOM = 8  # characters tempfile puts between a temporary name's prefix and suffix


@contextlib.contextmanager
def replaced_atomically(path, mode: str = "wb"):
    """Open a temporary file beside ``path`` for writing; when the block ends without an error it
    is renamed over ``path``, otherwise removed (``path`` keeps what it held). A write that fails
    (a full disk, a file size limit) names ``path``."""
    fd, tmp = temporary_beside(path)
    try:
        with naming(path, only_unnamed=True):
            with os.fdopen(fd, mode, **({} if "b" in mode else {"encoding": "utf-8", "newline": ""})) as handle:
                yield handle
        land(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def temporary_beside(path) -> tuple:
    """(descriptor, name) of a new empty file beside ``path`` (its directory made), for what takes
    ``path``'s name once whole (``land``); for writers that want a file name, not a handle."""
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with naming(path):
        return tempfile.mkstemp(prefix=temporary_prefix(path.name), suffix=_SUFFIX, dir=path.parent)


def temporary_prefix(name: str) -> str:
    """``.NAME.``, or where the temporary name would pass NAME_MAX (a legal name of 240 bytes or
    more) NAME's start and a hash of all of it: any name that may be written gets a temporary one."""
    prefix = f".{name}."
    room = NAME_MAX - _RANDOM - len(_SUFFIX)
    if len(os.fsencode(prefix)) <= room:
        return prefix
    digest = hashlib.sha256(os.fsencode(name)).hexdigest()[:12]
    start = os.fsencode(name)[:room - len(digest) - 3].decode("utf-8", "ignore")  # no half character
    return f".{start}~{digest}."


def land(tmp: str, path) -> None:
    """Rename the whole temporary file ``tmp`` (``temporary_beside``) over ``path``."""
    with naming(pathlib.Path(path)):
        os.chmod(tmp, 0o644)  # mkstemp makes it private; this is an ordinary output file
        os.replace(tmp, path)


@contextlib.contextmanager
def naming(path, only_unnamed: bool = False):
    """An OSError in the block names ``path``, the file the user asked for, not the temporary one
    (or, ``only_unnamed``, no file: a failed write says only "No space left on device")."""
    try:
        yield
    except OSError as error:
        if error.errno is None or (only_unnamed and error.filename is not None):
            raise
        raise type(error)(error.errno, error.strerror, str(path)) from None


def write_text(path, text: str) -> None:
    with replaced_atomically(path, "w") as handle:
        handle.write(text)


def write_json(path, obj) -> None:
    """``obj`` as JSON (numpy numbers and arrays as plain ones), written whole or not at all."""
    write_text(path, json.dumps(obj, indent=1, default=_plain_json))


def _plain_json(value):
    import numpy as np
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON serialisable: {type(value)}")


def save_figure(fig, path, **savefig_kwargs) -> pathlib.Path:
    """``fig.savefig`` to ``path`` (its suffix names the format), whole or not at all."""
    path = pathlib.Path(path)
    with replaced_atomically(path) as handle:
        fig.savefig(handle, format=path.suffix.lstrip(".") or "png", **savefig_kwargs)
    return path
