"""robostrich-sweep: its grid, its table, and real sweeps at tiny budgets on a local Ray (2 CPUs):
a 2 x 2 sweep finishes and aggregates its runs; one killed mid-way and started again reruns
nothing finished and resumes the rest bit for bit; a run that fails is reported while the others
finish; without Ray the command says how to install it."""
import json
import os
import pathlib
import signal
import subprocess
import sys
import tempfile
import time

import pytest

from agents.robostrich.sweep import grid as sweep_grid
from agents.robostrich.sweep import table as sweep_table
from conftest import COMMAND_ENVIRONMENT, console_script, run_in_one_process

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))
import results_page  # noqa: E402

# The main job at its smallest (no plain SAC, no `track`): three 100-step lessons, a checkpoint
# after each, one held-out target.
TINY = ["--plan", "lesson1:100,lesson2:100,lesson3:100", "--hidden-sizes", "16,16", "--batch-size", "16",
        "--min-replay-size", "20", "--num-eval-targets", "1", "--final-eval-targets", "1", "--eval-every", "1000000",
        "--checkpoint-every", "100", "--no-baseline", "--track-task", "", "--no-rerun", "--no-figures"]
GRID = ["--seeds", "0,1", "--layouts", "ventral_slips,antagonist_pairs", "--num-cpus", "2", "--quiet", *TINY]
CHECKPOINT = "checkpoint.ckpt"  # a run's checkpoint, in RUN/curriculum/
RUNS = [(layout, seed) for layout in ("ventral_slips", "antagonist_pairs") for seed in (0, 1)]


def _report(success, precise=0.5, position=0.01, attitude=1.0):
    return {"success_rate": success, "precise_success_rate": precise, "position_error_median": position,
            "attitude_error_median": attitude}


# -- the grid and the table (no Ray) --------------------------------------------------------------

def test_a_grid_file_and_flags_give_one_group_per_layout_and_setting(tmp_path):
    grid = tmp_path / "grid.toml"
    grid.write_text('seeds = [3, 4]\nlayouts = ["a"]\n[train]\nsteps = 600\nno-figures = true\n'
                    '[settings.her]\nher-ratio = 0.5\nher-lessons = ["lesson1", "lesson2"]\n'
                    '[settings.kw]\ntask-kwargs = {weights = {position_error = 10}}\nbaseline = false\n')
    table = sweep_grid.read_grid_file(str(grid))
    settings = {name: sweep_grid.flags_of(t, name) for name, t in table["settings"].items()}
    common = sweep_grid.flags_of(table["train"], "train") + ["--steps", "900"]
    groups, runs = sweep_grid.build_grid(table["seeds"], ["a", "b"], settings, common, "OUT")
    assert [g.name for g in groups] == ["a+her", "a+kw", "b+her", "b+kw"]
    assert groups[0].arguments == ("--layout", "a", "--her-ratio", "0.5", "--her-lessons", "lesson1,lesson2",
                                   "--steps", "600", "--no-figures", "--steps", "900")  # the command line last
    assert groups[1].arguments[2:6] == ("--task-kwargs", '{"weights": {"position_error": 10}}', "--no-baseline",
                                        "--steps")
    assert [(r.group, r.seed, r.run_dir) for r in runs[:2]] == [("a+her", 3, "OUT/runs/a+her/seed_3"),
                                                               ("a+her", 4, "OUT/runs/a+her/seed_4")]
    assert runs[0].argv()[-7:] == ["--seed", "3", "--out", "OUT/runs/a+her/seed_3", "--workers", "1", "--quiet"]
    only, _ = sweep_grid.build_grid([0], None, {}, [], "OUT")
    assert [(g.name, g.arguments) for g in only] == [("default", ())]


