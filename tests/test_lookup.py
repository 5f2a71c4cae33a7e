"""The lookup baseline on the real arm, and evaluation on a dm_control domain without a head (reacher)."""
import collections
import json
import os

import numpy as np
import pytest
from dm_env import specs

from agents.robostrich.evaluate import episodes, evaluation
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, parse_plan
from agents.robostrich.domains import Domain, as_domain
from agents.robostrich.lookup import LookupPolicy, lookup_table
from agents.replay import ObservationFlattener
from agents.sac.builder import SACBuilder
from agents.sac.config import SACConfig
from robostrich_suite import targets

ARM = Domain("robostrich")  # the frame arm with its own routing


@pytest.fixture(scope="module")
def flattener():
    return ObservationFlattener(as_domain("robostrich").make_environment("lesson2", 0).observation_spec())


def distances(a, b):
    return np.linalg.norm(np.asarray(a)[:, None, :] - np.asarray(b)[None, :, :], axis=2)


def test_lookup_table_holds_no_pose_at_a_heldout_target():
    table = lookup_table()
    poses = targets.level_head_poses()["head_position"]
    heldout, training = targets.heldout_targets(), targets.training_targets()
    assert distances(heldout, poses).min(axis=1).max() == 0.0  # every held-out target is a stored pose ...
    assert distances(table["head_position"], heldout).min() >= targets.MIN_TARGET_SPACING  # ... none in the table
    assert distances(training, table["head_position"]).min(axis=1).max() == 0.0  # every training pose is
    assert len(table["control"]) == len(table["head_position"]) > len(training)


def test_lookup_holds_a_stored_training_pose(flattener):
    policy = LookupPolicy(flattener)
    target = targets.training_targets()[0]
    report = episodes.evaluate_heldout(policy, flattener, ARM, "lesson2", target[None])
    episode = report["episodes"][0]
    assert episode["success"], episode
    assert episode["final_position_error"] < 0.01 and episode["final_attitude_error"] < 5.0, episode
    np.testing.assert_array_equal(policy.control_for(target), lookup_table()["control"][
        np.flatnonzero(np.all(lookup_table()["head_position"] == target, axis=1))[0]])


def test_precise_success_is_the_share_within_1cm_and_2deg(flattener):
    """The stored poses are level only within the paper's 5 deg: holding them is a success at
    the paper's tolerance, but rarely a precise reach, which evaluations report beside it."""
    report = episodes.evaluate_heldout(LookupPolicy(flattener), flattener, ARM, "lesson2",
                                         targets.training_targets()[:6])
    within = [e["final_position_error"] <= 0.01 and abs(e["final_attitude_error"]) <= 2.0
              for e in report["episodes"]]
    assert report["summary"]["precise_success_rate"] == np.mean(within)
    assert report["summary"]["precise_tolerances"] == [0.01, 2.0]
    assert report["summary"]["success_rate"] == 1.0 and 0.0 < report["summary"]["precise_success_rate"] < 1.0


def test_lookup_needs_a_target_position():
    spec = collections.OrderedDict(position=specs.Array((2,), np.float64), velocity=specs.Array((2,), np.float64))
    with pytest.raises(ValueError, match="target_position"):
        LookupPolicy(ObservationFlattener(spec))


def test_heldout_moving_starts_from_poses_holding_other_targets(flattener):
    policy = LookupPolicy(flattener)
    target = targets.heldout_targets()[:1]
    report = episodes.evaluate_heldout_moving(policy, flattener, "robostrich", targets=target)
    starts, _ = Domain("robostrich").moving_starts()
    assert report["summary"]["episodes"] == 3 and [e["start"] for e in report["episodes"]] == [0, 1, 2]
    assert distances(starts, targets.training_targets()).min(axis=1).max() == 0.0  # starts are training targets
    assert distances(starts, starts)[np.triu_indices(3, 1)].min() > 0.15  # well separated (0.16 m apart at least)
    for episode in report["episodes"]:
        assert episode["start_position_error"] < 0.01  # the arm really held the start pose
        assert episode["target"] == target[0].tolist()
    # different starts give different endings: the start pose was carried into the episode
    assert len({round(e["final_position_error"], 6) for e in report["episodes"]}) > 1


