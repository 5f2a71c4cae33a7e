"""The installed console scripts, run as a user runs them: exit status and what reaches stderr.

Success: status 0, no traceback and no dumped return value on stderr.  An
expected user error: non-zero status and one line `robostrich-X: error: ...`
(after argparse's usage lines for a usage error), no traceback.
"""
import json
import re
import os
import shutil
import subprocess
import sys

import pytest

from agents import checkpoint
from agents.robostrich.evaluate import evaluation
from robostrich_suite import targets
from robostrich_suite.model import layouts

from conftest import finish, run_in_one_process, start

TINY_TRAIN = ["--plan", "lesson1:250", "--no-baseline", "--hidden-sizes", "16,16", "--batch-size", "16",
              "--min-replay-size", "50", "--num-eval-targets", "1", "--final-eval-targets", "1", "--quiet",
              "--no-rerun", "--no-figures"]




def call(name, *args, cwd=None):
    return finish(start(name, *args, cwd=cwd))


def assert_succeeded(result):
    name = os.path.basename(result.args[0])
    assert result.returncode == 0, f"{name} exited {result.returncode}; stderr:\n{result.stderr[-3000:]}"
    assert "Traceback" not in result.stderr, result.stderr[-3000:]
    assert not result.stderr.lstrip().startswith(("{", "[", "(")), f"{name} dumped its result: {result.stderr[:300]}"
    assert len(result.stderr) < 2000, f"{name} wrote {len(result.stderr)} characters to stderr"


def assert_user_error(result, *fragments):
    """Non-zero status; the last stderr line is the one-line error (argparse puts its usage above)."""
    name = os.path.basename(result.args[0])
    assert result.returncode not in (0, None), f"{name} succeeded; stdout:\n{result.stdout[-2000:]}"
    assert "Traceback" not in result.stderr, result.stderr[-3000:]
    lines = result.stderr.strip().splitlines()
    assert lines and lines[-1].startswith(f"{name}: error: "), result.stderr[-3000:]
    if not lines[0].startswith("usage:"):  # not an argparse usage error: the error line is all there is
        assert len(lines) == 1, result.stderr
    for fragment in fragments:
        assert fragment in lines[-1], (fragment, lines[-1])
    return lines[-1]


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    """One tiny `robostrich-train` run: (its result, its run directory)."""
    out = tmp_path_factory.mktemp("cli") / "run"
    return call("robostrich-train", *TINY_TRAIN, "--out", out), out


def kind_of(line: str) -> str:
    """The evaluation a summary line is about (after the run's label column, before the colon)."""
    return line[11:].split(":")[0].strip()


def test_train_exits_zero_and_writes_its_run(trained):
    result, out = trained
    assert_succeeded(result)
    for name in ("config.json", "summary.json", "curriculum/checkpoint.ckpt", "evaluation/curriculum_heldout.json"):
        assert (out / name).stat().st_size > 0, name
    lines = result.stdout.strip().splitlines()  # a few lines a person reads; the JSON stays in the files
    assert lines[0].startswith("curriculum ") and "% reached (" in lines[0] and "within 1 cm and 2 deg" in lines[0]
    assert any(line.startswith("lookup ") for line in lines) and "{" not in result.stdout
    assert [kind_of(line) for line in lines[:5]] == list(evaluation.KIND_NAMES.values())
    assert lines[-1].startswith(f"wrote {out}/: summary.json") and len(lines) <= 11, result.stdout
    assert not (out / ".lock").exists()  # a clean end leaves only the results


def test_resuming_a_finished_run_shows_its_results_again(trained):
    _, out = trained
    before = {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()}
    result = call("robostrich-train", *TINY_TRAIN, "--out", out, "--resume")
    assert_succeeded(result)
    lines = result.stdout.strip().splitlines()
    assert lines[0] == f"{out} is finished; nothing to resume" and lines[1].startswith("curriculum "), result.stdout
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()} == before  # nothing evaluated again
    assert "step/s" not in result.stderr, result.stderr


