"""The application evaluations (head_stabilize, narrow_gap): metrics from real, short rollouts,
and the installed commands robostrich-stabilize / robostrich-gap end to end."""
import json
import os
import subprocess

import numpy as np
import pytest

from agents.robostrich.applications import stabilize
from agents.robostrich.applications import figures as application_figures
from agents.robostrich.applications import rollouts as applications
from agents.robostrich.applications import narrow_gap as gap
from agents.robostrich.applications import stabilization
from robostrich_suite.tasks import quadruped_tasks

from conftest import console_script

ENVIRONMENT = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}


@pytest.fixture(scope="module")
def references():
    zero, lookup = applications.policies(None, None, None)
    return zero, lookup, applications.load_gait()


def test_crests_and_troughs_read_the_middle_of_an_oscillation_through_jitter():
    t = np.linspace(0, 4, 2000)
    x = 0.4 + 0.03 * np.sin(2 * np.pi * 2.5 * t) + 0.0005 * np.sin(2 * np.pi * 97 * t)
    crests, troughs = stabilization.crests_and_troughs(x)
    assert len(crests) in (9, 10) and len(troughs) in (9, 10)  # 10 cycles, jitter ignored
    assert 0.5 * (crests.mean() + troughs.mean()) == pytest.approx(0.4, abs=1e-3)


def test_holding_the_lookup_input_stabilises_the_head_better_than_zero_input(references):
    zero, lookup, gait = references
    report = stabilization.evaluate([zero, lookup], 1, gait, settle=1.0, time_limit=3.0)
    z, k = (report[label]["seeds"][0] for label in ("zero", "lookup"))
    # The series is the rollout's: 3 s of 8 ms steps, scored after the first second.
    assert len(report["zero"]["series"]["time"]) == 375 and z["scored_steps"] == 251
    series = report["lookup"]["series"]
    assert np.all(series["desired_height"] == quadruped_tasks.HEAD_STABILIZE_HEIGHT)
    assert np.ptp(series["trunk_z"]) > 0.005 and np.ptp(series["head_vz"]) > 0  # the walk shakes the arm
    # Zero input: the neck tips forward and the head sits ~20 cm off its height; the lookup is closer.
    assert z["height_rms_error"] > 0.15 and k["height_rms_error"] < z["height_rms_error"] - 0.05
    assert k["attitude_rms_error"] < z["attitude_rms_error"]
    assert 0 <= k["attitude_within_fraction"] <= 1 and k["distance_crests"] > 3
    goals = report["zero"]["goals"]
    assert set(goals) == set(stabilization.GOALS) and not any(g["met"] for g in goals.values())
    # Fig. 9 reads each panel against its goal: every policy's worst seed, the goal, met or not
    fig = application_figures.stabilization_figure(report)
    try:
        texts = [t.get_text() for ax in fig.axes for t in ax.get_legend().get_texts()]
        height = goals["height_rms_error"]["worst"] * 100
        assert f"head (zero): height {height:.1f} cm RMS off (goal <= 1 cm, not met)" in texts
        assert any(t.startswith("lookup: level ") and "(goal >= 90 %" in t for t in texts), texts
    finally:
        import matplotlib.pyplot as plt
        plt.close(fig)


def test_narrow_gap_reports_every_sub_target_with_contact_forces_from_a_real_rollout(references):
    # On ventral_from_base zero input drives the head into the wall (on the default arm it does not).
    zero, lookup = applications.policies(None, None, "ventral_from_base")
    gait = references[2]
    # Time switching: 40 steps (0.32 s) per sub-target, all six within the 1.92 s episode.
    report = gap.evaluate([lookup], 1, gait, time_limit=1.92, steps_per_target=40)
    seed = report["lookup"]["seeds"][0]
    assert [row["target"] for row in seed["targets"]] == [1, 2, 3, 4, 5, 6]
    assert seed["switch_times_s"] == pytest.approx([0.32, 0.64, 0.96, 1.28, 1.60])
    for row in seed["targets"]:
        assert row["active_from_s"] is not None and row["max_arm_contact_force"] >= 0
        assert isinstance(row["reached"], bool) and row["min_position_error"] > 0
    assert seed["success"] is False  # the lookup cannot go round the shelf in 2 s
    # Reached switching; zero input drives the head into the wall while walking: real contact
    # forces, of the size an arm pressing on a wall has (not the stale solver rows after a step).
    report = gap.evaluate([zero, lookup], 1, gait, time_limit=3.2, switch="reached")
    zero_seed, lookup_seed = report["zero"]["seeds"][0], report["lookup"]["seeds"][0]
    assert 0 < zero_seed["max_arm_contact_force"] < 200 and zero_seed["head_touched"]
    assert lookup_seed["targets"][0]["reached"] and lookup_seed["switch_times_s"]  # moved on when reached
    assert zero_seed["reached"] == 0 and zero_seed["switch_times_s"] == []


