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
    path = pathlib.Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with _naming(path):
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".partial", dir=path.parent)
    try:
        with os.fdopen(fd, mode, **({} if "b" in mode else {"encoding": "utf-8", "newline": ""})) as handle:
            yield handle
        os.chmod(tmp, 0o644)  # mkstemp makes it private; this is an ordinary output file
        with _naming(path):
            os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


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