def test_evaluate_exits_zero_on_a_checkpoint(trained, tmp_path):
    _, out = trained
    result = call("robostrich-evaluate", out / "curriculum" / "checkpoint.ckpt", "--out", tmp_path / "ev",
                  "--num-targets", "1", "--no-rerun", "--no-figures")
    assert_succeeded(result)
    assert (tmp_path / "ev" / "summary.json").stat().st_size > 0
    lines = result.stdout.strip().splitlines()
    assert [line.split()[0] for line in lines[:-1] if not line.startswith(" ")] == ["eval", "lookup"], result.stdout
    assert [kind_of(line) for line in lines[:-1]] == 2 * list(evaluation.KIND_NAMES.values()), result.stdout
    assert lines[-1] == f"wrote {tmp_path / 'ev'}/: summary.json, reports", result.stdout
    # the evaluation's progress bar, ending at all its episodes (what it shows before depends on the speed)
    assert re.search(r"evaluation: 100%.* (\d+)/\1 \[", result.stderr) and "episode" in result.stderr, result.stderr
    # its first line, before the seconds of rebuilding the run: what it will evaluate
    assert result.stderr.startswith(f"evaluating {out / 'curriculum' / 'checkpoint.ckpt'} on robostrich "
                                    "(ventral_slips): held-out targets, new targets, the track task, and the lookup"), \
        result.stderr


def test_a_checkpoint_whose_stored_plan_is_damaged_is_named_in_one_line(trained, tmp_path):
    _, out = trained
    record = checkpoint._read_record(str(out / "curriculum" / "checkpoint.ckpt"))
    damaged = tmp_path / "damaged.ckpt"
    checkpoint.save(str(damaged), record["payload"], {**record["fingerprint"], "plan": "robostrich/lesson1:abc"})
    result = call("robostrich-evaluate", damaged, "--out", tmp_path / "ev", "--num-targets", "1")
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2 and len(lines) == 1, result.stderr[-3000:]
    assert lines[0].startswith(f"robostrich-evaluate: error: {damaged} holds a damaged plan: "), lines[0]


def test_train_runs_on_the_quadruped_and_on_another_layout(tmp_path):
    """A plan on robostrich_a1 no longer falls through to dm_control; --layout names a layout."""
    processes = {"a1": start("robostrich-train", *TINY_TRAIN, "--domain", "robostrich_a1", "--out", tmp_path / "a1"),
                 "layout": start("robostrich-train", *TINY_TRAIN, "--layout", "antagonist_pairs",
                                 "--out", tmp_path / "layout")}
    results = {name: finish(process) for name, process in processes.items()}
    for name, result in results.items():
        assert_succeeded(result)
        summary = json.loads((tmp_path / name / "summary.json").read_text())["runs"]
        assert set(summary) == {"curriculum", "lookup"}
        assert summary["lookup"]["heldout"]["episodes"] == 1 and "heldout_moving" in summary["curriculum"]
    a1 = json.loads((tmp_path / "a1" / "evaluation" / "curriculum_heldout.json").read_text())
    assert a1["domain"] == "robostrich_a1" and "track" not in json.loads(
        (tmp_path / "a1" / "summary.json").read_text())["runs"]["curriculum"]
    layout = json.loads((tmp_path / "layout" / "evaluation" / "lookup_heldout.json").read_text())
    assert layout["layout"] == "antagonist_pairs"
    assert layout["episodes"][0]["target"] == targets.heldout_targets(layouts.target_file("antagonist_pairs"))[0].tolist()


def test_the_other_scripts_exit_zero(tmp_path):
    runs = {  # cheap real invocations, run side by side
        "robostrich-export-xml": ["--out", tmp_path / "xml"],
        "robostrich-walk": ["--seconds", "0.2", "--no-rrd", "--out", tmp_path / "walk"],
        "robostrich-movement": ["--out", tmp_path / "movement", "--patterns", "lever", "--no-match-travel",
                                "--ramp-time", "0.05", "--no-recording", "--no-progress"],
        "robostrich-workspace": ["--out", tmp_path / "workspace", "--samples", "200", "--edge-samples", "200",
                                 "--actuated-samples", "0", "--no-progress"],
        "robostrich-gait": ["--out", tmp_path / "gait" / "trot.csv"],
        "robostrich-targets": ["--samples", "2", "--workers", "1", "--out", tmp_path / "targets.npz"],  # keeps 1
    }
    processes = {name: start(name, *args) for name, args in runs.items()}
    results = {name: finish(process) for name, process in processes.items()}
    for result in results.values():
        assert_succeeded(result)
    assert (tmp_path / "movement" / "lever.png").exists() and (tmp_path / "workspace" / "workspace.png").exists()
    assert (tmp_path / "walk" / "walk.png").exists()  # --out is a directory for every command
    assert (tmp_path / "xml" / "robostrich_a1.xml").exists() and (tmp_path / "gait" / "trot.csv").exists()
    assert "level-head poses to" in results["robostrich-targets"].stdout


