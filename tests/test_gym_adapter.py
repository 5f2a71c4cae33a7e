"""The gymnasium adapter exposes the same task with gymnasium's contract."""
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from robostrich_suite import gym_adapter, targets


def test_passes_gymnasiums_checker():
    env = gym_adapter.make("robostrich", "lesson1", seed=0, time_limit=0.08)
    check_env(env, skip_render_check=True)


def test_episode_ends_truncated_and_observation_matches_dm_env():
    env = gym_adapter.make("robostrich", "lesson2", seed=0, time_limit=0.08)
    obs, _ = env.reset(seed=3)
    assert obs.shape == env.observation_space.shape == (46,)
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


def red_pixels(frame):
    frame = frame.astype(int)
    return (frame[..., 0] > 2 * frame[..., 1] + 30) & (frame[..., 0] > 2 * frame[..., 2] + 30)  # not the orange head


def test_a_rendered_frame_draws_the_target_where_the_task_puts_it_and_depth_stays_a_measurement():
    import os
    if os.environ.get("MUJOCO_GL") != "egl":
        pytest.skip("renders under MUJOCO_GL=egl")
    env = gym_adapter.make("robostrich", "lesson2", seed=0, render_mode="rgb_array", width=200, height=150)
    env.reset(seed=0)
    physics, task = env.unwrapped.dm_env.physics, env.unwrapped.dm_env.task
    centres = []
    for target in ([-0.2, 0.3], [0.2, 0.3]):
        task.target_position = np.array(target)
        red = red_pixels(env.render())
        assert red.sum() > 20, red.sum()
        centres.append(np.argwhere(red).mean(axis=0))
    assert abs(centres[1][1] - centres[0][1]) > 10  # 40 cm along the arm's plane: the dot moves across the frame
    depth = physics.render(height=150, width=200, camera_id="side", depth=True)
    physics.show_target_of(None)
    assert red_pixels(physics.render(height=150, width=200, camera_id="side")).sum() == 0  # the robot has no red
    np.testing.assert_array_equal(depth, physics.render(height=150, width=200, camera_id="side", depth=True))


def test_rgb_array_render_shows_the_arm_and_check_env_renders():
    """render_mode='rgb_array': a real frame under EGL."""
    import os
    if os.environ.get("MUJOCO_GL") != "egl":
        pytest.skip("renders under MUJOCO_GL=egl")
    env = gym_adapter.make("robostrich", "lesson1", seed=0, time_limit=0.6, render_mode="rgb_array",
                           width=160, height=120)
    assert env.metadata["render_fps"] == 125
    check_env(env)  # including gymnasium's render check
    env.reset(seed=0)
    straight = env.render()
    assert straight.shape == (120, 160, 3) and straight.dtype == np.uint8
    assert straight.std() > 5  # not a blank image
    for _ in range(60):  # pull the ventral tendons: the neck bends, the picture changes
        env.step(np.r_[-1.0, np.ones(8)].astype(np.float32))
    bent = env.render()
    assert np.abs(bent.astype(int) - straight.astype(int)).mean() > 0.5
    assert gym_adapter.make("robostrich", "lesson1").render() is None  # no render mode: gymnasium's warning, None
    with pytest.raises(ValueError, match="render_mode"):
        gym_adapter.make("robostrich", "lesson1", render_mode="human")
    with pytest.raises(ValueError, match="100000 x 480 exceeds the model's offscreen framebuffer"):
        gym_adapter.make("robostrich", "lesson1", render_mode="rgb_array", width=100000)


def test_every_task_is_registered_with_gymnasium():
    import gymnasium
    import robostrich_suite
    ids = [f"{domain}/{task}-v0" for domain, task in robostrich_suite.ALL_TASKS]
    assert "robostrich/lesson2-v0" in ids and "robostrich_a1/head_stabilize-v0" in ids
    assert all(env_id in gymnasium.registry for env_id in ids)
    env = gymnasium.make("robostrich/lesson2-v0", time_limit=0.08, position_tolerance=0.02)
    obs, _ = env.reset(seed=1)
    assert obs.shape == env.observation_space.shape
    assert env.unwrapped.dm_env.task.position_tolerance == 0.02  # keyword arguments reach the task
    steps, truncated = 0, False
    while not truncated:
        *_, truncated, _ = env.step(env.action_space.sample())
        steps += 1
    assert steps == 10


def test_osmesa_without_its_library_is_a_clear_import_error():
    """MUJOCO_GL=osmesa failed deep in PyOpenGL ('NoneType' object has no attribute 'glGetError');
    it names the backend and the library to install, or renders where OSMesa is installed."""
    import ctypes.util
    import os
    import subprocess
    import sys
    code = ("from robostrich_suite import gym_adapter; "
            "env = gym_adapter.make('robostrich', 'lesson1', render_mode='rgb_array', width=64, height=48); "
            "env.reset(seed=0); print(env.render().shape)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                            env={**os.environ, "MUJOCO_GL": "osmesa"})
    if ctypes.util.find_library("OSMesa"):
        assert result.returncode == 0 and "(48, 64, 3)" in result.stdout, result.stderr[-2000:]
    else:
        last = result.stderr.strip().splitlines()[-1]
        assert result.returncode != 0 and last.startswith("ImportError: "), result.stderr[-2000:]
        assert "MUJOCO_GL='osmesa'" in last and "libosmesa6" in last and "MUJOCO_GL=egl" in last


def test_info_holds_the_tasks_success_and_errors():
    """info carries what the task measures: its success test and the head's errors, as gymnasium
    users (HER's is_success) expect. Holding a stored level pose's inputs reaches that pose."""
    poses = targets.level_head_poses()
    target, inputs = poses["head_position"][0], poses["control"][0]
    env = gym_adapter.make("robostrich", "lesson2", seed=0, normalize_actions=False,
                           target_pool=np.asarray([target]))
    obs, info = env.reset(seed=0)
    assert {"is_success", "position_error", "attitude_error", "target"} <= set(info) and not info["is_success"]
    np.testing.assert_allclose(info["target"], target)
    done = False
    while not done:
        obs, _, terminated, truncated, info = env.step(inputs.astype(np.float32))
        done = terminated or truncated
        to_target = obs[env.observation_slices["to_target"]]
        assert info["position_error"] == pytest.approx(float(np.linalg.norm(to_target)), abs=1e-6)
        assert info["is_success"] == (info["position_error"] <= 0.05 and abs(info["attitude_error"]) <= 5.0)
    assert info["is_success"] and info["position_error"] < 0.02, info