def test_a_checkpoint_is_evaluated_beside_the_references(tmp_path):
    from agents.robostrich.domain_run import DomainRun
    from agents.robostrich.run_spec import RunSpec, parse_plan
    from agents.sac.config import SACConfig
    config = SACConfig(batch_size=16, hidden_sizes=(16, 16), min_replay_size=50, max_replay_size=1000)
    run = DomainRun(RunSpec(parse_plan("robostrich_a1/lesson1:100"), config, 0), str(tmp_path / "run"))
    run.save_checkpoint()
    result = stabilize.main(
        [run.checkpoint_path, "--reference", run.checkpoint_path, "--seeds", "1", "--time-limit", "1.5",
         "--out", str(tmp_path / "out"), "--no-rerun", "--no-figures", "--no-progress"])
    assert list(result["policies"]) == ["trained", "reference", "zero", "lookup"]
    trained = result["policies"]["trained"]["seeds"][0]
    assert trained == result["policies"]["reference"]["seeds"][0]  # the same checkpoint, deterministic
    assert np.isfinite(trained["height_rms_error"])


def test_commands_write_reports_figures_and_recordings(tmp_path, verify_rrd):
    out = tmp_path / "stabilize"
    done = subprocess.run([console_script("robostrich-stabilize"), "--seeds", "2", "--time-limit", "1.5", "--settle", "0.5",
                           "--out", str(out)], capture_output=True, text=True, env=ENVIRONMENT, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "head_stabilize on robostrich_a1" in done.stdout and "lookup" in done.stdout
    report = json.loads((out / "stabilize_report.json").read_text())
    assert list(report["policies"]) == ["zero", "lookup"] and report["seeds"] == 2
    assert len(report["policies"]["lookup"]["seeds"]) == 2
    assert (out / "stabilize_summary.txt").read_text() in done.stdout
    assert (out / "stabilize.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    recordings = [out / f"stabilize_{label}.rrd" for label in ("zero", "lookup")]

    out = tmp_path / "gap"
    done = subprocess.run([console_script("robostrich-gap"), "--seeds", "1", "--time-limit", "0.6", "--steps-per-target", "10",
                           "--out", str(out), "--no-rerun", "--gait", str(quadruped_tasks.gait_lib.DATA_PATH)],
                          capture_output=True, text=True, env=ENVIRONMENT, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    report = json.loads((out / "gap_report.json").read_text())
    assert report["gait"] == str(quadruped_tasks.gait_lib.DATA_PATH)
    assert len(report["policies"]["lookup"]["summary"]["targets"]) == 6
    assert (out / "gap.png").exists() and not list(out.glob("*.rrd"))
    verify_rrd(*recordings)  # last: without the rerun command the test skips here (conftest)


def test_a_malformed_gait_file_exits_2_with_one_line(tmp_path):
    bad = tmp_path / "gait.csv"
    bad.write_text("time,FR_hip\n0.0,0.1\n")
    done = subprocess.run([console_script("robostrich-gap"), "--gait", str(bad), "--out", str(tmp_path / "out")],
                          capture_output=True, text=True, env=ENVIRONMENT, timeout=120)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("robostrich-gap: error: ") and "line 1" in lines[0]
    assert not (tmp_path / "out").exists()  # refused before anything was written


def test_narrow_gap_refuses_an_unknown_switch():
    import robostrich_suite
    with pytest.raises(ValueError, match="unknown switch 'never'"):
        robostrich_suite.load("robostrich_a1", "narrow_gap", task_kwargs=dict(switch="never"))
