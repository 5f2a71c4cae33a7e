"""The parts a reaching task composes, each alone: the target sampler, the start distribution and
the task's default configuration (the environment-level behaviour is in test_robostrich_env.py)."""
import dataclasses

import numpy as np
import pytest

import robostrich_suite
from robostrich_suite.tasks import reach, starts, target_samplers

POOL = np.array([[0.1, 0.3], [0.2, 0.4], [0.3, 0.5]])


def test_failure_sampler_draws_missed_targets_more_often_and_uniform_ignores_misses():
    rng = np.random.RandomState(0)
    sampler = target_samplers.TargetSampler(POOL, "failures")
    for _ in range(300):  # target 2 is always missed, the others always reached
        target = sampler.draw(rng, "fixed")
        sampler.record(bool(target[0] < 0.25))
    shares = sampler.tries / sampler.tries.sum()
    assert shares[2] > 0.6 and sampler.failures[2] == sampler.tries[2] and sampler.failures[:2].sum() == 0
    uniform = target_samplers.TargetSampler(POOL, "uniform")
    draws = [int(np.argmin(np.abs(uniform.draw(rng, "fixed") - POOL).sum(1))) for _ in range(600)]
    assert np.bincount(draws, minlength=3).min() > 150  # every target about a third
    both = target_samplers.TargetSampler(POOL, "continue_failures")
    assert both.by_failures("continue") and not both.by_failures("fixed")


def test_sampler_refuses_bad_pools_and_names():
    with pytest.raises(ValueError, match="target_sampling"):
        target_samplers.TargetSampler(POOL, "worst")
    with pytest.raises(ValueError, match=r"\(n, 2\)"):
        target_samplers.TargetSampler(np.zeros((4, 3)))
    with pytest.raises(ValueError, match="far outside"):
        target_samplers.TargetSampler([[5.0, 0.0]])


def test_start_distribution_checks_its_shares_and_inputs():
    with pytest.raises(ValueError, match="initial_state"):
        starts.StartDistribution("sideways")
    with pytest.raises(ValueError, match="stored_starts must be a share"):
        starts.StartDistribution("continue", stored_starts=1.5)
    with pytest.raises(ValueError, match="needs start_inputs"):
        starts.StartDistribution("fixed", fixed_stored_starts=0.5)
    with pytest.raises(ValueError, match="release_time"):
        starts.StartDistribution("continue", release_time=0.0)


def test_start_distribution_settles_at_a_stored_input_on_the_real_arm():
    """A fixed-start episode with every episode from a stored pose: the arm rests where the
    stored input holds it (not at the straight pose), and the episode's clock starts at 0."""
    env = robostrich_suite.load("robostrich", "lesson2")
    physics = env.physics
    inputs = np.full((1, len(physics.arm_control_bounds()[0])), 0.0)
    inputs[0, 1:] = 0.01  # ventral tendons in a little: the head moves forward and down
    straight = physics.head_position().copy()
    distribution = starts.StartDistribution("fixed", fixed_stored_starts=1.0, start_inputs=inputs)
    distribution.begin(physics, np.random.RandomState(0), None)
    assert physics.data.time == 0.0
    assert np.linalg.norm(physics.head_position() - straight) > 0.01
    np.testing.assert_allclose(physics.arm_control(), np.clip(inputs[0], *physics.arm_control_bounds()))


def test_default_config_is_the_papers_and_lessons_override_it():
    config = reach.default_config()
    assert (config.reward, config.initial_state, config.target_sampling) == ("lesson2", "fixed", "uniform")
    assert config.position_tolerance == 0.05 and config.attitude_tolerance == 5.0
    assert config.stored_starts == config.fixed_stored_starts == config.release_starts == 0.0
    task = reach.Reach(dataclasses.replace(config, target_pool=POOL), initial_state="continue",
                       target_sampling="failures")
    assert task.initial_state == "continue" and task.target_sampling == "failures"
    np.testing.assert_array_equal(task.target_pool, POOL)
    with pytest.raises(TypeError):
        reach.Reach(target_pool=POOL, no_such_option=1)
    lesson3 = robostrich_suite.load("robostrich", "lesson3")
    assert lesson3.task.initial_state == "continue" and lesson3.task.reward_name == "lesson2"
