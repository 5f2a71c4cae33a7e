"""Console-script wrapper: exit status and one-line errors for the `robostrich-*` commands.

Every module with a command keeps `main(argv)` returning its results (for
Python callers and tests) and offers `cli(argv)`, the entry point that the
console scripts' table (robostrich_commands.py) names, which calls
`run(main, prog, argv)`:

    0    success (whatever `main` returned)
    2    an expected user error: ValueError (bad values, damaged or mismatched
         checkpoints), OSError (a missing file or directory, ...); one line
         `PROG: error: MESSAGE` on stderr, no traceback
    130  interrupted (Ctrl-C), also when a library swallowed the KeyboardInterrupt; a long
         loop that polls `interrupted()` inside `deferred_interrupts()` stops where its
         state is whole (training writes a checkpoint first)
    143  terminated (SIGTERM, as a batch scheduler or `kill` sends): handled as Ctrl-C is

Usage errors (`Parser`) are one line too, exit status 2; `--help` exits 0.  Anything
else is a bug and keeps its traceback.

Every count, duration and size a command accepts has an upper bound (the `MAX_*`
limits below, named in the error), so no flag asks for days or terabytes by accident.
"""
from __future__ import annotations

import argparse
import contextlib
import gc
import math
import re
import signal
import sys
import threading
from typing import Callable, Optional, Sequence

from robostrich_suite import parsing

USER_ERROR = 2
INTERRUPTED = 130  # 128 + SIGINT
TERMINATED = 143  # 128 + SIGTERM
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)  # both stop a command the same way (module doc)
CHECKPOINT_WRITTEN = "checkpoint written"  # how an interrupt that saved its work begins its message

# Generous but finite limits of what a flag may ask for (and, beside these, parsing's).
MAX_COUNT = parsing.MAX_COUNT
MAX_SECONDS = parsing.MAX_SECONDS
MAX_WORKERS = 256  # processes
MAX_SEED = 2**31 - 1 - 100_000  # seeds with offsets added stay 32-bit

_interrupted = False
_signal = signal.SIGINT  # the stop signal that came last
_deferred = 0


class Parser(argparse.ArgumentParser):
    """argparse with a one-line usage error (`PROG: error: ...`, exit 2): the usage of a
    command with fifty options would bury the line that matters. Abbreviated flags are refused
    (``allow_abbrev=False``): `--learning-rat` must not quietly set --learning-rate, nor change
    meaning when a flag is added."""

    def __init__(self, *args, allow_abbrev: bool = False, **kwargs):
        super().__init__(*args, allow_abbrev=allow_abbrev, **kwargs)

    def error(self, message):
        self.exit(USER_ERROR, f"{self.prog}: error: {' '.join(message.split())} (--help lists the options)\n")


def doc_excerpt(doc: str, start: str, stop: str, names: Optional[dict] = None) -> str:
    """The words of ``doc`` from ``start`` up to ``stop`` (excluded) as one line of --help text,
    reST markup taken off and each of ``names`` (a constant's name) replaced by its text (its
    value): help quotes a module's definition instead of a second copy of it."""
    text = doc[doc.index(start):doc.index(stop, doc.index(start) + len(start))]
    text = " ".join(re.sub(r":\w+:`~?([^`]+)`", r"\1", text).replace("``", "").split())
    for name, shown in (names or {}).items():
        text = re.sub(rf"\b{re.escape(name)}\b", shown, text)
    return text.rstrip(" :,;")


def interrupted() -> bool:
    """Whether Ctrl-C came since the command started (polled by loops inside `deferred_interrupts`)."""
    return _interrupted


def raise_if_interrupted() -> None:
    """KeyboardInterrupt if Ctrl-C came and was not acted on (deferred, or swallowed by a library
    that caught it in a callback): long loops call it once per step."""
    if _interrupted and not _deferred:
        raise KeyboardInterrupt


def _on_sigint(signum, frame):
    """Ctrl-C or SIGTERM: a KeyboardInterrupt now, or a flag for the loop inside `deferred_interrupts`;
    only the flag where Python would print the exception as ignored and go on (a garbage-collection
    callback, JAX's; an object's finaliser, Rerun's recording stream): the next
    `raise_if_interrupted`, or the end of `run`, acts on it."""
    global _interrupted, _signal
    _interrupted, _signal = True, signum
    if not _deferred and not _where_exceptions_are_ignored(frame):
        raise KeyboardInterrupt


def _where_exceptions_are_ignored(frame) -> bool:
    """Whether ``frame`` runs inside one of ``gc.callbacks`` or a ``__del__`` method."""
    codes = {getattr(callback, "__code__", None) for callback in gc.callbacks}
    while frame is not None:
        if frame.f_code in codes or frame.f_code.co_name == "__del__":
            return True
        frame = frame.f_back
    return False


