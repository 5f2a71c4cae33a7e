"""Output files written whole or not at all: a reader (or a Ctrl-C, a full disk) never leaves a
half-written target file, figure, table or recording behind, only the old file or the new one."""
from __future__ import annotations

import contextlib
import os
import pathlib
import tempfile


@contextlib.contextmanager
def replaced_atomically(path, mode: str = "wb"):
    """Open a temporary file beside ``path`` for writing; when the block ends without an error it
    is renamed over ``path``, otherwise removed (``path`` keeps what it held)."""
    fd, tmp = temporary_beside(path)
    try:
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
    with _naming(path):
        return tempfile.mkstemp(prefix=f".{path.name}.", suffix=".partial", dir=path.parent)


def land(tmp: str, path) -> None:
    """Rename the whole temporary file ``tmp`` (``temporary_beside``) over ``path``."""
    os.chmod(tmp, 0o644)  # mkstemp makes it private; this is an ordinary output file
    with _naming(pathlib.Path(path)):
        os.replace(tmp, path)


@contextlib.contextmanager
def _naming(path: pathlib.Path):
    """An OSError in the block names ``path``, the file the user asked for, not the temporary one."""
    try:
        yield
    except OSError as error:
        if error.errno is None:
            raise
        raise type(error)(error.errno, error.strerror, str(path)) from None


def write_text(path, text: str) -> None:
    with replaced_atomically(path, "w") as handle:
        handle.write(text)


def save_figure(fig, path, **savefig_kwargs) -> pathlib.Path:
    """``fig.savefig`` to ``path`` (its suffix names the format), whole or not at all."""
    path = pathlib.Path(path)
    with replaced_atomically(path) as handle:
        fig.savefig(handle, format=path.suffix.lstrip(".") or "png", **savefig_kwargs)
    return path
