"""A policy file that cannot act is refused when it is read, in one line naming the file and what
is wrong with it (metadata nested too deeply, weights of the wrong shape or NaN), before
robostrich-play creates its output folder."""
import io
import json
import os
import pathlib
import zipfile

import numpy as np
import pytest

from robostrich_suite import policies
from conftest import finish, start



def _shipped() -> dict:
    with np.load(policies.SHIPPED["robostrich"]) as data:
        return {key: data[key] for key in data.files}


def _damaged(tmp_path) -> dict:
    """{file name: (path, words its error must hold)}: the shipped policy damaged one way each."""
    arrays = _shipped()
    meta = json.loads(str(arrays["meta"]))
    observed = sum(size for _, size in meta["observation_layout"])
    deep = json.dumps(meta)[:-1] + ', "deep": ' + "[" * 100_000 + "]" * 100_000 + "}"
    cases = {
        "deepmeta.npz": (dict(meta=np.array(deep)), ["nested too deeply"]),
        "nanweights.npz": (dict(hidden_1_w=np.full_like(arrays["hidden_1_w"], np.nan)), ["hidden_1_w", "NaN"]),
        "wrongshape.npz": (dict(hidden_0_w=arrays["hidden_0_w"][:-3]),
                           ["hidden_0_w", f"expected ({observed}, 64)"]),
        "wrongactions.npz": (dict(mean_w=arrays["mean_w"][:, :4]), ["mean_w", "expected (64, 9)"]),
        "intweights.npz": (dict(mean_b=np.zeros(9, np.int64)), ["mean_b", "int64"]),
        "listmeta.npz": (dict(meta=np.array("[1]")), ["metadata", "list"]),
        "layoutless.npz": (dict(meta=np.array(json.dumps({**meta, "observation_layout": "abc"}))),
                           ["observation layout"]),
    }
    written = {}
    for name, (changes, words) in cases.items():
        np.savez(tmp_path / name, **{**arrays, **changes})
        written[name] = (tmp_path / name, words)
    return written


def test_a_damaged_policy_file_is_named_with_what_is_wrong(tmp_path):
    for name, (path, words) in _damaged(tmp_path).items():
        with pytest.raises(ValueError) as caught:
            policies.read_policy(path)
        message = str(caught.value)
        assert message.startswith(f"{path}: ") and all(w in message for w in words), (name, message)
        assert "\n" not in message
    np.savez(tmp_path / "whole.npz", **_shipped())
    assert policies.read_policy(tmp_path / "whole.npz").observation_size > 0


def test_play_refuses_a_damaged_policy_before_making_its_folder(tmp_path):
    damaged = _damaged(tmp_path)
    names = ("deepmeta.npz", "nanweights.npz", "wrongshape.npz")
    processes = {name: start("robostrich-play", "--policy", damaged[name][0], "--out", tmp_path / f"out_{name}",
                             "--num-targets", "1", "--no-rerun") for name in names}
    for name, process in processes.items():
        result = finish(process)
        lines = result.stderr.strip().splitlines()
        assert result.returncode == 2 and len(lines) == 1, (name, result.stderr[-3000:])
        assert lines[0].startswith(f"robostrich-play: error: {damaged[name][0]}: "), lines[0]
        assert not os.path.exists(tmp_path / f"out_{name}"), name


def _claims_huge_shape(path) -> None:
    """A policy archive whose member's header claims 10^12 entries it does not hold."""
    arrays = _shipped()
    buffer = io.BytesIO()
    np.lib.format.write_array_header_1_0(buffer, {"descr": "<f4", "fortran_order": False, "shape": (10 ** 12,)})
    with zipfile.ZipFile(path, "w") as archive:
        for key, value in arrays.items():
            member = io.BytesIO()
            np.save(member, value)
            archive.writestr(f"{key}.npy", member.getvalue())
        archive.writestr("mean_b.npy", buffer.getvalue() + b"\0" * 64)


def _unpacks_big(path) -> None:
    """A small archive one of whose members unpacks to more than a policy file may hold."""
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        with archive.open("meta.npy", "w", force_zip64=True) as member:
            np.lib.format.write_array_header_1_0(member, {"descr": "|u1", "fortran_order": False,
                                                          "shape": (policies.MAX_POLICY_BYTES + 1,)})
            zeros = bytes(1 << 20)
            for _ in range(policies.MAX_POLICY_BYTES // len(zeros) + 1):
                member.write(zeros)


def _damaged_deflate(path) -> None:
    arrays = _shipped()
    np.savez_compressed(path, **arrays)
    data = bytearray(path.read_bytes())
    middle = len(data) // 2
    data[middle:middle + 64] = bytes(64)
    path.write_bytes(bytes(data))


def test_a_policy_that_is_no_regular_file_or_unpacks_past_its_bound_is_refused_before_it_is_read(tmp_path):
    """A FIFO (opening it would wait for a writer), /dev/zero (it never ends), a member claiming
    10^12 entries (numpy would allocate them first), a small archive that unpacks past the bound,
    a damaged deflate stream: each one ValueError naming the file, nothing read without bound."""
    fifo = tmp_path / "fifo.npz"
    os.mkfifo(fifo)
    cases = {fifo: "a FIFO", pathlib.Path("/dev/zero"): "a character device",
             tmp_path / "huge.npz": "claims shape (1000000000000,)", tmp_path / "bomb.npz": "unpack",
             tmp_path / "deflate.npz": "not a policy file"}
    _claims_huge_shape(tmp_path / "huge.npz")
    _unpacks_big(tmp_path / "bomb.npz")
    assert (tmp_path / "bomb.npz").stat().st_size < policies.MAX_POLICY_BYTES // 100
    _damaged_deflate(tmp_path / "deflate.npz")
    for path, words in cases.items():
        with pytest.raises(ValueError) as caught:
            policies.read_policy(path)
        message = str(caught.value)
        assert message.startswith(f"{path}: ") and words in message and "\n" not in message, message


def test_commands_given_a_fifo_or_a_device_answer_at_once_in_one_line(tmp_path):
    """robostrich-evaluate, -play and -robustness, as installed, given a FIFO nobody writes to or
    /dev/zero: one line naming it, exit 2 (they used to wait for ever, or read until memory ran out)."""
    fifo = tmp_path / "fifo.npz"
    os.mkfifo(fifo)
    commands = {"evaluate_fifo": ("robostrich-evaluate", [fifo, "--out", tmp_path / "e"]),
                "evaluate_zero": ("robostrich-evaluate", ["/dev/zero", "--out", tmp_path / "z"]),
                "play": ("robostrich-play", ["--policy", fifo, "--out", tmp_path / "p"]),
                "robustness": ("robostrich-robustness", [fifo, "--out", tmp_path / "r"])}
    processes = {case: start(name, *args) for case, (name, args) in commands.items()}
    for case, process in processes.items():
        result = finish(process, timeout=120)
        name, args = commands[case]
        lines = result.stderr.strip().splitlines()
        assert result.returncode == 2 and len(lines) == 1, (case, result.stderr[-3000:])
        assert lines[0].startswith(f"{name}: error: {args[1 if name == 'robostrich-play' else 0]}"), lines[0]
        assert "regular file" in lines[0], lines[0]
