"""Every command as a hostile user drives it: bad flags, damaged files, two runs in one
directory, Ctrl-C. The promise (README): exit 0 on success, 2 with one line
`robostrich-X: error: ...` on bad input (no traceback), 130 on Ctrl-C with a checkpoint
written (training) and nothing half-written (the others).

Commands run as installed scripts, side by side where they are independent; the many that stop at
their flags' checks run through the same entry point in one process (``run_in_one_process``).
"""
import json
import math
import os
import pathlib
import shutil
import signal
import time

import numpy as np
import pytest

from agents import checkpoint
from conftest import finish, run_in_one_process, start


TRAIN = ["--plan", "lesson1:300,lesson2:300", "--hidden-sizes", "16,16", "--batch-size", "16", "--min-replay-size", "50",
         "--num-eval-targets", "1", "--final-eval-targets", "1", "--eval-every", "600", "--track-task", "",
         "--quiet", "--no-rerun", "--no-figures"]


def one_line_error(result, *fragments):
    """Exit 2 and exactly one stderr line, `NAME: error: ...` holding every fragment."""
    name = os.path.basename(result.args[0])
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2 and len(lines) == 1, (result.returncode, result.stderr[-3000:])
    assert lines[0].startswith(f"{name}: error: "), lines[0]
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]


def wait_for(condition, what, timeout=400):
    deadline = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.2)


def files(directory: pathlib.Path) -> dict:
    return {p.relative_to(directory): p.read_bytes() for p in directory.rglob("*") if p.is_file()}