def test_one_hold_per_moving_start_scores_every_target_as_a_hold_before_each_target_does(flattener):
    """The moving-start evaluation brings the arm to each start once and starts every target's episode
    from that resting state: the episodes must be those of holding the start again before each one."""
    from robostrich_suite import policies
    from robostrich_suite.tasks.measurement import measure
    policy, chosen = policies.load_policy("robostrich"), targets.heldout_targets()[:2]
    report = episodes.evaluate_heldout_moving(policy, flattener, "robostrich", targets=chosen)
    env = as_domain("robostrich").make_environment("lesson3", 30_000, target_pool=chosen[:1])
    expected = []
    for start, control in zip(*Domain("robostrich").moving_starts()):
        for target in chosen:  # as the evaluation ran before: hold the start before every target
            env.task.set_initial_state("fixed")
            env.task.set_target_pool(start)
            timestep = env.reset()
            while not timestep.last():
                timestep = env.step(control)
            held = measure(env)
            env.task.set_initial_state("continue")
            env.task.set_target_pool(target)
            row = episodes._episode_summary(episodes.rollout(env, policy, flattener))
            expected.append({**row, "start_position_error": held.position_error})
    assert len(report["episodes"]) == len(expected) == 6
    for got, want in zip(report["episodes"], expected):
        assert {k: got[k] for k in want} == want  # bit for bit
    assert len({e["final_position_error"] for e in expected}) == 6


def test_evaluation_on_reacher_reports_returns_not_nan(tmp_path):
    config = SACConfig(batch_size=32, hidden_sizes=(32, 32), min_replay_size=200, max_replay_size=5000)
    run = DomainRun(RunSpec(parse_plan("reacher/easy:1000"), config, 0), str(tmp_path / "run"))
    actor = SACBuilder.make_eval_actor(run.loop)  # untrained
    reports = evaluation.evaluate_agent(actor, run.loop.flattener, str(tmp_path / "ev"), "sac", "reacher", "easy",
                                        None, num_targets=2, record=False)
    assert list(reports) == ["heldout"]  # no moving starts or track off the arm
    summary = reports["heldout"]["summary"]
    assert set(summary) == {"episodes", "return_mean", "return_std", "return_min", "return_max"}
    assert summary["episodes"] == 2 and all(np.isfinite(v) for v in summary.values())
    text = open(os.path.join(tmp_path, "ev", "sac_heldout.json")).read()
    episodes = json.loads(text)["episodes"]
    assert "NaN" not in text and [e["steps"] for e in episodes] == [1000, 1000]
    returns = [e["return"] for e in episodes]  # the summary is of the episodes written beside it
    assert (summary["return_min"], summary["return_max"]) == (min(returns), max(returns))
    assert summary["return_mean"] == pytest.approx(np.mean(returns))
    assert 0.0 <= min(returns) and max(returns) <= 1000  # reacher pays at most 1 per step
    assert evaluation.evaluate_lookup(str(tmp_path / "ev"), "reacher", "easy", None) is None


def test_evaluation_judges_success_with_the_tasks_own_tolerances():
    """A task built with a 2 cm tolerance is scored against 2 cm, not the paper's 5 cm."""
    from robostrich_suite import targets
    from agents.robostrich.lookup import LookupPolicy
    from agents.replay import ObservationFlattener
    import robostrich_suite
    target = targets.heldout_targets()[:1]  # the lookup holds a neighbour: about a centimetre off
    results = {}
    for tolerance in (0.05, 1e-4):
        env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(
            random=0, target_pool=target, position_tolerance=tolerance))
        flattener = ObservationFlattener(env.observation_spec())
        series = episodes.rollout(env, LookupPolicy(flattener), flattener)
        results[tolerance] = episodes._episode_summary(series)
    assert results[0.05]["success"] and results[0.05]["tolerances"][0] == 0.05
    assert not results[1e-4]["success"] and results[1e-4]["tolerances"][0] == 1e-4


