"""The task's measurement (robostrich_suite/tasks/measurement.py) is the one reading of a step:
it agrees with the reward's success and is gymnasium's info, on a real simulation."""
import math

import numpy as np
import pytest
from dm_control import suite

import robostrich_suite
from robostrich_suite import gym_adapter, targets
from agents.robostrich.evaluate import episodes
from robostrich_suite import load_policy
from robostrich_suite.tasks.measurement import errors, measure


def test_a_reaching_tasks_measurement_is_its_rewards_success_and_gyms_info():
    """Eq. 10 with its shaping weighed 0 pays 0 exactly when the head is within both tolerances.
    Holding a stored level pose's inputs reaches that pose: the episode has steps on both sides."""
    poses = targets.level_head_poses()
    target, inputs = poses["head_position"][0], poses["control"][0].astype(np.float32)
    env = gym_adapter.make("robostrich", "lesson2", seed=0, normalize_actions=False, target_pool=np.asarray([target]),
                           weights=dict(position_error=0.0, attitude_error=0.0))
    env.reset(seed=0)
    task, physics = env.dm_env.task, env.dm_env.physics
    successes, done = [], False
    while not done:
        _, reward, terminated, truncated, info = env.step(inputs)
        done = terminated or truncated
        measured = measure(env.dm_env)
        assert measured.is_success == (reward == 0.0) == task.is_success(physics)
        assert measured.position_error == task.position_error(physics)
        assert measured.attitude_error == task.attitude_error(physics)
        assert errors(env.dm_env) == (measured.position_error, measured.attitude_error)
        assert set(info) == set(measured.as_dict())
        for key, value in measured.as_dict().items():
            np.testing.assert_array_equal(info[key], value, err_msg=key)
        np.testing.assert_array_equal(measured.target, task.target_position)
        successes.append(measured.is_success)
    assert not successes[0] and successes[-1]
    assert measured.head_in_world[[0, 2]] == pytest.approx(measured.head_position)
    assert (measured.position_tolerance, measured.attitude_tolerance) == (0.05, 5.0)


def test_point_mass_is_measured_by_its_distance_and_other_domains_by_nothing():
    env = suite.load("point_mass", "easy", task_kwargs={"random": 0})
    env.reset()
    measured = measure(env)
    assert measured.position_error == env.physics.mass_to_target_dist() and measured.attitude_error == 0.0
    assert measured.is_success == (measured.position_error <= 0.05) and measured.target is None
    assert errors(env) == (measured.position_error, 0.0)
    env = suite.load("cartpole", "balance", task_kwargs={"random": 0})
    env.reset()
    measured = measure(env)
    assert math.isnan(measured.position_error) and not measured.is_success and measured.head_position is None


@pytest.mark.parametrize("domain", ["robostrich", "robostrich_a1"])
def test_an_evaluation_that_keeps_only_the_errors_summarises_its_episode_as_the_full_reading(domain):
    """The shipped policy's episode towards a stored pose, read in full and by its errors alone."""
    policy = load_policy(domain)
    env = robostrich_suite.load(domain, "lesson2", task_kwargs={"random": 3})  # the same target for both
    full = episodes.rollout(env, policy, policy.flatten)
    lean = episodes.rollout(robostrich_suite.load(domain, "lesson2", task_kwargs={"random": 3}), policy,
                            policy.flatten, errors_only=True)
    assert lean["position_error"] == full["position_error"] and lean["reward"] == full["reward"]
    assert episodes._episode_summary(lean) == episodes._episode_summary(full)
    assert len(full["position_error"]) == 250 and min(full["position_error"]) < 0.05
    with pytest.raises(ValueError, match="on_step"):
        episodes.rollout(env, policy, policy.flatten, on_step=print, errors_only=True)
