"""Atomic, checksummed checkpoints that hold data only and refuse to load into a different configuration.

File layout: MAGIC (8 bytes) | sha256 of what follows (32 bytes) | header length (8 bytes,
little-endian) | header (JSON: format version, fingerprint, payload) | body (an .npz archive of
the payload's arrays, which the header names). Nothing is pickled: reading a checkpoint parses
JSON and loads arrays with ``allow_pickle=False``, so a crafted file can be refused but never run.
Written to a temporary file in the same directory, fsynced, then renamed over the old
checkpoint, so a kill at any moment leaves either the old or the new file, never a torn one.

A payload is plain data: dicts with string keys, lists, tuples, str, int, float, bool, None,
numpy arrays (not of dtype object) and numpy scalars; :func:`save` refuses anything else.
"""
import hashlib
import io
import json
import os
import stat
import struct
import tempfile
import zipfile

import numpy as np

MAGIC = b"RSACKPTZ"
# The magic of the pickled checkpoints of format versions 1-2, refused without being unpickled.
PICKLE_MAGIC = b"RSACKPT1"
# The header and body layout; a checkpoint of another version is refused (version 3: JSON and
# .npz instead of pickle).
FORMAT_VERSION = 3
# A run directory's checkpoint, and the one a run may keep after each lesson: not ".pkl", which
# names the pickled checkpoints of earlier versions (this version does not read them).
FILE_NAME = "checkpoint.ckpt"
LESSON_FILE_NAME = "after_lesson{lessons_done}.ckpt"
PICKLED_FILE_NAME = "checkpoint.pkl"

MAX_CHECKPOINT_BYTES = 8 << 30  # a run's state with its whole replay: far more than 10M transitions take
_LENGTH = struct.Struct("<Q")
# Markers of the header's non-JSON values; a payload's own keys starting with "$" get one more "$".
_ARRAY, _SCALAR, _TUPLE = "$array", "$scalar", "$tuple"


class CheckpointError(ValueError):
    """A checkpoint that is damaged or belongs to another configuration."""


class NotData(TypeError):
    """A value a checkpoint cannot hold: not plain data (module doc)."""


def save(path: str, payload: dict, fingerprint: dict) -> None:
    arrays = {}
    header = {"format_version": FORMAT_VERSION, "fingerprint": _encode(fingerprint, arrays, "fingerprint"),
              "payload": _encode(payload, arrays, "payload")}
    text = json.dumps(header, separators=(",", ":")).encode("utf-8")
    body = io.BytesIO()
    np.savez(body, **arrays)
    digest = hashlib.sha256()
    parts = (_LENGTH.pack(len(text)), text, body.getbuffer())
    for part in parts:
        digest.update(part)
    directory = os.path.dirname(os.path.abspath(path))
    os.makedirs(directory, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".ckpt-", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(MAGIC)
            f.write(digest.digest())
            for part in parts:
                f.write(part)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)  # mkstemp makes it private; a checkpoint is an ordinary output file
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def check_plain(value, where: str = "value") -> None:
    """NotData naming where in ``value`` something is not data a checkpoint holds (module doc)."""
    _encode(value, {}, where)


