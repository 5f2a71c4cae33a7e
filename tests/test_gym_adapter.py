"""The gymnasium adapter exposes the same task with gymnasium's contract."""
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from robostrich_suite import gym_adapter


def test_passes_gymnasiums_checker():
    env = gym_adapter.make("robostrich", "lesson1", seed=0, time_limit=0.08)
    check_env(env, skip_render_check=True)


def test_episode_ends_truncated_and_observation_matches_dm_env():
    env = gym_adapter.make("robostrich", "lesson2", seed=0, time_limit=0.08)
    obs, _ = env.reset(seed=3)
    assert obs.shape == env.observation_space.shape == (55,)
    joints = env.observation_slices["joint_angles"]
    np.testing.assert_array_equal(obs[joints], np.zeros(18, np.float32))
    steps, done = 0, False
    while not done:
        obs, reward, terminated, truncated, _ = env.step(np.full(9, 0.5, np.float32))
        steps += 1
        done = terminated or truncated
    assert truncated and not terminated and steps == 10
    head = env.dm_env.physics.head_position()[[0, 2]]
    np.testing.assert_allclose(obs[env.observation_slices["head_position"]], head, rtol=1e-6)
    assert reward < 0


def test_normalized_actions_map_onto_the_tendon_range():
    env = gym_adapter.make("robostrich", "lesson1", seed=0)
    spec = env.dm_env.action_spec()
    env.reset(seed=0)
    env.step(-np.ones(9, np.float32))
    np.testing.assert_allclose(env.dm_env.physics.data.ctrl, spec.minimum)
    env.step(np.zeros(9, np.float32))
    np.testing.assert_allclose(env.dm_env.physics.data.ctrl, (spec.minimum + spec.maximum) / 2)
    raw = gym_adapter.make("robostrich", "lesson1", seed=0, normalize_actions=False)
    np.testing.assert_allclose(raw.action_space.high, spec.maximum.astype(np.float32))


def test_gym_step_rejects_actions_of_the_wrong_shape_or_type():
    env = gym_adapter.make("robostrich", "lesson1", seed=0)
    env.reset(seed=0)
    for action, message in ((np.float32(0.5), "shape"), (np.zeros(8, np.float32), "shape"),
                            (np.array(["x"] * 9), "real numbers")):
        with pytest.raises(ValueError, match=message):
            env.step(action)


def test_lesson3_passes_gymnasiums_checker_and_seeded_resets_start_alike():
    """A seeded reset forgets lesson 3's carried-over pose, so equal seeds give equal episodes."""
    env = gym_adapter.make("robostrich", "lesson3", seed=0, time_limit=0.08)
    check_env(env, skip_render_check=True)
    first, _ = env.reset(seed=5)
    for _ in range(5):
        env.step(np.ones(9, np.float32))
    again, _ = env.reset(seed=5)
    np.testing.assert_array_equal(first, again)


def test_step_after_the_episode_ended_asks_for_a_reset():
    import gymnasium
    env = gym_adapter.make("robostrich", "lesson1", seed=0, time_limit=0.016)
    with pytest.raises(gymnasium.error.ResetNeeded):
        env.step(np.zeros(9, np.float32))
    env.reset(seed=0)
    env.step(np.zeros(9, np.float32))
    _, _, _, truncated, _ = env.step(np.zeros(9, np.float32))
    assert truncated
    with pytest.raises(gymnasium.error.ResetNeeded, match="reset"):
        env.step(np.zeros(9, np.float32))