@pytest.mark.parametrize("grid, layouts, common, message", [
    ("nope = 1\n", None, [], "unknown key nope"),
    ("[settings]\nx = 1\n", None, [], "settings.x must be a table"),
    ("", ["a/b"], [], "names a directory"),
    ("", ["a", "a"], [], "repeat a name"),
    ("", None, ["--seed", "3"], "--seed is set for each run"),
    ("", None, ["--out=x"], "--out is set for each run"),
    ("", ["a"], ["--layout", "b"], "--layout is given by the sweep's layouts"),
    ("seeds = [1, 1]\n", None, [], "seeds repeat"),
])
def test_a_grid_that_cannot_be_run_as_meant_is_refused(tmp_path, grid, layouts, common, message):
    path = tmp_path / "grid.toml"
    path.write_text(grid)
    with pytest.raises(ValueError, match=message):
        table = sweep_grid.read_grid_file(str(path))
        seeds = sweep_grid.check_seeds(table.get("seeds", [0]), 100)
        settings = {n: sweep_grid.flags_of(t, n) for n, t in table.get("settings", {}).items()}
        sweep_grid.build_grid(seeds, layouts, settings, common, "OUT")


def test_the_group_table_has_a_row_per_run_and_mean_min_max_over_seeds():
    summaries = []
    for success, minutes in ((1.0, 10.0), (0.5, 20.0)):
        runs = {"curriculum": {"heldout": _report(success), "heldout_moving": _report(success / 2),
                               "track": _report(2 / 3)},
                "baseline": {"heldout": _report(0.25, position=0.03, attitude=2.0)},
                "lookup": {"heldout": _report(0.9, precise=0.0), "heldout_moving": _report(0.8)}}
        summaries.append({"runs": runs, "env_steps": {"curriculum": 300, "baseline": 300},
                          "timings": {"curriculum": {"seconds": minutes * 60}, "baseline": {"seconds": 60.0}}})
    agg = sweep_table.aggregate(summaries, [0, 1], [11.0, 21.0])
    rows = sweep_table.group_table(agg, sweep_table.training_minutes(summaries))
    assert rows[0] == ("| run | success, fixed start | moving starts | `track` | within 1 cm and 2 deg | "
                       "median position error | median attitude error | minutes |")
    assert rows[2] == ("| curriculum SAC | 75.0 % [50.0, 100.0] | 37.5 % [25.0, 50.0] | 66.7 % | 50.0 % | "
                       "1.00 cm | 1.00 deg | 15.0 [10.0, 20.0] |")
    assert rows[3] == "| plain SAC | 25.0 % | - | - | 50.0 % | 3.00 cm | 2.00 deg | 1.0 |"
    assert rows[4] == "| lookup | 90.0 % | 80.0 % | - | 0.0 % | 1.00 cm | 1.00 deg | - |"
    summaries[0]["runs"]["curriculum"].update(new=_report(0.75, precise=0.5), new_moving=_report(0.5))
    newer = sweep_table.group_table(sweep_table.aggregate(summaries[:1], [0], [11.0]),
                                    sweep_table.training_minutes(summaries[:1]))
    assert newer[0] == ("| run | success, fixed start | moving starts | new targets, fixed start | new targets, moving "
                        "starts | `track` | within 1 cm and 2 deg | new targets within 1 cm and 2 deg | median position "
                        "error | median attitude error | minutes |")
    assert newer[2].startswith("| curriculum SAC | 100.0 % | 50.0 % | 75.0 % | 50.0 % | 66.7 % | 50.0 % | 50.0 % |")


# -- the command (real runs on a local Ray) -------------------------------------------------------

@pytest.fixture(scope="module")
def command_env(tmp_path_factory):
    """The sweep's environment: a home and a temporary directory of its own, which must stay empty
    (nothing is written outside the sweep's directory), and an XLA cache that outlives the tests."""
    base = tmp_path_factory.mktemp("outside")
    (base / "home").mkdir()
    (base / "tmp").mkdir()
    cache = os.environ.get("JAX_COMPILATION_CACHE_DIR") or os.path.join(tempfile.gettempdir(),
                                                                         "robostrich-tests-jax-cache")
    env = {**COMMAND_ENVIRONMENT, "HOME": str(base / "home"), "TMPDIR": str(base / "tmp"),
           "JAX_COMPILATION_CACHE_DIR": cache, "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS": "0",
           "JAX_PERSISTENT_CACHE_MIN_ENTRY_SIZE_BYTES": "-1", "MPLCONFIGDIR": str(tmp_path_factory.mktemp("mpl"))}
    yield env
    assert not any((base / "home").iterdir()) and not any((base / "tmp").iterdir()), list(base.rglob("*"))


