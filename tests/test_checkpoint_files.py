"""The checkpoint file (agents/checkpoint.py): data only, so a crafted file is refused and never run.

Crafted files here carry a payload that creates a marker file when unpickled: a checkpoint of
the pickled format (valid header and checksum) and one of this format whose .npz holds an object
array. Both are refused in one line naming the file, and the marker never appears."""
import hashlib
import io
import json
import pickle
import struct

import numpy as np
import pytest

from agents import checkpoint

from conftest import finish, start


class Marker:
    """Unpickled, it creates the file ``path`` (what a hostile payload could do with any call)."""

    def __init__(self, path):
        self.path = str(path)

    def __reduce__(self):
        return open, (self.path, "w")


def write_raw(path, header: dict, arrays: dict, magic: bytes = checkpoint.MAGIC) -> None:
    """A file in this format's layout with a valid checksum, whatever its header and arrays hold."""
    body = io.BytesIO()
    np.savez(body, **arrays)  # savez pickles object arrays: what a crafted file may do
    text = json.dumps(header).encode()
    content = struct.pack("<Q", len(text)) + text + body.getvalue()
    path.write_bytes(magic + hashlib.sha256(content).digest() + content)


def read_parts(path) -> tuple:
    """(JSON header, .npz body) of a file in this format's layout."""
    data = path.read_bytes()
    start = len(checkpoint.MAGIC) + 32
    (length,) = struct.unpack_from("<Q", data, start)
    return json.loads(data[start + 8:start + 8 + length]), data[start + 8 + length:]


def test_a_checkpoint_gives_back_the_data_it_was_given_with_its_types(tmp_path):
    """Tuples stay tuples, numpy scalars and arrays keep their dtypes, big ints and NaN survive, a
    key starting with "$" is no marker; the header is JSON naming the format version, the arrays
    lie in an .npz that numpy reads without pickle."""
    payload = {"counts": (1, 2, (3, "x")), "list": [None, True, 2.5], "big": 2 ** 100, "nan": float("nan"),
               "scalar": np.float32(0.1), "flag": np.bool_(True), "$array": "not a marker",
               "arrays": {"f": np.arange(6, dtype=np.float32).reshape(2, 3), "i": np.array([-1], np.int64),
                          "zero_d": np.array(7, np.uint32), "empty": np.zeros((0, 4))}}
    path = tmp_path / "data.ckpt"
    checkpoint.save(str(path), payload, {"seed": 3, "sizes": (32, 32)})
    loaded = checkpoint.load(str(path), {"seed": 3, "sizes": [32, 32]})
    assert loaded["counts"] == (1, 2, (3, "x")) and loaded["list"] == [None, True, 2.5]
    assert loaded["big"] == 2 ** 100 and np.isnan(loaded["nan"]) and loaded["$array"] == "not a marker"
    assert type(loaded["scalar"]) is np.float32 and loaded["scalar"] == np.float32(0.1)
    assert type(loaded["flag"]) is np.bool_
    for name, array in payload["arrays"].items():
        assert loaded["arrays"][name].dtype == array.dtype and loaded["arrays"][name].shape == array.shape
        np.testing.assert_array_equal(loaded["arrays"][name], array)
    header, body = read_parts(path)
    with np.load(io.BytesIO(body), allow_pickle=False) as arrays:
        assert len(arrays.files) == 6  # the four arrays and the two numpy scalars
    assert header["format_version"] == checkpoint.FORMAT_VERSION == 3
    assert header["fingerprint"]["seed"] == 3


def test_save_refuses_what_is_not_data_and_leaves_no_file(tmp_path):
    path = tmp_path / "x.ckpt"
    for payload, named in (({"a": np.array([object()], dtype=object)}, "payload.a"), ({"f": print}, "payload.f"),
                           ({"d": {1: 2}}, "payload.d"), ({"m": Marker(tmp_path / "m")}, "payload.m")):
        with pytest.raises(TypeError, match=named):
            checkpoint.save(str(path), payload, {})
    assert list(tmp_path.iterdir()) == []