FLAG_CASES = {  # (command, arguments, fragments the one line must hold)
    "steps_0": ("robostrich-train", ["--steps", "0"], ["--steps"]),
    "steps_negative": ("robostrich-train", ["--steps", "-100"], ["--steps"]),
    "steps_huge": ("robostrich-train", ["--steps", "1e12"], ["--steps"]),
    "plan_huge": ("robostrich-train", ["--plan", "lesson1:1e12"], ["--plan", "100000000"]),
    "lr_negative": ("robostrich-train", ["--learning-rate", "-1"], ["--learning-rate"]),
    "lr_nan": ("robostrich-train", ["--learning-rate", "nan"], ["--learning-rate", "nan"]),
    "hidden_0": ("robostrich-train", ["--hidden-sizes", "0"], ["--hidden-sizes"]),
    "hidden_negative": ("robostrich-train", ["--hidden-sizes", "-3"], ["--hidden-sizes"]),
    "log_std": ("robostrich-train", ["--log-std-min", "5", "--log-std-max", "-5"], ["--log-std-min", "--log-std-max"]),
    "temperature": ("robostrich-train", ["--init-temperature", "-1"], ["--init-temperature"]),
    "lessons_empty": ("robostrich-train", ["--lessons", ","], ["--lessons"]),
    "replay_huge": ("robostrich-train", ["--max-replay-size", "1000000000000"], ["--max-replay-size", "10000000"]),
    "train_track_task": ("robostrich-train", ["--track-task", "nope"], ["--track-task", "nope"]),
    "train_heldout_track": ("robostrich-train", ["--heldout-task", "track"], ["--heldout-task", "track"]),
    "task_kwargs_far": ("robostrich-train", ["--task-kwargs", '{"target_pool": [[5, 0]]}'],
                        ["--task-kwargs", "far outside any workspace"]),
    "task_kwargs_deep": ("robostrich-train", ["--task-kwargs", "[" * 100_000], ["--task-kwargs", "nested too deeply"]),
    "task_kwargs_weights": ("robostrich-train", ["--task-kwargs", '{"weights": "x"}'],
                            ["--task-kwargs", "weights must be"]),
    "task_kwargs_randomization": ("robostrich-train", ["--task-kwargs", '{"randomization": "yes"}'],
                                  ["--task-kwargs", "randomization must be"]),
    "task_kwargs_time_limit": ("robostrich-train", ["--task-kwargs", '{"time_limit": 1e300}'],
                               ["--task-kwargs", "time_limit", "600"]),
    "plan_fraction": ("robostrich-train", ["--plan", "lesson1:300.9"], ["--plan", "300.9", "whole number"]),
    "hidden_letters": ("robostrich-train", ["--hidden-sizes", "a,b"], ["--hidden-sizes", "'a,b'"]),
    "her_lessons_typo": ("robostrich-train", ["--her-lessons", "lesson1,2"], ["--her-lessons", "'2'"]),
    "abbreviated_flag": ("robostrich-train", ["--learning-rat", "1e-3"], ["--learning-rat"]),
    "evaluate_targets_0": ("robostrich-evaluate", ["x.ckpt", "--num-targets", "0"], ["--num-targets"]),
    "evaluate_targets_negative": ("robostrich-evaluate", ["x.ckpt", "--num-targets", "-3"], ["--num-targets"]),
    "evaluate_new_targets_negative": ("robostrich-evaluate", ["x.ckpt", "--new-targets", "-1"], ["--new-targets"]),
    "evaluate_new_targets_word": ("robostrich-evaluate", ["x.ckpt", "--new-targets", "all"], ["--new-targets", "'all'"]),
    "evaluate_new_target_seed": ("robostrich-evaluate", ["x.ckpt", "--new-target-seed", "-5"], ["--new-target-seed"]),
    "train_new_targets_huge": ("robostrich-train", ["--new-targets", "1e9"], ["--new-targets"]),
    "train_new_target_seed": ("robostrich-train", ["--new-target-seed", "1.5"], ["--new-target-seed"]),
    "train_randomize_twice": ("robostrich-train", ["--randomize", "mass=0.1,mass=0.2"], ["--randomize", "twice"]),
    "train_randomize_empty": ("robostrich-train", ["--randomize", "mass=0.1,,latency=0.2"], ["--randomize", "empty"]),
    "robustness_scales_empty": ("robostrich-robustness", ["robostrich", "--scales", "0,,0.1"], ["--scales", "empty"]),
    "design_study_name_empty": ("robostrich-design", ["--study-name", ""], ["--study-name", "''"]),
    "design_study_name_blank": ("robostrich-design", ["--study-name", "  "], ["--study-name"]),
    "targets_nan": ("robostrich-targets", ["--seek-level-time", "nan", "--out", "t.npz"], ["--seek-level-time"]),
    "movement_nan": ("robostrich-movement", ["--amplitude", "nan"], ["--amplitude"]),
    "movement_inf": ("robostrich-movement", ["--ramp-time", "inf"], ["--ramp-time"]),
    "walk_inf": ("robostrich-walk", ["--seconds", "inf"], ["--seconds"]),
    "walk_long": ("robostrich-walk", ["--seconds", "1e6"], ["--seconds", "600"]),
    "gait_slow": ("robostrich-gait", ["--frequency", "1e-9", "--out", "g.csv"], ["--frequency"]),
    "workspace_settle": ("robostrich-workspace", ["--settle-time", "1e9"], ["--settle-time", "600"]),
    "workspace_samples": ("robostrich-workspace", ["--samples", "1e15"], ["--samples"]),
    "stabilize_far": ("robostrich-stabilize", ["--distance", "-5"], ["--distance"]),
    "stabilize_seeds": ("robostrich-stabilize", ["--seeds", "1000000"], ["--seeds", "1000"]),
    "gap_steps": ("robostrich-gap", ["--steps-per-target", "10000000000"], ["--steps-per-target"]),
    "layouts_stiffness": ("robostrich-layouts", ["--stiffness", "inf"], ["--stiffness"]),
}


@pytest.mark.long
def test_bad_flags_exit_2_with_one_line_naming_the_flag(tmp_path):
    """Nonsense is refused before anything runs, with a bound named for every count and duration."""
    results = run_in_one_process({case: (name, args) for case, (name, args, _) in FLAG_CASES.items()}, cwd=tmp_path)
    for case, result in results.items():
        one_line_error(result, *FLAG_CASES[case][2])
    for name in ("robostrich-train", "robostrich-movement"):  # and as installed scripts, a heavy and a light one
        case = next(case for case, (command, _, _) in FLAG_CASES.items() if command == name)
        one_line_error(finish(start(name, *FLAG_CASES[case][1], cwd=tmp_path)), *FLAG_CASES[case][2])
    assert os.listdir(tmp_path) == []  # nothing written, not even a run directory