def test_user_errors_give_one_line_and_a_nonzero_status(tmp_path):
    empty = tmp_path / "empty_run"
    empty.mkdir()
    checkpoint.save(str(tmp_path / "whole.ckpt"), {"weights": list(range(2000))}, {"seed": 0})
    data = (tmp_path / "whole.ckpt").read_bytes()
    (tmp_path / "truncated.ckpt").write_bytes(data[:len(data) // 2])
    (tmp_path / "empty.ckpt").write_bytes(b"")
    results = run_in_one_process({  # each only parses, imports and checks
        "resume_empty": ("robostrich-train", ["--resume", "--quiet", "--out", empty]),
        "checkpoint_every_0": ("robostrich-train", ["--checkpoint-every", "0", "--out", tmp_path / "ck0"]),
        "truncated": ("robostrich-evaluate", [tmp_path / "truncated.ckpt", "--num-targets", "1", "--no-rerun",
                                              "--no-figures"]),
        "empty": ("robostrich-evaluate", [tmp_path / "empty.ckpt", "--num-targets", "1"]),
        "ramp_negative": ("robostrich-movement", ["--ramp-time", "-1", "--out", tmp_path / "mv"]),
        "layout": ("robostrich-train", ["--layout", "tangled", "--quiet", "--out", tmp_path / "lay"]),
        "task": ("robostrich-train", ["--plan", "lesson1:10,lesson9:10", "--quiet", "--out", tmp_path / "task"]),
        "xml_no_out": ("robostrich-export-xml", []),  # no default: it would write into the installed package
        "task_kwargs": ("robostrich-train", ["--task-kwargs", '{"target_sampling": "worst"}', "--quiet",
                                             "--out", tmp_path / "tk"]),
        "lesson_names": ("robostrich-train", ["--long-horizon-lessons", "lesson9", "--quiet", "--out", tmp_path / "ln"]),
        "head_speed": ("robostrich-train", ["--domain", "robostrich_a1", "--task-kwargs",
                                            '{"weights": {"head_vertical_speed": 5}}', "--quiet", "--out", tmp_path / "hs"]),
    })
    assert_user_error(results["resume_empty"], "--resume", "no checkpoint", str(empty))
    assert os.listdir(empty) == []  # nothing started
    assert_user_error(results["checkpoint_every_0"], "--checkpoint-every")
    assert results["checkpoint_every_0"].returncode == 2 and not (tmp_path / "ck0").exists()
    assert_user_error(results["truncated"], "truncated.ckpt", "damaged")
    assert_user_error(results["empty"], "empty.ckpt", "not a SAC checkpoint")
    assert_user_error(results["ramp_negative"], "--ramp-time")
    assert not list(tmp_path.glob("mv/*.rrd"))  # refused before the recording was opened
    assert_user_error(results["layout"], "unknown layout 'tangled'")
    assert_user_error(results["task"], "no task 'lesson9'")
    assert not (tmp_path / "lay").exists() and not (tmp_path / "task").exists()
    assert_user_error(results["xml_no_out"], "--out")
    assert_user_error(results["task_kwargs"], "--task-kwargs", "robostrich/lesson1", "unknown target_sampling 'worst'")
    assert not (tmp_path / "tk").exists()
    assert_user_error(results["lesson_names"], "--long-horizon-lessons names ['lesson9']")
    assert not (tmp_path / "ln").exists()
    # The head-speed term depends on the goal in a way recomputed rewards cannot give: refused, named.
    assert_user_error(results["head_speed"], "weights.head_vertical_speed", "--no-relabel-rewards --her-ratio 0")
    for case in ("resume_empty", "truncated", "empty", "ramp_negative", "layout", "task", "xml_no_out",
                 "task_kwargs", "lesson_names", "head_speed"):
        assert results[case].returncode == 2, (case, results[case].stderr)


def test_read_fingerprint_checks_the_file(tmp_path):
    path = tmp_path / "c.ckpt"
    checkpoint.save(str(path), {"x": 1}, {"seed": 3})
    assert checkpoint.read_fingerprint(str(path)) == {"seed": 3}
    data = path.read_bytes()
    for damaged in (b"", data[:20], data[:-1], data[:-1] + bytes([data[-1] ^ 1])):
        path.write_bytes(damaged)
        with pytest.raises(checkpoint.CheckpointError, match="c.ckpt"):
            checkpoint.read_fingerprint(str(path))


def test_rejected_resume_leaves_the_run_unchanged(trained, tmp_path):
    _, out = trained
    run = tmp_path / "run"
    shutil.copytree(out, run)
    before = {p: p.read_bytes() for p in run.rglob("*") if p.is_file()}
    other = [a if a != "16,16" else "32,32" for a in TINY_TRAIN]  # another network: another configuration
    result = call("robostrich-train", *other, "--out", run, "--resume")
    assert_user_error(result, "different configuration", "hidden_sizes")
    assert result.returncode == 2
    after = {p: p.read_bytes() for p in run.rglob("*") if p.is_file()}
    assert after.keys() == before.keys()
    assert after[run / "config.json"] == before[run / "config.json"]
    assert after == before


def test_import_without_display_prints_no_glfw_error():
    """No DISPLAY and no MUJOCO_GL: the package picks a headless backend itself."""
    env = {k: v for k, v in os.environ.items() if k not in ("MUJOCO_GL", "DISPLAY", "WAYLAND_DISPLAY")}
    result = subprocess.run([sys.executable, "-c", "import os, robostrich_suite; print(os.environ['MUJOCO_GL'])"],
                            env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "GLFW" not in result.stderr and "DISPLAY" not in result.stderr, result.stderr
    assert result.stdout.strip() in ("egl", "osmesa", "disable")


def test_at_a_terminal_a_command_notes_its_loading_then_erases_the_note():
    """The seconds a command's libraries take to load are not silent at a terminal; the note is gone
    before the command's own first line (and never reaches a file or a pipe)."""
    import pty
    from conftest import console_script
    controller, terminal = pty.openpty()
    process = subprocess.Popen([console_script("robostrich-export-xml"), "--no-such-flag"], stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=terminal)
    os.close(terminal)
    shown = b""
    while True:
        try:
            chunk = os.read(controller, 4096)
        except OSError:  # the command closed its end
            break
        if not chunk:
            break
        shown += chunk
    os.close(controller)
    assert process.wait(timeout=120) == 2
    note = b"robostrich-export-xml: loading its libraries..."
    assert shown.startswith(note + b"\r\x1b[K"), shown
    assert shown[len(note) + 4:].decode().startswith("robostrich-export-xml: error: "), shown
    piped = call("robostrich-export-xml", "--no-such-flag")
    assert "loading" not in piped.stderr and piped.stderr.count("\n") == 1, piped.stderr


def test_training_first_says_what_it_trains_how_short_it_is_and_what_the_bar_shows():
    from agents.robostrich.train import command
    argv = ["--steps", "30000", "--no-baseline", "--out", "runs/quick"]
    args = command.build_parser().parse_args(argv)
    lines = command.start_lines(args, command.prepare(args, argv))
    assert lines[0] == ("training curriculum (lesson1 8,000, lesson2 8,000, lesson3 14,000 control steps) on robostrich "
                        "(ventral_slips), seed 0, into runs/quick/"), lines
    assert lines[1].startswith("30,000 control steps per run are 15 % of the main job's 200,000"), lines
    assert "return is the mean return of the last 20 training episodes, reached the share" in lines[2]
    args = command.build_parser().parse_args([])
    assert len(command.start_lines(args, command.prepare(args, []))) == 2  # the main job's budget: no warning
