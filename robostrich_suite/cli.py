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


def _number(kind, text: str):
    import argparse
    try:
        return kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid {'whole number' if kind is int else 'number'}: {text!r}") from None


def whole_number(minimum: int):
    """argparse type: an int >= minimum (a usage error naming the flag otherwise)."""
    import argparse

    def parse(text: str) -> int:
        value = _number(int, text)
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be at least {minimum}, got {text}")
        return value
    return parse


def seconds(allow_zero: bool = False):
    """argparse type: a finite number of seconds, > 0 (or >= 0 with allow_zero); NaN is refused."""
    import argparse
    import math

    def parse(text: str) -> float:
        value = _number(float, text)
        if not math.isfinite(value) or value < 0 or (value == 0 and not allow_zero):
            raise argparse.ArgumentTypeError(
                f"must be a finite number of seconds {'>= 0' if allow_zero else '> 0'}, got {text}")
        return value
    return parse