def _encode(value, arrays: dict, where: str):
    """``value`` as JSON, its arrays moved into ``arrays``; NotData naming ``where`` for what is not plain data."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, float)) and type(value) in (int, float):
        return value
    if isinstance(value, (np.ndarray, np.generic)):
        array = np.asarray(value)
        if array.dtype.hasobject or array.dtype.kind not in "biufcSU":
            raise NotData(f"{where}: a checkpoint holds no arrays of dtype {array.dtype}")
        key = str(len(arrays))
        arrays[key] = array
        return {_SCALAR if isinstance(value, np.generic) else _ARRAY: key}
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            if not isinstance(k, str):
                raise NotData(f"{where}: a checkpoint's dicts have string keys, not {k!r}")
            out["$" + k if k.startswith("$") else k] = _encode(v, arrays, f"{where}.{k}")
        return out
    if isinstance(value, (list, tuple)):
        items = [_encode(v, arrays, f"{where}[{i}]") for i, v in enumerate(value)]
        return items if type(value) is list else {_TUPLE: items}
    raise NotData(f"{where}: a checkpoint holds plain data and arrays, not {type(value).__name__}")


def _decode(value, arrays):
    if isinstance(value, list):
        return [_decode(v, arrays) for v in value]
    if not isinstance(value, dict):
        return value
    if len(value) == 1:
        (key, inner), = value.items()
        if key == _TUPLE and isinstance(inner, list):
            return tuple(_decode(v, arrays) for v in inner)
        if key in (_ARRAY, _SCALAR):
            array = arrays[inner]
            return array[()] if key == _SCALAR else array
    if any(k.startswith("$") and not k.startswith("$$") for k in value):
        raise ValueError(f"unknown marker among {sorted(value)}")
    return {k[1:] if k.startswith("$") else k: _decode(v, arrays) for k, v in value.items()}


class _MemoryFile(io.RawIOBase):
    """A read-only file over bytes already in memory, for np.load: io.BytesIO would copy them (a
    checkpoint is mostly its replay)."""

    def __init__(self, view: memoryview):
        super().__init__()
        self.view, self.position = view, 0

    def readable(self):
        return True

    def seekable(self):
        return True

    def readinto(self, buffer):
        chunk = self.view[self.position:self.position + len(buffer)]
        buffer[:len(chunk)] = chunk
        self.position += len(chunk)
        return len(chunk)

    def seek(self, offset, whence=io.SEEK_SET):
        base = {io.SEEK_SET: 0, io.SEEK_CUR: self.position, io.SEEK_END: len(self.view)}[whence]
        self.position = max(base + offset, 0)
        return self.position

    def tell(self):
        return self.position


class _Arrays(dict):
    """The body's arrays by name, each read (with ``allow_pickle=False``) when the header names it."""

    def __init__(self, archive):
        super().__init__()
        self.archive = archive

    def __missing__(self, key):
        if not isinstance(key, str) or key not in self.archive.files:
            raise ValueError(f"the header names an array {key!r} that the body lacks")
        array = self[key] = self.archive[key]
        return array


def _read_regular_file(path: str) -> bytes:
    """The file's bytes, if it is a regular file of at most MAX_CHECKPOINT_BYTES: opened without
    waiting, so a FIFO is refused instead of waited on, and a device such as /dev/zero is refused
    instead of read without end (CheckpointError naming it)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    with os.fdopen(fd, "rb") as handle:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise CheckpointError(f"{path} is not a regular file (a FIFO, a device or a directory), not a checkpoint")
        if info.st_size > MAX_CHECKPOINT_BYTES:
            raise CheckpointError(f"{path} holds {info.st_size} bytes, more than a checkpoint may ({MAX_CHECKPOINT_BYTES})")
        os.set_blocking(fd, True)
        data = handle.read(MAX_CHECKPOINT_BYTES + 1)
    if len(data) > MAX_CHECKPOINT_BYTES:
        raise CheckpointError(f"{path} holds more than a checkpoint may ({MAX_CHECKPOINT_BYTES} bytes)")
    return data


def _read_record(path: str) -> dict:
    """The stored record after checking header, checksum, layout and format version; CheckpointError if not."""
    return read_with_digest(path)[0]


def read_with_digest(path: str) -> tuple:
    """(record, hex sha256 of its content) after the checks of :func:`_read_record`: the digest names
    this checkpoint's content (a run started from it records it)."""
    data = _read_regular_file(path)
    if data[:len(PICKLE_MAGIC)] == PICKLE_MAGIC:
        raise CheckpointError(f"{path} is a checkpoint of format version 2 or earlier, written with pickle, which "
                              f"this version does not read (loading a pickle can run code); train it again, or "
                              f"use the release that wrote it")
    if len(data) < len(MAGIC) + 32 + _LENGTH.size or data[:len(MAGIC)] != MAGIC:
        raise CheckpointError(f"{path} is not a SAC checkpoint of this package (bad header or truncated)")
    start = len(MAGIC) + 32
    digest, content = data[len(MAGIC):start], memoryview(data)[start:]
    if hashlib.sha256(content).digest() != digest:
        raise CheckpointError(f"{path} is damaged: checksum mismatch (truncated or modified file)")
    try:
        record = _parse(content)
    except Exception as e:  # a valid checksum over a layout this code cannot read: another writer
        raise CheckpointError(f"{path} has a valid checksum but cannot be read: {type(e).__name__}: "
                              f"{' '.join(str(e).split())}") from e
    if record.get("format_version") != FORMAT_VERSION:
        raise CheckpointError(f"{path} is a checkpoint of format version {record.get('format_version')}; this code "
                              f"reads version {FORMAT_VERSION} (train it again, or use the release that wrote it)")
    lacking = [k for k in ("fingerprint", "payload") if not isinstance(record.get(k), dict)]
    if lacking:
        raise CheckpointError(f"{path} lacks its {' and '.join(lacking)} (not a whole checkpoint)")
    return record, digest.hex()