def _install(handler) -> dict:
    """Set `handler` for both stop signals; returns the handlers it replaced."""
    previous = {}
    for signum in STOP_SIGNALS:
        previous[signum] = signal.getsignal(signum)
        signal.signal(signum, handler if not isinstance(handler, dict) else handler[signum])
    return previous


@contextlib.contextmanager
def deferred_interrupts():
    """Inside the block Ctrl-C only sets `interrupted()`, for a loop to poll between chunks: a
    KeyboardInterrupt raised anywhere can land in an XLA callback (which swallows it) or leave
    half-made state behind."""
    global _deferred, _interrupted
    main_thread = threading.current_thread() is threading.main_thread()
    inside_run = not main_thread or signal.getsignal(signal.SIGINT) is _on_sigint
    previous = None if inside_run else _install(_on_sigint)
    _deferred += 1
    try:
        yield
    finally:
        _deferred -= 1
        if previous is not None:  # outside `run` (a Python caller): the loop has acted on it
            _install(previous)
            _interrupted = False


@contextlib.contextmanager
def held_interrupts():
    """Ctrl-C and SIGTERM held off while the block makes or takes apart something that must not be
    left half-made (a Rerun sink: a KeyboardInterrupt raised as Rerun's call returns drops it unread,
    and Rerun warns on stderr), then acted on: a KeyboardInterrupt once the block is done, unless an
    enclosing `deferred_interrupts` loop polls for it."""
    enclosing = _deferred
    with deferred_interrupts():
        yield
        stopped = interrupted()
    if stopped and not enclosing:
        raise KeyboardInterrupt


def error_message(error: BaseException) -> str:
    """One line: `str(error)`, with an OSError's strerror and file name where it has them."""
    if isinstance(error, OSError) and error.strerror:
        message = error.strerror if error.filename is None else f"{error.strerror}: {error.filename}"
    else:
        message = str(error) or type(error).__name__
    return " ".join(message.split())


def run(main: Callable, prog: str, argv: Optional[Sequence[str]] = None) -> int:
    """Call `main(argv)` as a console script would: an exit status instead of a return value.
    Ctrl-C after `main` returned only sets the flag: the command is done, and a
    KeyboardInterrupt in the interpreter's exit would end it by the signal instead of 130."""
    global _interrupted, _deferred
    _interrupted, _deferred = False, 0
    if threading.current_thread() is threading.main_thread():
        _install(_on_sigint)
    try:
        main(argv)
        status, detail = (_stop_status() if _interrupted else 0), ""  # a library swallowed the KeyboardInterrupt
    except KeyboardInterrupt as error:  # the one detail worth a word: where a checkpoint went (a
        # library may wrap the interrupt in its own context, which says nothing to the user)
        status, detail = _stop_status(), error_message(error) if str(error).startswith(CHECKPOINT_WRITTEN) else ""
    except (ValueError, OSError) as error:
        sys.stdout.flush()
        print(f"{prog}: error: {error_message(error)}", file=sys.stderr)
        return USER_ERROR
    finally:
        _deferred += 1
    if status in (INTERRUPTED, TERMINATED):
        print(f"{prog}: {'terminated' if status == TERMINATED else 'interrupted'}" + (f" ({detail})" if detail else ""),
              file=sys.stderr)
    return status


def _stop_status() -> int:
    return TERMINATED if _signal == signal.SIGTERM else INTERRUPTED


def _number(kind, text: str):
    try:
        return kind(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"invalid {'whole number' if kind is int else 'number'}: {text!r}") from None


def whole_number(minimum: int, maximum: int = MAX_COUNT):
    """argparse type: an int in [minimum, maximum] (a usage error naming the flag otherwise)."""

    def parse(text: str) -> int:
        value = _number(int, text)
        if not minimum <= value <= maximum:
            raise argparse.ArgumentTypeError(f"must be from {minimum} to {maximum}, got {text}")
        return value
    return parse


def seconds(allow_zero: bool = False, maximum: float = MAX_SECONDS):
    """argparse type: a finite number of seconds, > 0 (or >= 0 with allow_zero), at most `maximum`."""

    def parse(text: str) -> float:
        value = _number(float, text)
        if not (math.isfinite(value) and value <= maximum and (value > 0 or (allow_zero and value == 0))):
            raise argparse.ArgumentTypeError(
                f"must be a number of seconds {'>= 0' if allow_zero else '> 0'} and at most {maximum:g}, got {text}")
        return value
    return parse


def number(minimum: float, maximum: float, unit: str = ""):
    """argparse type: a finite float in [minimum, maximum] (NaN and infinities refused)."""

    def parse(text: str) -> float:
        value = _number(float, text)
        if not (math.isfinite(value) and minimum <= value <= maximum):
            raise argparse.ArgumentTypeError(f"must be a number from {minimum:g} to {maximum:g}{unit}, got {text}")
        return value
    return parse


seed = whole_number(0, MAX_SEED)
