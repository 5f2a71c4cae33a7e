"""Where the commands write, as a hostile user or a full disk tests it: any legal file name can be
written; a disk that fills up is one line naming the file, exit 2, with no partial file left.

Commands run as installed scripts, side by side where they are independent.
"""
import os
import pathlib
import resource
import subprocess

import pytest

import conftest
from conftest import finish, start

pytestmark = pytest.mark.usefixtures("shared_jax_cache")


def one_line_error(result, *fragments):
    """Exit 2 and exactly one stderr line, `NAME: error: ...` holding every fragment."""
    name = os.path.basename(result.args[0])
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2 and len(lines) == 1, (name, result.returncode, result.stderr[-3000:])
    assert lines[0].startswith(f"{name}: error: "), lines[0]
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]


def every_file(directory: pathlib.Path) -> list:
    return sorted(str(p.relative_to(directory)) for p in directory.rglob("*"))


def test_a_file_name_of_250_bytes_is_written(tmp_path):
    """Legal names up to 255 bytes: the atomic writer's temporary name must not pass 255 itself."""
    name = "g" * 246 + ".csv"
    result = finish(start("robostrich-gait", "--out", tmp_path / name))
    assert result.returncode == 0, result.stderr[-3000:]
    assert every_file(tmp_path) == [name] and (tmp_path / name).read_text().startswith("#")


def start_with_a_full_disk(name, *args, limit_bytes=64 * 1024, cwd=None) -> subprocess.Popen:
    """The installed command with every file it writes limited to ``limit_bytes`` (``ulimit -f``,
    SIGXFSZ ignored as Python does: a write past it fails with "File too large", as on a full
    disk). Its own XLA cache: writes to a shared one would fail too."""
    def limit():
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    environment = {k: v for k, v in conftest.COMMAND_ENVIRONMENT.items() if not k.startswith("JAX_")}
    return subprocess.Popen([conftest.console_script(name), *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=environment, cwd=cwd, preexec_fn=limit)


TINY_TRAIN = ["--plan", "lesson1:100", "--hidden-sizes", "16,16", "--batch-size", "16", "--min-replay-size", "50",
              "--num-eval-targets", "1", "--final-eval-targets", "1", "--track-task", "", "--quiet",
              "--no-figures"]


def test_a_full_disk_is_one_line_naming_the_file_and_leaves_no_partial_file(tmp_path):
    """Rerun writes a recording from a thread of its own and only logs a failed write (32 lines,
    then exit 1); training's checkpoints failed without a file name. Now: exit 2, one line naming
    the file, and no partial file anywhere."""
    processes = {
        "walk": (start_with_a_full_disk("robostrich-walk", "--seconds", "2", "--out", tmp_path / "walk"),
                 ["File too large", str(tmp_path / "walk" / "walk.rrd")]),
        "play": (start_with_a_full_disk("robostrich-play", "--num-targets", "1", "--out", tmp_path / "play"),
                 ["File too large", str(tmp_path / "play" / "policy_track.rrd")]),
        "train": (start_with_a_full_disk("robostrich-train", *TINY_TRAIN, "--out", tmp_path / "train"),
                  ["File too large: " + str(tmp_path / "train"), "checkpoint.ckpt"]),
    }
    for name, (process, fragments) in processes.items():
        one_line_error(finish(process), *fragments)
    assert every_file(tmp_path / "walk") == [] and every_file(tmp_path / "play") == []
    left = every_file(tmp_path / "train")
    assert not [p for p in left if "ckpt" in p or "partial" in p or "tmp" in p], left  # no checkpoint, no partial