def _parse(content: memoryview) -> dict:
    """The record of a checksummed checkpoint's content: JSON header, then the arrays it names."""
    (length,) = _LENGTH.unpack_from(content)
    end = _LENGTH.size + length
    if end > len(content):
        raise ValueError("the header runs past the end of the file")
    header = json.loads(bytes(content[_LENGTH.size:end]).decode("utf-8"))
    if not isinstance(header, dict):
        raise ValueError("the header is not a JSON object")
    if header.get("format_version") != FORMAT_VERSION:
        return {"format_version": header.get("format_version")}
    body = _MemoryFile(content[end:])
    if not zipfile.is_zipfile(body):  # numpy would read anything else as one array, or a pickle it refuses
        raise ValueError("the body is not an .npz archive")
    body.seek(0)
    with np.load(body, allow_pickle=False) as archive:
        arrays = _Arrays(archive)
        return {"format_version": FORMAT_VERSION, "fingerprint": _decode(header.get("fingerprint"), arrays),
                "payload": _decode(header.get("payload"), arrays)}


def load(path: str, fingerprint: dict = None, current=None) -> dict:
    """Returns the payload; raises CheckpointError if damaged or if `fingerprint` differs from the stored one
    (read through ``current(stored)`` where given: an older fingerprint as this version writes it)."""
    record = _read_record(path)
    if fingerprint is not None:
        stored = record["fingerprint"]
        check_fingerprint(current(stored) if current is not None else stored, fingerprint, path)
    return record["payload"]


def read_fingerprint(path: str) -> dict:
    """The configuration that wrote `path`; raises CheckpointError if the file is damaged (as `load` does)."""
    return _read_record(path)["fingerprint"]


def _flatten(d, prefix=""):
    out = {}
    for k, v in d.items():
        name = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(_flatten(v, name + "."))
        else:
            out[name] = v
    return out


def check_fingerprint(stored: dict, expected: dict, path: str = "checkpoint") -> None:
    a, b = _flatten(stored), _flatten(expected)
    diffs = []
    for k in sorted(set(a) | set(b)):
        va, vb = a.get(k, "<missing>"), b.get(k, "<missing>")
        if _normalise(va) != _normalise(vb):
            diffs.append(f"{k}: checkpoint has {va!r}, this run has {vb!r}")
    if diffs:
        raise CheckpointError(f"{path} was written by a different configuration; " + "; ".join(diffs))


def _normalise(v):
    if isinstance(v, (list, tuple)):
        return tuple(_normalise(x) for x in v)
    return v