def test_damaged_files_are_named_in_one_line(tmp_path):
    wide = tmp_path / "wide.csv"
    wide.write_text("time," + "x" * 200_000 + "\n")  # a field over csv's 128 KB limit
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100_000 + "]" * 100_000)
    latin = tmp_path / "latin.json"
    latin.write_bytes('{"name": "caf\u00e9"}'.encode("latin-1"))
    keys = tmp_path / "keys.npz"
    np.savez(keys, positions=np.zeros((3, 2)))
    whole = tmp_path / "whole.npz"
    np.savez(whole, head_position=np.zeros((3, 2)), head_attitude=np.zeros(3), control=np.zeros((3, 9)),
             fingerprint=np.array("x"))
    truncated = tmp_path / "truncated.npz"
    truncated.write_bytes(whole.read_bytes()[:200])
    cases = {
        "gait_field": (start("robostrich-stabilize", "--gait", wide, "--out", tmp_path / "s"), ["wide.csv", "line 1"]),
        "layout_deep": (start("robostrich-layouts", "--layout-file", deep, "--out", tmp_path / "l1"),
                        ["deep.json", "nested too deeply"]),
        "layout_latin": (start("robostrich-layouts", "--layout-file", latin, "--out", tmp_path / "l2"),
                         ["latin.json", "UTF-8"]),
        "npz_keys": (start("robostrich-targets", "--recheck", "--out", keys), ["keys.npz", "head_position"]),
        "npz_truncated": (start("robostrich-targets", "--recheck", "--out", truncated), ["truncated.npz"]),
        "npz_append": (start("robostrich-targets", "--append", "--samples", "1", "--seek-level-time", "0",
                             "--workers", "1", "--out", keys), ["keys.npz", "fingerprint"]),
    }
    for case, (process, fragments) in cases.items():
        one_line_error(finish(process), *fragments)
    assert np.load(keys).files == ["positions"]  # --append left the foreign file alone
    assert not any((tmp_path / d).exists() for d in ("s", "l1", "l2"))


@pytest.mark.long
def test_one_run_owns_its_directory_and_ctrl_c_writes_a_checkpoint(tmp_path):
    """Two workers (the default): a second run in the same --out is refused while the first holds
    it; Ctrl-C checkpoints both runs and exits 130; --resume drops a torn last metrics line and
    finishes with a metrics line for every step, episodes cut by a lesson's end included. Long
    enough (5,800 steps) that Ctrl-C after the first episode always lands mid-training."""
    train = [("lesson1:2900,lesson2:2900" if a == "lesson1:300,lesson2:300" else a) for a in TRAIN]
    out = tmp_path / "run"
    first = start("robostrich-train", *train, "--out", out)
    wait_for(lambda: (out / ".lock").exists() and (out / ".lock").read_text().strip(), "the run's lock")
    second = finish(start("robostrich-train", *train, "--seed", "1", "--out", out))
    one_line_error(second, str(out), "in use")
    wait_for(lambda: (out / "curriculum" / "metrics.jsonl").exists() and first.poll() is None
             and (out / "curriculum" / "metrics.jsonl").stat().st_size > 0, "the first episode")
    first.send_signal(signal.SIGINT)
    interrupted = finish(first)
    assert interrupted.returncode == 130, interrupted.stderr[-3000:]
    assert interrupted.stderr.strip().splitlines()[-1].startswith(
        "robostrich-train: interrupted (checkpoint written at step "), interrupted.stderr
    assert "Traceback" not in interrupted.stderr, interrupted.stderr[-3000:]
    assert json.loads((out / "config.json").read_text())["seed"] == 0  # the second run touched nothing
    steps = {}
    for label in ("curriculum", "baseline"):
        record = checkpoint._read_record(str(out / label / "checkpoint.ckpt"))
        steps[label] = record["payload"]["loop"]["env_steps"]
        assert 0 < steps[label] <= 5800, steps
        # the parent's one line says where each worker's checkpoint went (SIGTERM: tests/test_stops.py)
        assert f"at step {steps[label]}: {out / label / 'checkpoint.ckpt'}" in interrupted.stderr.strip().splitlines()[-1]
    assert steps["curriculum"] < 5800 or steps["baseline"] < 5800  # stopped early, not at the plan's end

    missing = tmp_path / "missing"  # checkpoints with a valid checksum but no learner: a worker's one line
    shutil.copytree(out, missing)
    for label in ("curriculum", "baseline"):
        path = missing / label / "checkpoint.ckpt"
        record = checkpoint._read_record(str(path))
        checkpoint.save(str(path), {k: v for k, v in record["payload"].items() if k != "learner"},
                        record["fingerprint"])
    rejected = start("robostrich-train", *train, "--out", missing, "--resume")
    torn = out / "curriculum" / "metrics.jsonl"
    with open(torn, "a") as f:
        f.write('{"env_steps": 5799, "return": -3')  # a crash in mid-write
    resumed = finish(start("robostrich-train", *train, "--no-baseline", "--out", out, "--resume"))
    assert resumed.returncode == 0, resumed.stderr[-3000:]
    records = [json.loads(line) for line in torn.read_text().splitlines()]
    assert sum(r["length"] for r in records) == 5800 and records[-1]["env_steps"] == 5800, records
    assert [r["env_steps"] for r in records if r.get("cut")] == [2900, 5800]  # each lesson's last episode, cut
    one_line_error(finish(rejected), "checkpoint.ckpt", "learner")


