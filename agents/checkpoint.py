"""Atomic, checksummed checkpoints that refuse to load into a different configuration.

File layout: MAGIC (8 bytes) | sha256 of payload (32 bytes) | payload (pickle).
Written to a temporary file in the same directory, fsynced, then renamed over
the old checkpoint, so a kill at any moment leaves either the old or the new
file, never a torn one.
"""
import hashlib
import os
import pickle
import tempfile

MAGIC = b"RSACKPT1"
# The payload's layout; a checkpoint of another version is refused (version 2: the run state
# holds every field a resume reads, the fingerprint no field a reader must fill in).
FORMAT_VERSION = 2


class CheckpointError(ValueError):
    """A checkpoint that is damaged or belongs to another configuration."""


def save(path: str, payload: dict, fingerprint: dict) -> None:
    body = pickle.dumps({"format_version": FORMAT_VERSION, "fingerprint": fingerprint, "payload": payload},
                        protocol=pickle.HIGHEST_PROTOCOL)
    digest = hashlib.sha256(body).digest()
    directory = os.path.dirname(os.path.abspath(path))
    os.makedirs(directory, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=".ckpt-", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(fd, "wb") as f:
            f.write(MAGIC)
            f.write(digest)
            f.write(body)
            f.flush()
            os.fsync(f.fileno())
        os.chmod(tmp, 0o644)  # mkstemp makes it private; a checkpoint is an ordinary output file
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def _read_record(path: str) -> dict:
    """The stored record after checking header, checksum, pickle and format version; CheckpointError if not."""
    return read_with_digest(path)[0]


def read_with_digest(path: str) -> tuple:
    """(record, hex sha256 of its payload) after the checks of :func:`_read_record`: the digest names
    this checkpoint's content (a run started from it records it)."""
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < len(MAGIC) + 32 or data[:len(MAGIC)] != MAGIC:
        raise CheckpointError(f"{path} is not a SAC checkpoint of this package (bad header or truncated)")
    digest, body = data[len(MAGIC):len(MAGIC) + 32], data[len(MAGIC) + 32:]
    if hashlib.sha256(body).digest() != digest:
        raise CheckpointError(f"{path} is damaged: checksum mismatch (truncated or modified file)")
    try:
        record = pickle.loads(body)
    except Exception as e:  # a valid checksum over an unreadable pickle: wrong code version
        raise CheckpointError(f"{path} cannot be unpickled: {e}") from e
    if not isinstance(record, dict) or record.get("format_version") != FORMAT_VERSION:
        version = record.get("format_version") if isinstance(record, dict) else None
        raise CheckpointError(f"{path} is a checkpoint of format version {version}; this code reads version "
                              f"{FORMAT_VERSION} (train it again, or use the release that wrote it)")
    lacking = [k for k in ("fingerprint", "payload") if not isinstance(record.get(k), dict)]
    if lacking:
        raise CheckpointError(f"{path} lacks its {' and '.join(lacking)} (not a whole checkpoint)")
    return record, digest.hex()


def load(path: str, fingerprint: dict = None) -> dict:
    """Returns the payload; raises CheckpointError if damaged or if `fingerprint` differs from the stored one."""
    record = _read_record(path)
    if fingerprint is not None:
        check_fingerprint(record["fingerprint"], fingerprint, path)
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
