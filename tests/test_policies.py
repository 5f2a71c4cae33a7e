"""Shipped policies: the default robot's policy reaches its targets with numpy alone, a policy
refuses a robot it was not trained on, an exported policy acts as its run's evaluation actor,
and robostrich-play runs it as an installed command."""
import dataclasses
import json
import subprocess

import numpy as np
import pytest
from conftest import console_script

import robostrich_suite
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, parse_plan
from agents.robostrich.domains import domain_of
from agents.robostrich.evaluate.episodes import evaluate_track
from agents.robostrich.evaluate.policy_export import export_policy
from agents.sac.builder import SACBuilder
from agents.sac.config import SACConfig
from robostrich_suite import policies
from robostrich_suite.model import layouts


@pytest.mark.parametrize("name", ["robostrich", "robostrich_robust"])
def test_shipped_policy_reaches_every_track_target(name):
    """The frame's policies, the nominal one and the one trained with latency (which observes its
    sent actions: the policy file says so, and the domain is rebuilt from it)."""
    policy = robostrich_suite.load_policy(name)
    report = evaluate_track(policy, policy.flatten, domain_of(policy.info))
    assert len(report["segments"]) == 3
    assert report["summary"]["success_rate"] == 1.0, [s["final_position_error"] for s in report["segments"]]


def test_policy_refuses_another_robot():
    policy = robostrich_suite.load_policy("robostrich")
    other = robostrich_suite.load("robostrich", "lesson2", task_kwargs=layouts.task_kwargs("antagonist_pairs"))
    with pytest.raises(policies.PolicyMismatch, match="trained on model"):
        policy.check(other)
    with pytest.raises(policies.PolicyMismatch):
        robostrich_suite.load_policy("robostrich", other)
    own = robostrich_suite.load("robostrich", "lesson2")
    policy.check(own)  # its own robot passes, and track, which observes more than the policy reads
    policy.check(robostrich_suite.load("robostrich", "track"))
    reads_more = dataclasses.replace(policy, observation_layout=policy.observation_layout + (("gaze", 2),))
    with pytest.raises(policies.PolicyMismatch, match="gaze"):
        reads_more.check(own)


def test_policy_file_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.npz"
    np.savez(bad, something=np.zeros(3))
    with pytest.raises(ValueError, match="bad.npz: not a policy file"):
        policies.load_policy(str(bad))
    for fine in ((("gaze", 10.0),), (("to_target", -1.0),), (("to_target", 1.0), ("to_target", 2.0))):
        dataclasses.replace(policies.load_policy("robostrich"), fine_inputs=fine).save(bad)
        with pytest.raises(ValueError, match=r"bad.npz: not a policy file \(its fine_inputs .* over keys of its"):
            policies.load_policy(str(bad))
    (tmp_path / "empty.npz").write_bytes(b"")
    with pytest.raises(ValueError, match="empty.npz: not a policy file .not an .npz archive, it is empty"):
        policies.load_policy(str(tmp_path / "empty.npz"))
    (tmp_path / "text.npz").write_text("not a policy at all\n")
    with pytest.raises(ValueError, match="text.npz: not a policy file .not an .npz archive"):
        policies.load_policy(str(tmp_path / "text.npz"))
    with pytest.raises(ValueError, match="no such policy file"):
        policies.load_policy(str(tmp_path / "missing.npz"))
    with pytest.raises(ValueError, match="unknown policy 'nope'"):
        policies.load_policy("nope")