def test_incomplete_checkpoints_and_task_names_are_refused_before_any_work(tmp_path):
    from agents.sac.config import SACConfig
    from agents.curriculum import LessonSettings
    fingerprint = {"plan": "robostrich/lesson1:300,robostrich/lesson2:300", "config": SACConfig().to_dict(),
                   "lessons": LessonSettings().to_dict(), "seed": 0, "observation_layout": [], "action_size": 9}
    empty, whole = tmp_path / "empty.ckpt", tmp_path / "whole.ckpt"
    checkpoint.save(str(empty), {}, fingerprint)
    checkpoint.save(str(whole), {k: None for k in ("learner", "actor_key", "actor_noise", "replay", "loop",
                                                   "lesson_index", "lesson_steps", "environment",
                                                   "latest_metrics")}, fingerprint)
    checkpoint.save(str(tmp_path / "no_plan.ckpt"), {}, {"seed": 0})
    cases = {
        "evaluate": (start("robostrich-evaluate", empty, "--out", tmp_path / "e"), ["empty.ckpt", "learner"]),
        "no_plan": (start("robostrich-evaluate", tmp_path / "no_plan.ckpt", "--out", tmp_path / "e"),
                    ["no_plan.ckpt", "plan"]),
        "init_from": (start("robostrich-train", *TRAIN, "--init-from", empty, "--out", tmp_path / "i"),
                      ["--init-from", "learner"]),
        "track": (start("robostrich-evaluate", whole, "--track-task", "nope", "--out", tmp_path / "e"),
                  ["--track-task", "nope"]),
        "heldout": (start("robostrich-evaluate", whole, "--heldout-task", "track", "--out", tmp_path / "e"),
                    ["--heldout-task", "track"]),
    }
    for case, (process, fragments) in cases.items():
        one_line_error(finish(process), *fragments)
    assert not (tmp_path / "e").exists() and not (tmp_path / "i").exists()


def test_torn_and_damaged_metrics_lines(tmp_path):
    """A torn last line is what a crash leaves (dropped); a bad line before it is named, file and line."""
    from agents.curriculum import read_records
    path = tmp_path / "metrics.jsonl"
    path.write_text('{"env_steps": 1}\n{"env_steps": 2, "ret')
    assert read_records(str(path)) == [{"env_steps": 1}]
    path.write_text('{"env_steps": 1}\n{"env_ste\n{"env_steps": 3}\n')
    with pytest.raises(ValueError, match=r"metrics.jsonl: line 2"):
        read_records(str(path))


def test_a_torn_evaluation_report_is_named(tmp_path):
    """A worker's report that a crash left in part is a ValueError naming the file, not a bare JSON error."""
    from agents.robostrich.evaluate.evaluation import read_reports
    (tmp_path / "curriculum_heldout.json").write_text('{"summary": {"success_rate": 1.0}}')
    (tmp_path / "curriculum_track.json").write_text('{"summary": {"succ')
    with pytest.raises(ValueError, match=r"curriculum_track\.json"):
        read_reports(str(tmp_path), "curriculum")
    (tmp_path / "curriculum_track.json").unlink()
    assert read_reports(str(tmp_path), "curriculum") == {"heldout": {"summary": {"success_rate": 1.0}}}


