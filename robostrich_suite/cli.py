"""Console-script wrapper: exit status and one-line errors for the `robostrich-*` commands.

Every module with a command keeps `main(argv)` returning its results (for
Python callers and tests) and offers `cli(argv)`, the console-script entry
point in setup.py, which calls `run(main, prog, argv)`:

    0    success (whatever `main` returned)
    2    an expected user error: ValueError (bad values, damaged or mismatched
         checkpoints), OSError (a missing file or directory, ...); one line
         `PROG: error: MESSAGE` on stderr, no traceback
    130  interrupted (Ctrl-C)

argparse's own usage errors keep their usual exit status 2 and `--help` 0.
Anything else is a bug and keeps its traceback.
"""
from __future__ import annotations

import sys
from typing import Callable, Optional, Sequence

USER_ERROR = 2
INTERRUPTED = 130


def error_message(error: BaseException) -> str:
    """One line: `str(error)`, with an OSError's strerror and file name where it has them."""
    if isinstance(error, OSError) and error.strerror:
        message = error.strerror if error.filename is None else f"{error.strerror}: {error.filename}"
    else:
        message = str(error) or type(error).__name__
    return " ".join(message.split())


def run(main: Callable, prog: str, argv: Optional[Sequence[str]] = None) -> int:
    """Call `main(argv)` as a console script would: an exit status instead of a return value."""
    try:
        main(argv)
    except KeyboardInterrupt:
        print(f"{prog}: interrupted", file=sys.stderr)
        return INTERRUPTED
    except (ValueError, OSError) as error:
        sys.stdout.flush()
        print(f"{prog}: error: {error_message(error)}", file=sys.stderr)
        return USER_ERROR
    return 0
