"""JSON and TOML read from users' files and flags, every failure one ValueError naming its source.

The standard parsers recurse: a document nested 100,000 deep ends in a RecursionError, a
traceback thousands of lines long, and one nested a few hundred deep parses but can exhaust the
stack of whatever walks it next. Here nesting beyond ``MAX_DEPTH`` levels, text that is not
UTF-8, an empty or torn document are all a ``ValueError`` that names the file (or flag) and says
what is wrong with it, which the commands turn into their one-line error.
"""
from __future__ import annotations

import json
import os
import tomllib

from robostrich_suite import input_files

# Generous but finite limits of what a flag or a task option may ask for (the commands' flags:
# robostrich_suite/cli.py; the tasks' options: robostrich_suite/tasks/options.py).
MAX_COUNT = 10_000_000  # samples, targets, rollouts: more than a day of simulation on 2 cores
MAX_SECONDS = 600.0  # simulated seconds of one episode, hold or ramp

MAX_DEPTH = 64  # levels of nested arrays and objects; what the project writes stays under 10


def _prefix(source) -> str:
    return f"{source}: " if source is not None else ""


def _too_deep(value, max_depth: int) -> bool:
    """Whether ``value`` nests lists/dicts more than ``max_depth`` levels (without recursing)."""
    stack = [(value, 1)]
    while stack:
        item, level = stack.pop()
        if isinstance(item, (dict, list, tuple)):
            if level > max_depth:
                return True
            stack.extend((child, level + 1) for child in (item.values() if isinstance(item, dict) else item))
    return False


def _decoded(text, source) -> str:
    if isinstance(text, (bytes, bytearray)):
        try:
            return bytes(text).decode("utf-8")
        except UnicodeDecodeError as error:
            raise ValueError(f"{_prefix(source)}not a UTF-8 text file (byte {error.start} cannot be decoded)") from None
    return text


def _parsed(parse, text, source, kind: str, max_depth: int):
    text = _decoded(text, source)
    try:
        value = parse(text)
    except RecursionError:
        value = None
        too_deep = True
    except ValueError as error:  # JSONDecodeError, TOMLDecodeError, an integer of 5,000 digits
        detail = "it is empty" if not text.strip() else " ".join(str(error).split())
        raise ValueError(f"{_prefix(source)}not valid {kind} ({detail})") from None
    else:
        too_deep = _too_deep(value, max_depth)
    if too_deep:
        raise ValueError(f"{_prefix(source)}not valid {kind}: nested too deeply (more than {max_depth} levels)")
    return value


def loads_json(text, source=None, max_depth: int = MAX_DEPTH):
    """The JSON value of ``text`` (str or UTF-8 bytes); ``source`` (a path, a flag) heads every error."""
    return _parsed(json.loads, text, source, "JSON", max_depth)


def loads_toml(text, source=None, max_depth: int = MAX_DEPTH) -> dict:
    """The TOML document of ``text`` (str or UTF-8 bytes) as a dict; errors as ``loads_json``'s."""
    return _parsed(tomllib.loads, text, source, "TOML", max_depth)


def _read(path) -> bytes:
    """A missing or unreadable file is an OSError naming it; a FIFO, a device or a file of over
    input_files.MAX_TEXT_BYTES a ValueError (robostrich_suite/input_files.py)."""
    return input_files.read_bytes(path, input_files.MAX_TEXT_BYTES, "text file")


def read_json(path, max_depth: int = MAX_DEPTH):
    """The JSON value in file ``path``; a ValueError naming the file if it is not one."""
    return loads_json(_read(path), os.fspath(path), max_depth)


def read_toml(path, max_depth: int = MAX_DEPTH) -> dict:
    """The TOML document in file ``path``; a ValueError naming the file if it is not one."""
    return loads_toml(_read(path), os.fspath(path), max_depth)