def test_a_checkpoint_of_another_format_version_is_refused_in_one_line(tmp_path):
    path = tmp_path / "v2.ckpt"
    write_raw(path, {"format_version": 2, "fingerprint": {}, "payload": {}}, {})
    with pytest.raises(checkpoint.CheckpointError) as refused:
        checkpoint.load(str(path))
    message = str(refused.value)
    assert "v2.ckpt is a checkpoint of format version 2" in message and "reads version 3" in message
    assert "\n" not in message


def test_pickled_checkpoints_and_object_arrays_are_refused_without_running_them(tmp_path):
    """An old pickled checkpoint (valid header and checksum) and a new-format one whose .npz holds a
    pickled object array: robostrich-evaluate exits 2 with one line naming the file, the Python
    reader raises CheckpointError, and neither payload ever runs."""
    markers = {name: tmp_path / f"{name}_ran" for name in ("pickled", "objects")}

    def pickled_record(marker):
        return pickle.dumps({"format_version": 2, "fingerprint": {"seed": 0}, "payload": Marker(marker)})

    body = pickled_record(markers["pickled"])
    pickled = tmp_path / "checkpoint.pkl"
    pickled.write_bytes(checkpoint.PICKLE_MAGIC + hashlib.sha256(body).digest() + body)
    objects = tmp_path / "objects.ckpt"
    write_raw(objects, {"format_version": checkpoint.FORMAT_VERSION, "fingerprint": {"seed": 0},
                        "payload": {"learner": {"$array": "0"}}},
              {"0": np.array([Marker(markers["objects"])], dtype=object)})
    # The crafted payloads are live: unpickled, each would create its marker (here another one).
    pickle.loads(pickled_record(tmp_path / "proof_ran"))
    np.load(io.BytesIO(read_parts(objects)[1]), allow_pickle=True)["0"]
    assert (tmp_path / "proof_ran").exists() and markers["objects"].exists()
    markers["objects"].unlink()

    reasons = {pickled: "written with pickle", objects: "allow_pickle=False"}
    processes = {path: start("robostrich-evaluate", path, "--out", tmp_path / "evaluation") for path in reasons}
    for path, process in processes.items():
        result = finish(process)
        assert result.returncode == 2, result.stderr[-3000:]
        lines = result.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("robostrich-evaluate: error: "), result.stderr[-3000:]
        assert str(path) in lines[0] and reasons[path] in lines[0], lines[0]
    for path, reason in reasons.items():
        with pytest.raises(checkpoint.CheckpointError, match=reason) as refused:
            checkpoint.load(str(path))
        assert str(path) in str(refused.value) and "\n" not in str(refused.value)
    assert not any(marker.exists() for marker in markers.values())
    assert not (tmp_path / "evaluation").exists()


def test_a_run_directory_of_pickled_checkpoints_is_neither_resumed_nor_trained_over(tmp_path):
    """robostrich-train names the pickled checkpoints an earlier version left in --out and stops."""
    out = tmp_path / "run"
    (out / "curriculum").mkdir(parents=True)
    (out / "curriculum" / checkpoint.PICKLED_FILE_NAME).write_bytes(checkpoint.PICKLE_MAGIC)
    processes = [start("robostrich-train", "--plan", "lesson1:10", "--no-baseline", "--quiet", "--out", out, *resume)
                 for resume in ([], ["--resume"])]
    for process in processes:
        result = finish(process)
        assert result.returncode == 2, result.stderr[-3000:]
        line = result.stderr.strip().splitlines()[-1]
        assert "written with pickle" in line and "curriculum/checkpoint.pkl" in line, line
    assert sorted(p.name for p in out.rglob("*")) == ["checkpoint.pkl", "curriculum"]
