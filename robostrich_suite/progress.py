"""Progress bars that leave the screen clean when a command stops early: a bar cut short by an
error or Ctrl-C is cleared, so the command's one line (robostrich_suite/cli.py) stands alone
instead of beside a half-drawn bar."""
from __future__ import annotations

import contextlib


@contextlib.contextmanager
def bar(enabled: bool = True, **tqdm_kwargs):
    """A tqdm bar (on stderr) for the block, or None when not ``enabled``; kept on the screen when
    the block ends normally, cleared when it ends by an exception."""
    if not enabled:
        yield None
        return
    from tqdm import tqdm
    progress = tqdm(**tqdm_kwargs)
    try:
        yield progress
    except BaseException:
        progress.leave = False  # close() then clears the line
        raise
    finally:
        progress.close()