def test_residual_adapter_offsets_the_lookup_by_a_bounded_correction(flattener, tmp_path):
    from agents.actors import ResidualAdapter
    env = as_domain("robostrich").make_environment("lesson2", 0)
    spec = env.action_spec()
    lookup = LookupPolicy(flattener)
    adapter = ResidualAdapter(spec, lookup, scale=0.25)
    obs = flattener(env.reset().observation)
    base = lookup.select_action(obs)
    np.testing.assert_allclose(adapter.to_env(np.zeros(9), obs), base)  # zero residual = the lookup
    half = 0.5 * (spec.maximum - spec.minimum)
    np.testing.assert_allclose(adapter.to_env(np.ones(9), obs), np.minimum(base + 0.25 * half, spec.maximum))
    np.testing.assert_allclose(adapter.to_env(-np.ones(9), obs), np.maximum(base - 0.25 * half, spec.minimum))
    with pytest.raises(ValueError, match="observation"):
        adapter.to_env(np.zeros(9))
    with pytest.raises(ValueError, match="residual scale"):
        ResidualAdapter(spec, lookup, scale=0.0)
    with pytest.raises(ValueError, match="do not mix"):
        DomainRun(RunSpec(parse_plan("lesson2:100"), SACConfig(her_ratio=0.5), 0, residual_scale=0.25),
                  str(tmp_path / "mix"))


def test_untrained_residual_agent_is_the_lookup(flattener, tmp_path):
    """The policy's mean head starts at zero, so before any update the residual agent's
    deterministic action is the lookup's and it lands where the lookup lands."""
    config = SACConfig(min_replay_size=10, her_ratio=0.0)
    run = DomainRun(RunSpec(parse_plan("lesson2:100"), config, 0, residual_scale=0.25), str(tmp_path / "run"))
    actor = SACBuilder.make_eval_actor(run.loop)
    target = targets.heldout_targets()[:2]
    agent = episodes.evaluate_heldout(actor, run.loop.flattener, ARM, "lesson2", target)
    base = episodes.evaluate_heldout(LookupPolicy(flattener), flattener, ARM, "lesson2", target)
    assert len(agent["episodes"]) == len(base["episodes"]) == 2
    for a, b in zip(agent["episodes"], base["episodes"]):
        assert a["final_position_error"] == pytest.approx(b["final_position_error"], abs=1e-9)
    run.run()  # training moves it: after 100 steps with updates the policy is no longer exactly zero
    obs = run.loop.flattener(as_domain("robostrich").make_environment("lesson2", 0).reset().observation)
    assert np.abs(SACBuilder.make_eval_actor(run.loop).policy_action(obs)).max() > 0


def test_continued_episode_keeps_the_servo_command():
    """Lesson 3 starts where the last episode ended, inputs included (a real servo keeps its command)."""
    env = as_domain("robostrich").make_environment("lesson3", 0)
    spec = env.action_spec()
    held = spec.minimum + 0.6 * (spec.maximum - spec.minimum)
    timestep = env.reset()
    while not timestep.last():
        timestep = env.step(held)
    env.reset()
    np.testing.assert_allclose(env.physics.arm_control(), held)


def test_the_lookups_evaluation_is_kept_and_copied_until_what_it_depends_on_changes(tmp_path, monkeypatch):
    """The same evaluation of the lookup (routing, targets, tasks, code) is copied from the cache,
    file for file, instead of being made again; other new targets make it again."""
    monkeypatch.setenv("ROBOSTRICH_CACHE", str(tmp_path / "cache"))
    domain = evaluation.as_domain("robostrich")
    new = domain.new_targets(2)
    made = evaluation.evaluate_lookup(str(tmp_path / "a"), domain, "lesson2", None, 1, record=False, new_targets=new)
    assert set(made) == {"heldout", "heldout_moving", "new", "new_moving"}

    def evaluated_again(*args, **kwargs):
        raise AssertionError("the lookup was evaluated again")
    monkeypatch.setattr(evaluation, "evaluate_agent", evaluated_again)
    ticks = []
    copied = evaluation.evaluate_lookup(str(tmp_path / "b"), domain, "lesson2", None, 1, record=False,
                                        new_targets=new, on_episode=lambda: ticks.append(1))
    assert json.loads(json.dumps(made)) == copied
    assert sorted(os.listdir(tmp_path / "b")) == sorted(os.listdir(tmp_path / "a"))
    assert len(ticks) == evaluation.episode_count(domain, 1, None, 2)  # the progress bar still fills
    with pytest.raises(AssertionError, match="evaluated again"):
        evaluation.evaluate_lookup(str(tmp_path / "c"), domain, "lesson2", None, 1, record=False, new_targets=new[:1])
