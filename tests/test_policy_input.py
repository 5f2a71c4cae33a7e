"""A policy file that cannot act is refused when it is read, in one line naming the file and what
is wrong with it (metadata nested too deeply, weights of the wrong shape or NaN), before
robostrich-play creates its output folder."""
import json
import os

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