@pytest.mark.parametrize("gain, fine", [(0.0, ()), (100.0, ("to_target=100", "attitude_error=30"))])
def test_exported_policy_acts_as_its_runs_evaluation_actor(tmp_path, gain, fine):
    config = SACConfig(batch_size=16, hidden_sizes=(16, 16), min_replay_size=50, max_replay_size=2000,
                       fine_input_gain=gain, fine_inputs=fine)
    run = DomainRun(RunSpec(parse_plan("lesson1:300"), config, 3), str(tmp_path / "run"), checkpoint_every=300)
    run.run()
    path = tmp_path / "policy.npz"
    policy = export_policy(str(tmp_path / "run" / "checkpoint.ckpt"), str(path), command="a test")
    again = policies.read_policy(path)
    assert again.info["seed"] == 3 and again.info["command"] == "a test"
    assert again.info["layout"] == layouts.DEFAULT and again.fine_input_gain == gain
    assert again.fine_inputs == tuple((k, float(g)) for k, g in (item.split("=") for item in fine))
    assert again.hidden[0][0].shape[0] == 46 * (2 if gain else 1) + 3 * bool(fine)  # 2 + 1 fine inputs
    actor = SACBuilder.make_eval_actor(run.loop)
    env = robostrich_suite.load("robostrich", "lesson1", task_kwargs={"random": 0})
    again.check(env)
    timestep = env.reset()
    for _ in range(20):
        flat = run.loop.flattener(timestep.observation)
        expected = actor.select_action(flat)
        np.testing.assert_allclose(again(timestep), expected, rtol=0, atol=1e-5)
        timestep = env.step(expected)


def test_play_runs_the_shipped_policy_as_an_installed_command(tmp_path):
    result = subprocess.run([console_script("robostrich-play"), "--num-targets", "2", "--out", "played"],
                            cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    assert "track    100.0 % reached" in result.stdout, result.stdout
    report = json.loads((tmp_path / "played" / "robostrich_heldout.json").read_text())
    assert report["summary"]["episodes"] == 2
    assert (tmp_path / "played" / "robostrich_track.png").stat().st_size > 10_000
    assert (tmp_path / "played" / "robostrich_track.rrd").stat().st_size > 0
    bad = subprocess.run([console_script("robostrich-play"), "--policy", "nope.npz"], cwd=tmp_path,
                         capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and bad.stderr.strip().count("\n") == 0, bad.stderr
    assert "nope.npz: no such policy file" in bad.stderr


def test_play_runs_the_quadrupeds_shipped_policy_on_held_out_targets_and_head_stabilisation(tmp_path):
    """The arm on the quadruped ships its policy after lesson 4: it holds standing held-out targets and,
    walking, keeps the head within 1 cm of its height and level; the frame's arm refuses it."""
    result = subprocess.run([console_script("robostrich-play"), "--policy", "robostrich_a1", "--num-targets", "2",
                             "--out", "played"], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    assert "heldout  100.0 % reached" in result.stdout, result.stdout
    stabilize = json.loads((tmp_path / "played" / "robostrich_a1_head_stabilize.json").read_text())["summary"]
    assert stabilize["height_rms_error"] < 0.01 and stabilize["attitude_within_fraction"] > 0.9, stabilize
    assert stabilize["distance_mean_error"] < 0.02 and not stabilize["fell"], stabilize
    assert (tmp_path / "played" / "robostrich_a1_head_stabilize.png").stat().st_size > 10_000
    assert (tmp_path / "played" / "robostrich_a1_head_stabilize.rrd").stat().st_size > 0
    with pytest.raises(policies.PolicyMismatch):
        robostrich_suite.load_policy("robostrich_a1", robostrich_suite.load("robostrich", "lesson2"))


def test_two_policies_played_into_one_folder_keep_their_own_files(tmp_path):
    """Each file is named after its policy: the second policy's reports do not overwrite the first's."""
    out = tmp_path / "played"
    for policy in ("robostrich", "robostrich_robust"):
        result = subprocess.run([console_script("robostrich-play"), "--policy", policy, "--num-targets", "1",
                                 "--no-rerun", "--out", str(out)], capture_output=True, text=True, timeout=600)
        assert result.returncode == 0, result.stderr[-3000:]
    names = sorted(p.name for p in out.iterdir())
    assert names == sorted(f"{policy}_{kind}" for policy in ("robostrich", "robostrich_robust")
                           for kind in ("heldout.json", "track.json", "track.png")), names
    for policy in ("robostrich", "robostrich_robust"):
        assert json.loads((out / f"{policy}_heldout.json").read_text())["policy"] == policy
