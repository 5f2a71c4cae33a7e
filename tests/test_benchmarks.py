"""tools/benchmark_seeds.py and tools/benchmark_dmc.py: aggregation exact, the seeds as a sweep, tiny end-to-end runs."""
import importlib.util
import json
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
import pytest
import results_page

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TOOLS = os.path.join(ROOT, "tools")

def load_tool(name):
    spec = importlib.util.spec_from_file_location(name, os.path.join(TOOLS, f"{name}.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def summary(success, position, attitude, steps=300, kinds=("heldout", "heldout_moving", "track")):
    run = {k: {"success_rate": success, "precise_success_rate": success / 2,
               "position_error_median": position, "attitude_error_median": attitude}
           for k in kinds}
    return {"runs": {"curriculum": run, "baseline": dict(run), "lookup": dict(run)},
            "env_steps": {"curriculum": steps, "baseline": steps}}


@pytest.fixture(scope="session")
def tool_env():
    """XLA compiles dominate these tiny runs; a compilation cache that outlives the test run makes reruns fast."""
    cache = os.environ.get("JAX_COMPILATION_CACHE_DIR") or os.path.join(tempfile.gettempdir(),
                                                                         "robostrich-tests-jax-cache")
    return {**os.environ, "MUJOCO_GL": "egl", "JAX_COMPILATION_CACHE_DIR": cache,
            "JAX_PERSISTENT_CACHE_MIN_COMPILE_TIME_SECS": "0", "JAX_PERSISTENT_CACHE_MIN_ENTRY_SIZE_BYTES": "-1"}


def run_tool(name, *args, cwd, env):
    proc = subprocess.run([sys.executable, os.path.join(TOOLS, f"{name}.py"), *args], cwd=cwd,
                          capture_output=True, text=True, env=env, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc


def test_seeds_aggregation_is_exact_mean_min_max():
    tool = load_tool("benchmark_seeds")
    summaries = [summary(0.0, 0.2, 10.0), summary(0.5, 0.4, 30.0), summary(0.25, 0.3, 5.0, kinds=("heldout",))]
    agg = tool.aggregate(summaries, seeds=[0, 1, 7], minutes=[1.5, 2.5, None])
    heldout = agg["results"]["curriculum"]["heldout"]
    assert heldout["success_rate"] == {"mean": 0.25, "min": 0.0, "max": 0.5, "values": [0.0, 0.5, 0.25]}
    assert heldout["position_error_median"]["mean"] == pytest.approx(0.3)
    assert (heldout["position_error_median"]["min"], heldout["position_error_median"]["max"]) == (0.2, 0.4)
    assert heldout["attitude_error_median"]["mean"] == pytest.approx(15.0)
    assert (heldout["attitude_error_median"]["min"], heldout["attitude_error_median"]["max"]) == (5.0, 30.0)
    track = agg["results"]["baseline"]["track"]  # the third seed has no track: averaged over the two that do
    assert track["seeds"] == 2 and track["success_rate"]["mean"] == 0.25
    assert list(agg["results"]) == ["curriculum", "baseline", "lookup"]
    assert agg["steps"]["curriculum"] == [300, 300, 300] and agg["steps"]["lookup"] == [None] * 3
    table = tool.format_table(agg)
    assert heldout["precise_success_rate"]["mean"] == 0.125
    assert ("| curriculum | heldout | 25.0 [0.0, 50.0] | 12.5 [0.0, 25.0] | 0.300 [0.200, 0.400] | "
            "15.0 [5.0, 30.0] |") in table
    assert "| lookup | track (2/3 seeds) |" in table
    assert "Seeds: 0, 1, 7" in table and "seed 1: 2.5, seed 7: -" in table and "curriculum 300" in table
    with pytest.raises(ValueError, match="no summaries"):
        tool.aggregate([])


def test_seeds_aggregation_shows_the_evaluations_at_each_lesson_end_beside_the_final():
    tool = load_tool("benchmark_seeds")
    summaries = [summary(1.0, 0.01, 1.0), summary(0.5, 0.02, 2.0)]
    for s, rate in zip(summaries, (0.9, 0.7)):
        s["lesson_ends"] = {"curriculum": {"heldout_after_lesson3": {"success_rate": rate}}, "baseline": {}}
    agg = tool.aggregate(summaries)
    assert agg["results"]["curriculum"]["heldout_after_lesson3"]["success_rate"]["mean"] == pytest.approx(0.8)
    assert "heldout_after_lesson3" not in agg["results"]["baseline"]
    assert agg["results"]["curriculum"]["heldout"]["success_rate"]["mean"] == 0.75
    assert "| curriculum | heldout_after_lesson3 | 80.0 [70.0, 90.0] |" in tool.format_table(agg)


def test_benchmark_seeds_is_the_sweep_with_its_own_default_directory(monkeypatch):
    """tools/benchmark_seeds.py hands its arguments to robostrich-sweep (tests/test_sweep.py runs it
    for real), keeping its old default directory."""
    tool = load_tool("benchmark_seeds")
    from agents.robostrich.sweep import command as sweep
    calls = []
    monkeypatch.setattr(sweep, "cli", lambda argv: calls.append(argv) or 0)
    assert tool.main(["--seeds", "0,1", "--steps", "600"]) == 0
    assert tool.main(["--out=x", "--seeds", "2"]) == 0
    assert calls == [["--seeds", "0,1", "--steps", "600", "--out", "runs/seeds"], ["--out=x", "--seeds", "2"]]


def test_benchmark_dmc_end_to_end_on_cartpole(tmp_path, tool_env):
    out = tmp_path / "dmc"
    # min-replay 20 transitions = 160 control steps at action repeat 8: the agent learns before each evaluation
    run_tool("benchmark_dmc", "--tasks", "cartpole/swingup", "--steps", "400", "--eval-at", "200,400",
             "--min-replay-size", "20", "--hidden-sizes", "16,16", "--batch-size", "16", "--eval-episodes", "2",
             "--out", str(out), "--quiet", cwd=tmp_path, env=tool_env)
    result = json.loads((out / "dmc.json").read_text())
    rows = result["rows"]
    assert [(r["task"], r["seed"], r["eval_step"]) for r in rows] == [("cartpole/swingup", 0, 200),
                                                                     ("cartpole/swingup", 0, 400)]
    for r in rows:
        assert math.isfinite(r["return_mean"]) and math.isfinite(r["return_std"]) and r["episodes"] == 2
        assert r["action_repeat"] == 8 and r["env_steps"] >= r["eval_step"] and r["updates"] > 0
    assert result["configs"]["cartpole/swingup"]["action_repeat"] == 8
    assert "| cartpole/swingup | 0 | 400 |" in (out / "dmc.md").read_text()
    record = results_page.make_record("dmc", str(out / "dmc.json"), "On dm_control", date="2026-12-04")
    assert record["kind"] == "dmc" and record["command"].startswith("python tools/benchmark_dmc.py --tasks ")
    page = results_page.render_record(record)
    last = rows[-1]["return_mean"]
    assert f"| cartpole/swingup | 200 | {rows[0]['return_mean']:.0f} |" in page
    assert f"**{last:.0f}** [{last:.0f}, {last:.0f}] | ~835 |" not in page  # no published value at 400 steps
    assert f"**{last:.0f}** [{last:.0f}, {last:.0f}] | - |" in page
    result["arguments"]["seeds"] = [0, 5]  # a record made while seed 5 still trains says so
    (out / "dmc.json").write_text(json.dumps(result))
    page = results_page.render_record(results_page.make_record("dmc", str(out / "dmc.json"), "On dm_control"))
    assert "over seeds 0 (seed 5 of the command not finished)" in page


def test_benchmark_dmc_rejects_unknown_settings_in_one_line():
    tool = load_tool("benchmark_dmc")
    assert tool.main(["--tasks", "hopper/hop", "--steps", "100"]) == 2  # no published action repeat
    args = tool.build_parser().parse_args(["--eval-at", "100000,200000"])
    assert tool.task_settings(args, "cartpole/swingup") == (100_000, 8, [100_000])
    assert tool.task_settings(args, "reacher/easy") == (200_000, 4, [100_000, 200_000])


def test_input_sensitivity_stored_inputs_hold_their_targets_and_errors_cost_success(tmp_path, tool_env):
    """The stored input of a training target, held exactly, lands on it; a 30 % constant error does not."""
    run_tool("input_sensitivity", "--errors", "0,0.3", "--every", "40", "--draws", "1", "--out", str(tmp_path / "s"),
             cwd=tmp_path, env=tool_env)
    rows = json.load(open(tmp_path / "s" / "sensitivity.json"))
    assert [r["error_fraction"] for r in rows] == [0.0, 0.3]
    exact, off = rows
    assert exact["success_rate"] == 1.0 and exact["position_error_median"] < 0.01
    assert off["success_rate"] < 1.0 and off["position_error_median"] > exact["position_error_median"]
    assert "| 30 % |" in open(tmp_path / "s" / "sensitivity.md").read()
    bad = subprocess.run([sys.executable, os.path.join(TOOLS, "input_sensitivity.py"), "--errors", "2"],
                         capture_output=True, text=True, env=tool_env, cwd=tmp_path)
    assert bad.returncode == 2 and "fractions in [0, 1]" in bad.stderr.strip().splitlines()[-1]


def test_env_benchmark_resets_its_raw_baseline_like_the_environment(capsys, tmp_path):
    """The raw mj_step baseline runs the same episodes as the environment (lesson 2: 250 control
    steps from the fixed start), as does the bare dm_control environment beside them, and the tool
    prints the rates and the median of its rounds' ratios."""
    tool = load_tool("benchmark_env")
    from robostrich_suite import speed_benchmarks
    assert speed_benchmarks.episode_steps("robostrich", "lesson2") == 250
    assert speed_benchmarks.episode_steps("robostrich", "track") == 750
    actions = speed_benchmarks.random_actions("robostrich", "lesson2")
    raw = tool.RawLoop(actions, 250)
    raw.run(300)  # an episode of 250 control steps, then 50 of the next from the fixed start
    assert raw.data.time == pytest.approx(50 * 0.008)
    wrapped = speed_benchmarks.EnvLoop("robostrich", "lesson2", actions)
    wrapped.run(300)
    assert wrapped.env.physics.data.time == pytest.approx(50 * 0.008)
    np.testing.assert_array_equal(wrapped.env.physics.data.qpos, raw.data.qpos)  # the same episodes
    bare = tool.bare_loop(actions)  # the plain dm_control floor runs them too
    bare.run(300)
    np.testing.assert_array_equal(bare.env.physics.data.qpos, raw.data.qpos)
    report = tmp_path / "speed.json"
    tool.main(["--steps", "100", "--rounds", "3", "--json", str(report)])
    lines = capsys.readouterr().out.splitlines()[:-1]  # the last: where the report went
    ratios = {line.split(":")[0].split()[1]: float(line.split(":")[1].split()[0]) for line in lines[-2:]}
    assert lines[0].startswith("raw mj_step") and "median of 3 rounds" in lines[-1]
    # the ratios are printed, not judged: on a busy machine any value can come out
    assert set(ratios) == {"bare/raw", "env/raw"} and all(math.isfinite(r) and r > 0 for r in ratios.values())
    # its report is a results record: the printed medians, with their quartiles, and the command
    record = results_page.make_record("speed", str(report), "Speed", date="2026-12-04")
    assert record["kind"] == "speed" and record["command"].endswith("--rounds 3 --json " + str(report))
    written = {row["what"]: row for row in record["data"]["ratios"]}
    env_ratio = written["robostrich/lesson2 / raw mj_step"]
    assert f"{env_ratio['value']:.3f}" == f"{ratios['env/raw']:.3f}" and env_ratio["low"] <= env_ratio["high"]
    assert f"| ratio robostrich/lesson2 / raw mj_step | **{env_ratio['value']:.3f}** [" in \
        results_page.render_record(record)


def test_a1_benchmark_says_where_an_env_step_goes(capsys, tmp_path):
    """Each part dm_control calls is timed inside a real robostrich_a1 loop: the parts and the rest
    add up to the step, the physics and the gait take time, and the record carries the shares."""
    tool = load_tool("benchmark_a1")
    actions = tool.speed_benchmarks.random_actions("robostrich_a1", "lesson4")
    parts = tool.step_parts("lesson4", 200, actions)
    assert list(parts) == [*tool.PARTS, "other"] and sum(parts.values()) == pytest.approx(1.0)
    assert all(parts[p] > 0 for p in ("physics", "before_step (gait)", "observation", "reward"))
    assert parts["physics"] > parts["reward"]  # four MuJoCo substeps cost more than one reward
    report = tmp_path / "a1.json"
    tool.main(["--steps", "100", "--repeats", "1", "--json", str(report)])
    out = capsys.readouterr().out
    assert "where an env step's time goes: physics " in out
    record = results_page.make_record("speed_a1", str(report), "Speed", date="2026-12-07")
    shares = {row["what"] for row in record["data"]["ratios"]}
    assert {f"share of an env step: {p}" for p in parts} <= shares


def test_learner_benchmark_reports_its_ratios_against_plain_versions(tmp_path, tool_env):
    """At a tiny size: the fused update and the acting loop against their plain versions, printed
    and written as a speed record (ratios, not judged: any value can come out on a busy machine)."""
    report = tmp_path / "learner.json"
    proc = run_tool("benchmark_learner", "--hidden-sizes", "16,16", "--batch", "8", "--seconds", "0.3",
                    "--json", str(report), cwd=tmp_path, env=tool_env)
    assert "ratio ours/plain = " in proc.stdout and f"wrote {report}" in proc.stdout
    record = results_page.make_record("learner", str(report), "Learner", date="2026-12-04")
    ratios = {row["what"]: row["value"] for row in record["data"]["ratios"]}
    assert set(ratios) == {"learner / plain SAC update, each loss jitted", "learner / plain SAC update without jit",
                           "EnvironmentLoop / plain loop (eager policy, lists)", "EnvironmentLoop / raw env.step"}
    assert all(math.isfinite(value) and value > 0 for value in ratios.values())
    assert record["command"].startswith("python tools/benchmark_learner.py --hidden-sizes 16,16")


def test_precision_ceiling_holds_a_stored_pose_precisely_and_counts_the_share(tmp_path, capsys):
    """A held-out target whose stored inputs hold the head on it and level within 1 cm and 2 deg
    counts as reachable, and the share is over the targets tried; bad input is one line, status 2."""
    tool = load_tool("precision_ceiling")
    result = tool.main(["--every", "84", "--seek-times", "0.1", "--out", str(tmp_path / "c")])
    assert result["targets"] == 1 and result == json.load(open(tmp_path / "c" / "ceiling.json"))
    first = result["rows"][0]
    assert first["precise"] and first["seek_time"] == 0.0  # the stored inputs alone
    assert first["position_error"] < 0.01 and first["attitude_error"] < 2.0
    assert result["precise"] == 1 and result["precise_share"] == 1.0
    for argv, message in ((["--seek-times", "-1"], "--seek-times"),
                          (["--layout", "ventral_slips_2"], "no target file ships for layout 'ventral_slips_2'")):
        with pytest.raises(SystemExit) as stopped:
            tool.main([*argv, "--out", str(tmp_path / "n")])
        error = capsys.readouterr().err.strip().splitlines()
        assert stopped.value.code == 2 and message in error[-1]


def test_the_profile_counts_each_second_of_a_run_once_and_projects_the_main_job(tmp_path):
    """A tiny run timed by part: every part measured, none negative, together no more than the run,
    the learner's compile apart from its updates, and the environment's floor beside it."""
    tool = load_tool("profile_main_job")
    result = tool.main(["--steps", "400", "--floor-steps", "50", "--json", str(tmp_path / "p.json"),
                        "--hidden-sizes", "16,16", "--batch-size", "16", "--min-replay-size", "50",
                        "--num-eval-targets", "1", "--final-eval-targets", "1", "--new-targets", "1",
                        "--track-task", ""])
    seconds, calls = result["seconds"], result["calls"]
    assert set(seconds) == set(tool.PARTS) and all(value >= 0 for value in seconds.values())
    assert result["other_seconds"] >= 0 and sum(seconds.values()) <= result["total_seconds"]
    assert calls["compiling"] == 1 and calls["learner"] > 10 and calls["environment"] > 400
    assert calls["evaluation"] >= 3 and result["floor_steps_per_second"] > 0
    written = json.load(open(tmp_path / "p.json"))
    assert written["steps"] == 400
    record = results_page.make_record("profile", str(tmp_path / "p.json"), "Profile", date="2026-12-07")
    ratios = {row["what"]: row["value"] for row in record["data"]["ratios"]}  # a speed record of ratios
    assert ratios["projected run / the environment alone"] > 1.0  # the run costs more than stepping alone
    from agents.sac.learning import SACLearner
    assert SACLearner.step.__name__ == "step"  # the timers are taken off again