def test_sigterm_is_handled_as_ctrl_c_checkpoint_written_and_143(tmp_path):
    """A batch scheduler stops a job with SIGTERM: training writes its checkpoint and exits 143 with one line."""
    out = tmp_path / "run"
    train = [("lesson1:2900,lesson2:2900" if a == "lesson1:300,lesson2:300" else a) for a in TRAIN]
    process = start("robostrich-train", *train, "--no-baseline", "--out", out)
    metrics = out / "curriculum" / "metrics.jsonl"
    wait_for(lambda: process.poll() is not None or (metrics.exists() and metrics.stat().st_size > 0),
             "the first episode")
    process.send_signal(signal.SIGTERM)
    result = finish(process)
    assert result.returncode == 143, result.stderr[-3000:]
    line = result.stderr.strip().splitlines()[-1]
    assert line.startswith("robostrich-train: terminated (checkpoint written at step"), result.stderr[-3000:]
    steps = checkpoint._read_record(str(out / "curriculum" / "checkpoint.ckpt"))["payload"]["loop"]["env_steps"]
    assert 0 < steps < 5800


def test_ctrl_c_while_a_command_still_imports_its_libraries_is_one_line_and_130(tmp_path):
    """The installed commands start light (robostrich_commands.py) and note Ctrl-C while they
    import MuJoCo and JAX: Ctrl-C a moment after the start ends the command as Ctrl-C anywhere else
    does, before any work."""
    out = tmp_path / "train"
    process = start("robostrich-train", *TRAIN, "--out", out)
    time.sleep(0.5)  # the interpreter is up; importing the training's libraries takes seconds
    process.send_signal(signal.SIGINT)
    result = finish(process)
    assert result.returncode == 130, result.stderr[-3000:]
    assert result.stderr.strip().splitlines() == ["robostrich-train: interrupted"], result.stderr
    assert not out.exists()  # nothing started


def test_the_command_launcher_loads_nothing_heavy_and_knows_every_installed_command():
    import subprocess
    import sys
    code = ("import sys, robostrich_commands as c; "
            "print(sorted({m.split('.')[0] for m in sys.modules} & {'numpy', 'jax', 'mujoco', 'dm_control', "
            "'robostrich_suite', 'agents', 'matplotlib'}))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert loaded.strip() == "[]"
    from importlib import metadata
    import robostrich_commands as commands
    installed = {e.name: e.value for e in metadata.entry_points(group="console_scripts")
                 if e.name.startswith("robostrich-")}
    assert set(installed) == set(commands.COMMANDS)
    for name, value in installed.items():
        assert getattr(commands, value.split(":")[1]).__doc__.endswith(f"({commands.COMMANDS[name]}).")


def test_config_fields_are_checked_where_they_are_owned():
    from agents.sac.config import SACConfig
    for bad in ({"learning_rate": math.nan}, {"hidden_sizes": ()}, {"batch_size": 0}, {"reward_scale": math.inf},
                {"log_std_min": 2.0, "log_std_max": 2.0}, {"max_replay_size": 10**12}, {"target_entropy": math.nan}):
        field = next(iter(bad))
        with pytest.raises(ValueError, match=field):
            SACConfig(**bad)
    assert SACConfig.paper_sac().hidden_sizes == (256, 256)  # the presets still pass


def test_task_options_are_checked_in_their_constructors():
    import robostrich_suite
    from robostrich_suite.tasks.randomization import DomainRandomization
    with pytest.raises(ValueError, match="joint_angle_noise"):
        DomainRandomization(joint_angle_noise=math.nan)
    with pytest.raises(ValueError, match="mass_scale"):
        DomainRandomization(mass_scale=(0.9, math.inf))
    for kwargs, match in (({"target_axes": (0, 5)}, "target_axes"), ({"target_axes": (0, 0)}, "target_axes"),
                          ({"target_pool": [[0.2, 0.3], [0.0, -5.0]]}, "far outside any workspace")):
        with pytest.raises(ValueError, match=match):
            robostrich_suite.load("robostrich", "lesson2", task_kwargs=kwargs)


def test_gym_adapter_falls_back_to_the_free_camera():
    pytest.importorskip("gymnasium")
    from robostrich_suite import gym_adapter
    named = gym_adapter.make("robostrich", "lesson2", render_mode="rgb_array", width=32, height=24)
    unknown = gym_adapter.make("robostrich", "lesson2", render_mode="rgb_array", width=32, height=24, camera="nope")
    for env in (named, unknown):
        env.reset(seed=0)
    frame = unknown.render()
    assert frame.shape == (24, 32, 3) and frame.dtype == np.uint8 and frame.any()
    assert not np.array_equal(frame, named.render())  # another view: the free camera, not the side one