def short_dir() -> pathlib.Path:
    """A sweep directory short enough for Ray's sockets under it (pytest's own paths are not)."""
    return pathlib.Path(tempfile.mkdtemp(prefix="rs", dir="/tmp"))


def sweep(*args, env, **popen):
    return subprocess.Popen([console_script("robostrich-sweep"), *map(str, args)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, **popen)


def finish(process, timeout=900):
    stdout, stderr = process.communicate(timeout=timeout)
    return subprocess.CompletedProcess(process.args, process.returncode, stdout, stderr)


def outcome(run_dir: pathlib.Path) -> dict:
    """What a run computed: its final and lesson-end evaluations and its counters (not its timings)."""
    summary = json.loads((run_dir / "summary.json").read_text())
    return {"summary": {k: summary[k] for k in ("runs", "lesson_ends", "env_steps", "updates")},
            "evals": (run_dir / "curriculum" / "evals.jsonl").read_text()}


@pytest.fixture(scope="module")
def finished_sweep(command_env):
    out = short_dir()
    result = finish(sweep("--out", out / "sweep", *GRID, env=command_env))
    yield out / "sweep", result
    subprocess.run(["rm", "-rf", str(out)], check=True)


@pytest.mark.long
def test_a_two_by_two_sweep_finishes_and_its_table_aggregates_the_runs(finished_sweep):
    out, result = finished_sweep
    assert result.returncode == 0, result.stderr[-3000:]
    table = json.loads((out / "sweep.json").read_text())
    assert (table["total"], table["finished"], table["failed"]) == (4, 4, [])
    for layout in ("ventral_slips", "antagonist_pairs"):
        dirs = [out / "runs" / layout / f"seed_{seed}" for seed in (0, 1)]
        summaries = [json.loads((d / "summary.json").read_text()) for d in dirs]
        assert all(json.loads((d / "config.json").read_text())["layout"] == layout for d in dirs)
        group = table["groups"][layout]
        assert group["aggregate"]["results"] == sweep_table.aggregate(summaries, [0, 1])["results"]
        successes = [s["runs"]["curriculum"]["heldout"]["success_rate"] for s in summaries]
        assert group["aggregate"]["results"]["curriculum"]["heldout"]["success_rate"]["values"] == successes
        assert all((d / "curriculum" / CHECKPOINT).exists() for d in dirs)
    markdown = (out / "sweep.md").read_text()
    assert markdown == result.stdout and "4 of 4 runs finished, 0 failed" in markdown
    assert "## ventral_slips" in markdown and "## antagonist_pairs" in markdown
    assert markdown.count("| curriculum SAC | ") == 2 and markdown.count("| lookup | ") == 2
    assert (out / "ray").is_dir()  # Ray's files stay in the sweep's directory


def test_the_results_page_records_one_group_of_a_sweep(finished_sweep, tmp_path, monkeypatch):
    out, _ = finished_sweep
    record = results_page.make_record("x", str(out / "sweep.json"), "A title", group="antagonist_pairs",
                                      date="2026-12-04")
    assert record["command"].startswith("robostrich-sweep --out ") and record["data"]["seeds"] == [0, 1]
    text = results_page.render_record(record)
    assert "| curriculum SAC | held-out, fixed start |" in text and "seed 1: " in text
    with pytest.raises(ValueError, match="name one with --group"):
        results_page.make_record("x", str(out / "sweep.json"), "t")
    monkeypatch.setattr(results_page, "RECORDS", tmp_path)
    assert results_page.main(["add", "y", str(out / "sweep.json"), "--group", "ventral_slips", "--title", "T"]) == 0
    stored = json.loads((tmp_path / "y.json").read_text())
    assert stored["kind"] == "seeds" and stored["data"] == json.loads((out / "sweep.json").read_text())["groups"]["ventral_slips"]["aggregate"]


def _ended(pid: int) -> bool:
    """Whether the process ``pid`` has exited (gone, or a zombie). Not the run's lock: the run lets
    go of its directory before its last line (where its checkpoint went) is printed."""
    try:
        return "\nState:\tZ" in pathlib.Path(f"/proc/{pid}/status").read_text()
    except FileNotFoundError:
        return True


def _wait_for(condition, what, timeout=600, every=0.05):
    deadline = time.time() + timeout
    while not condition():
        assert time.time() < deadline, f"timed out waiting for {what}"
        time.sleep(every)


def _checkpointed(run_dir: pathlib.Path) -> bool:
    return (run_dir / "curriculum" / CHECKPOINT).exists()


def _mid_training(run_dir: pathlib.Path) -> bool:
    """A checkpoint written and fewer than its three lesson-end evaluations: still training."""
    evals = run_dir / "curriculum" / "evals.jsonl"
    return _checkpointed(run_dir) and evals.exists() and len(evals.read_text().splitlines()) < 3 \
        and not (run_dir / "summary.json").exists()


def _trainer(run_dir: pathlib.Path):
    """The process id of the robostrich-train that holds ``run_dir`` (from its lock file), else None."""
    try:
        pid = int((run_dir / ".lock").read_text().strip())
        status = pathlib.Path(f"/proc/{pid}/status").read_text()
        command = pathlib.Path(f"/proc/{pid}/cmdline").read_bytes()
    except (OSError, ValueError):
        return None
    alive = "\nState:\tZ" not in status
    return pid if alive and b"robostrich-train" in command else None


def _told_to_stop(pid: int) -> bool:
    """Whether SIGTERM or SIGINT waits to be delivered to the (stopped) process ``pid``."""
    status = pathlib.Path(f"/proc/{pid}/status").read_text()
    pending = {line.split(":")[0]: int(line.split()[1], 16) for line in status.splitlines()
               if line.startswith(("SigPnd:", "ShdPnd:"))}
    mask = (1 << (signal.SIGTERM - 1)) | (1 << (signal.SIGINT - 1))
    return any(bits & mask for bits in pending.values())


def _stop_mid_training(run_dir: pathlib.Path, process, timeout=600):
    """SIGSTOP the run's training while it is mid-training (a checkpoint written, not finished):
    stopped first and looked at then, so that it cannot finish between the look and the stop.
    Returns its process id."""
    deadline = time.time() + timeout
    while time.time() < deadline and process.poll() is None:
        pid = _trainer(run_dir)
        if pid is not None:
            os.kill(pid, signal.SIGSTOP)
            if _mid_training(run_dir):
                return pid
            os.kill(pid, signal.SIGCONT)
        time.sleep(0.05)
    raise AssertionError(f"{run_dir} was not caught mid-training (sweep status {process.poll()})")


@pytest.mark.long
def test_a_killed_sweep_stops_its_runs_with_a_checkpoint_and_resumes_them_bit_for_bit(finished_sweep, command_env):
    """SIGKILL to the sweep while its second run trains (its first finished): the run stops, as by
    SIGTERM, with a checkpoint of where it was; started again, the sweep reruns nothing finished
    and resumes the rest, and every run ends as in the uninterrupted sweep. The training is held
    (SIGSTOP) while the sweep is killed, so the run cannot finish in the meantime."""
    reference, _ = finished_sweep
    out = short_dir() / "sweep"
    grid = ["--seeds", "0,1", "--layouts", "ventral_slips", "--num-cpus", "1", "--quiet", *TINY]
    dirs = {seed: out / "runs" / "ventral_slips" / f"seed_{seed}" for seed in (0, 1)}
    process = sweep("--out", out, *grid, env=command_env)
    pid = None
    try:
        _wait_for(lambda: (dirs[0] / "summary.json").exists() or process.poll() is not None, "the first run")
        pid = _stop_mid_training(dirs[1], process)
        process.send_signal(signal.SIGKILL)
        process.communicate()
        _wait_for(lambda: _told_to_stop(pid), "the run to be told to stop", timeout=120)
    finally:
        process.kill()
        process.communicate()
        if pid is not None:
            os.kill(pid, signal.SIGCONT)
    assert process.returncode == -signal.SIGKILL
    _wait_for(lambda: _ended(pid), "the stopped run to write its checkpoint and end", timeout=300)
    log = (dirs[1] / "train.log").read_text()
    assert "robostrich-train: terminated (checkpoint written at step " in log, log[-2000:]
    assert not (dirs[1] / "summary.json").exists()
    done = os.stat(dirs[0] / "summary.json")
    result = finish(sweep("--out", out, *grid, env=command_env))
    assert result.returncode == 0, result.stderr[-3000:]
    assert "1 of 2 runs finished, 1 to run (1 resumed)" in result.stderr, result.stderr[-3000:]
    again = os.stat(dirs[0] / "summary.json")  # not run again
    assert (again.st_ino, again.st_mtime_ns) == (done.st_ino, done.st_mtime_ns)
    for seed, run_dir in dirs.items():  # every run as the uninterrupted sweep's
        assert outcome(run_dir) == outcome(reference / "runs" / "ventral_slips" / f"seed_{seed}"), seed
    assert json.loads((out / "sweep.json").read_text())["finished"] == 2
    subprocess.run(["rm", "-rf", str(out.parent)], check=True)


def test_sigterm_stops_a_sweep_as_ctrl_c_and_a_second_sweep_into_its_directory_is_refused(command_env, tmp_path):
    """A scheduler's SIGTERM: every running run writes its checkpoint, sweep.json says so, exit
    143 with one line, and Ray's temporary directory is gone. While it runs, another sweep into
    its --out is refused in one line and changes nothing. Runs too long to end on their own."""
    long_plan = [a if a != TINY[1] else "lesson1:100,lesson2:100,lesson3:1000000" for a in TINY]
    temp = short_dir()  # TMPDIR of this test alone: --out is too long for Ray's sockets, so they go there
    env = {**command_env, "TMPDIR": str(temp)}
    out = tmp_path / "sweep"
    grid = ["--seeds", "0,1", "--num-cpus", "2", "--quiet", *long_plan]
    dirs = [out / "runs" / "default" / f"seed_{seed}" for seed in (0, 1)]
    process = sweep("--out", out, *grid, env=env)
    try:
        _wait_for(lambda: all(_checkpointed(d) for d in dirs) or process.poll() is not None, "both runs to train")
        assert process.poll() is None, process.communicate()[1][-3000:]
        before = {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file() and p.name != "train.log"}
        second = finish(sweep("--out", out, *grid, env=env), timeout=300)
        lines = second.stderr.strip().splitlines()
        assert second.returncode == 2 and len(lines) == 1, second.stderr[-3000:]
        assert lines[0].startswith("robostrich-sweep: error: ") and "in use by another robostrich-sweep" in lines[0]
        process.send_signal(signal.SIGTERM)
        result = finish(process, timeout=600)
    finally:
        process.kill()
        process.communicate()
    assert all(p.stat().st_mtime_ns >= t for p, t in before.items() if p.exists())
    assert result.returncode == 143, result.stderr[-3000:]
    assert result.stderr.strip().splitlines()[-1] == "robostrich-sweep: terminated", result.stderr[-3000:]
    assert "SIGTERM" not in result.stderr and "Traceback" not in result.stderr, result.stderr[-3000:]
    for run_dir in dirs:
        assert "(checkpoint written at step " in (run_dir / "train.log").read_text()
    table = json.loads((out / "sweep.json").read_text())
    assert [r["status"] for r in table["runs"]] == ["interrupted", "interrupted"]
    assert not any(temp.iterdir()), list(temp.rglob("*"))
    subprocess.run(["rm", "-rf", str(temp)], check=True)


def test_a_failing_run_is_reported_and_the_others_finish(command_env, tmp_path):
    """A run that robostrich-train refuses once it starts (its checkpoint damaged) is listed with
    its one-line error while the other run finishes; a bad option would stop the sweep before
    any run (test_bad_input_and_a_missing_ray_are_one_line_and_exit_2)."""
    grid = tmp_path / "grid.toml"
    grid.write_text('seeds = [0]\n[settings.plain]\n[settings.bad]\n')
    out = tmp_path / "sweep"  # too long a path for Ray's sockets: they go to TMPDIR, this test's own
    damaged = out / "runs" / "bad" / "seed_0" / "curriculum" / CHECKPOINT
    damaged.parent.mkdir(parents=True)
    damaged.write_bytes(b"not a checkpoint")
    temp = short_dir()
    result = finish(sweep("--grid", grid, "--out", out, "--num-cpus", "2", "--quiet", *TINY,
                          env={**command_env, "TMPDIR": str(temp)}))
    assert not any(temp.iterdir()), list(temp.rglob("*"))  # removed at the end
    temp.rmdir()
    assert result.returncode == 1, result.stderr[-3000:]
    failure = [line for line in result.stderr.splitlines() if line.startswith("robostrich-sweep: run ")]
    assert len(failure) == 1 and failure[0].startswith("robostrich-sweep: run bad seed 0 failed: robostrich-train: "
                                                       "error: "), result.stderr[-3000:]
    assert str(damaged) in failure[0] and "(exit status 2; log: " in failure[0]
    assert (out / "runs" / "plain" / "seed_0" / "summary.json").exists()
    table = json.loads((out / "sweep.json").read_text())
    assert (table["finished"], [f["group"] for f in table["failed"]]) == (1, ["bad"])
    assert table["groups"]["bad"]["aggregate"] is None
    markdown = (out / "sweep.md").read_text()
    assert "## Failed runs" in markdown and "- bad seed 0: robostrich-train: error: " in markdown
    assert not (out / "ray").exists()


def test_bad_input_and_a_missing_ray_are_one_line_and_exit_2(command_env, tmp_path):
    hidden = ("import sys\nclass NoRay:\n    def find_spec(self, name, path=None, target=None):\n"
              "        if name == 'ray' or name.startswith('ray.'):\n            raise ImportError('hidden')\n"
              "sys.meta_path.insert(0, NoRay())\nsys.argv[0] = 'robostrich-sweep'\n"
              "from robostrich_commands import sweep\nsys.exit(sweep())\n")
    processes = {
        "no ray": subprocess.Popen([sys.executable, "-c", hidden, "--out", tmp_path / "a"], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True, env=command_env),
        "address": sweep("--out", tmp_path / "f", "--address", "127.0.0.1:1", *TINY, env=command_env)}
    results = run_in_one_process({  # refused at their flags' checks
        "bad flag": ("robostrich-sweep", ["--out", tmp_path / "b", "--her-ratio", "x"]),
        "per run": ("robostrich-sweep", ["--out", tmp_path / "c", "--seed", "3"]),
        "layout": ("robostrich-sweep", ["--out", tmp_path / "d", "--layouts", "ventral_slips,nope"]),
        "value": ("robostrich-sweep", ["--out", tmp_path / "e", "--learning-rate", "-1"]),
        "option": ("robostrich-sweep", ["--out", tmp_path / "g", "--task-kwargs", '{"no_such_option": 1}'])},
        env=command_env)
    results.update({name: finish(p, timeout=300) for name, p in processes.items()})
    expected = {"no ray": "Ray is not installed; pip install -e '.[sweep]'",
                "bad flag": "group default: robostrich-train: argument --her-ratio: invalid float value: 'x'",
                "per run": "--seed is set for each run by robostrich-sweep",
                "layout": "unknown layout 'nope'",
                "value": "group default: robostrich-train: --learning-rate",
                "option": "group default: robostrich-train: --task-kwargs",
                "address": "--address 127.0.0.1:1: no Ray cluster answers there"}
    for name, result in results.items():
        lines = result.stderr.strip().splitlines()
        assert result.returncode == 2 and len(lines) == 1, (name, result.stderr[-2000:])
        assert lines[0].startswith("robostrich-sweep: error: ") and expected[name] in lines[0], (name, lines)
    assert not any(tmp_path.iterdir())  # nothing written
