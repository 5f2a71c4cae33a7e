"""Where the commands write, as a hostile user or a full disk tests it: a label is a name and never
a way out of --out; a location that cannot be written (over PATH_MAX, a name over 255 bytes, under
a regular file) is one line before any work, with nothing made; any legal file name can be
written; a disk that fills up is one line naming the file, exit 2, with no partial file left;
a draw that keeps no pose writes no target file.

Commands run as installed scripts, side by side where they are independent.
"""
import os
import pathlib
import resource
import subprocess

import pytest

import conftest
from conftest import finish, run_in_one_process, start


# Every command that takes --out, with what else it needs to get as far as writing; for targets and
# train enough work that a check made after it would time the test out.
OUT_COMMANDS = {
    "robostrich-train": (["--quiet", "--plan", "lesson1:100000000"], ""),
    "robostrich-evaluate": (["missing.ckpt"], ""),
    "robostrich-play": ([], ""),
    "robostrich-movement": ([], ""),
    "robostrich-workspace": ([], ""),
    "robostrich-layouts": ([], ""),
    "robostrich-targets": (["--samples", "1000000"], "t.npz"),
    "robostrich-walk": ([], ""),
    "robostrich-gait": ([], "g.csv"),
    "robostrich-stabilize": ([], ""),
    "robostrich-gap": ([], ""),
    "robostrich-export-xml": ([], ""),
    "robostrich-design": (["--trials", "1"], ""),
    "robostrich-robustness": (["robostrich"], ""),
    "robostrich-sweep": ([], ""),
}


def one_line_error(result, *fragments):
    """Exit 2 and exactly one stderr line, `NAME: error: ...` holding every fragment."""
    name = os.path.basename(result.args[0])
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2 and len(lines) == 1, (name, result.returncode, result.stderr[-3000:])
    assert lines[0].startswith(f"{name}: error: "), lines[0]
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]


def shown_lines(stderr: str) -> list:
    """stderr as a terminal shows it: each line's text after its last carriage return (where a
    progress bar redraws itself), blank ones left out."""
    return [shown for shown in (line.rsplit("\r", 1)[-1].rstrip() for line in stderr.split("\n")) if shown]


def every_file(directory: pathlib.Path) -> list:
    return sorted(str(p.relative_to(directory)) for p in directory.rglob("*"))


def test_an_evaluation_label_is_a_name_not_a_path(tmp_path):
    """A label starts the report files' names: '../../escaped' would write them outside --out."""
    out = tmp_path / "a" / "b" / "D"
    cases = {"../../escaped": "no '/'", "sub/name": "no '/'", "..": "not '..'", "": "no '/'",
             "x" * 101: "at most 100 bytes", "lookup": "lookup baseline"}
    results = run_in_one_process({label: ("robostrich-evaluate", ["CK.ckpt", "--out", out, f"--label={label}"])
                                  for label in cases}, cwd=tmp_path)
    for label, result in results.items():
        one_line_error(result, "--label", cases[label])
    assert every_file(tmp_path) == []


def test_a_draw_that_keeps_no_pose_writes_no_target_file(tmp_path):
    """One draw without tuning towards level keeps no pose: a target file of none would be written
    and exit 0 (every task that loads it would fail later); refused, one line after the bar."""
    result = finish(start("robostrich-targets", "--samples", "1", "--seek-level-time", "0", "--workers", "1",
                          "--out", tmp_path / "zero.npz"))
    lines = shown_lines(result.stderr)
    assert result.returncode == 2 and lines[-1].startswith("robostrich-targets: error: none of the 1 poses"), \
        result.stderr[-3000:]
    assert all(line.startswith("actuated workspace") for line in lines[:-1]), lines  # the finished draw's bar
    assert "zero.npz" in lines[-1] and every_file(tmp_path) == []


def test_outputs_that_cannot_be_written_are_refused_before_any_work_and_nothing_is_made(tmp_path):
    """Every command that takes --out checks it first (robostrich_suite/outputs.py): under a regular
    file, over PATH_MAX (which once made 20 nested directories before failing), a name over 255
    bytes. Each refusal names --out; targets and train would otherwise draw or train for hours."""
    regular = tmp_path / "somefile.txt"
    regular.write_text("")
    deep = "/".join(["d"] * 2100)  # 4199 bytes
    cases, fragments = {}, {}
    for name, (args, file_name) in OUT_COMMANDS.items():
        under_file = regular / "sub" / file_name if file_name else regular / "sub"
        cases[name, "under_file"] = (name, [*args, "--out", under_file])
        fragments[name, "under_file"] = ["--out", "somefile.txt is a file"]
    for name in ("robostrich-train", "robostrich-targets", "robostrich-walk", "robostrich-gait"):
        args, file_name = OUT_COMMANDS[name]
        cases[name, "path_max"] = (name, [*args, "--out", f"{deep}/{file_name or 'o'}"])
        fragments[name, "path_max"] = ["--out", "bytes long"]
        cases[name, "name_max"] = (name, [*args, "--out", "n" * 256 + "/" + (file_name or "o")])
        fragments[name, "name_max"] = ["--out", "over the 255"]
    results = run_in_one_process({f"{name} {case}": command for (name, case), command in cases.items()}, cwd=tmp_path)
    for (name, case), what in fragments.items():
        line = one_line_error(results[f"{name} {case}"], *what)
        assert len(line) < 400, (name, case, line)  # the long path is shortened in the line
    assert every_file(tmp_path) == ["somefile.txt"]


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes in a read-only directory: nothing to refuse")
def test_a_read_only_output_directory_is_refused_before_the_draw(tmp_path):
    locked = tmp_path / "locked"
    locked.mkdir(mode=0o555)
    processes = [start("robostrich-targets", "--samples", "1000000", "--out", locked / "t.npz"),
                 start("robostrich-walk", "--out", locked / "walk")]
    for process in processes:
        one_line_error(finish(process, timeout=300), "--out", "cannot write in")
    assert every_file(locked) == []


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
        "walk": (start_with_a_full_disk("robostrich-walk", "--seconds", "2", "--no-progress",
                                         "--out", tmp_path / "walk"),
                 ["File too large", str(tmp_path / "walk" / "walk.rrd")]),
        "play": (start_with_a_full_disk("robostrich-play", "--num-targets", "1", "--out", tmp_path / "play"),
                 ["File too large", str(tmp_path / "play" / "robostrich_track.rrd")]),
        "train": (start_with_a_full_disk("robostrich-train", *TINY_TRAIN, "--out", tmp_path / "train"),
                  ["File too large: " + str(tmp_path / "train"), "checkpoint.ckpt"]),
    }
    for name, (process, fragments) in processes.items():
        one_line_error(finish(process), *fragments)
    assert every_file(tmp_path / "walk") == [] and every_file(tmp_path / "play") == []
    left = every_file(tmp_path / "train")
    assert not [p for p in left if "ckpt" in p or "partial" in p or "tmp" in p], left  # no checkpoint, no partial
