"""The robostrich domain: dm_env conformance, rewards, determinism, bad input."""
import logging
import pickle

import numpy as np
import pytest
from absl.testing import absltest
from dm_env import test_utils

import robostrich_suite
from robostrich_suite import targets
from robostrich_suite.model import arm
from robostrich_suite.tasks import rewards

TASKS = robostrich_suite.TASKS_BY_DOMAIN["robostrich"]


def test_registry_lists_the_lessons_and_track():
    assert TASKS == ("lesson1", "lesson2", "lesson3", "track")
    assert ("robostrich", "lesson3") in robostrich_suite.ALL_TASKS
    assert ("robostrich", "track") not in robostrich_suite.CURRICULUM_TASKS


def test_unknown_names_get_clear_errors():
    with pytest.raises(ValueError, match="unknown domain 'ostrich'"):
        robostrich_suite.load("ostrich", "lesson1")
    with pytest.raises(ValueError, match="no task 'lesson9'"):
        robostrich_suite.load("robostrich", "lesson9")
    with pytest.raises(TypeError):
        robostrich_suite.load("robostrich", "lesson1", task_kwargs=dict(no_such_option=1))


def _conformance_case(task_name):
    class Case(test_utils.EnvironmentTestMixin, absltest.TestCase):
        def make_object_under_test(self):
            return robostrich_suite.load("robostrich", task_name, task_kwargs=dict(
                random=0, time_limit=0.08) if task_name != "track" else dict(
                    random=0, steps_per_target=4))
    Case.__name__ = f"Conformance_{task_name}"
    return Case


for _task in TASKS:
    globals()[f"TestConformance_{_task}"] = _conformance_case(_task)


@pytest.mark.parametrize("task_name", TASKS)
def test_every_task_has_a_nine_tendon_action(task_name):
    env = robostrich_suite.load("robostrich", task_name, task_kwargs=dict(random=0))
    spec = env.action_spec()
    assert spec.shape == (9,)
    assert np.all(spec.minimum < 0) and np.all(spec.maximum > 0)
    assert env.control_timestep() == pytest.approx(0.008)


def test_observation_names_and_sizes():
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=0))
    shapes = {k: v.shape for k, v in env.observation_spec().items()}
    assert shapes == {"head_position": (2,), "head_velocity": (2,), "joint_angles": (18,),
                      "target_position": (2,), "to_target": (2,), "attitude_error": (1,),
                      "head_attitude": (1,), "tendon_contraction": (9,),
                      "tendon_tension": (9,)}


def _pose_env(task_name, target):
    env = robostrich_suite.load("robostrich", task_name,
                                task_kwargs=dict(random=0, target_pool=[target]))
    env.reset()
    return env


def _bend(physics, angle_rad):
    with physics.reset_context():
        physics.data.qpos[:] = angle_rad


def test_lesson1_reward_is_eq9():
    env = _pose_env("lesson1", [0.3, 0.4])
    physics, task = env.physics, env.task
    _bend(physics, 0.05)
    head = np.array(physics.named.data.site_xpos["arm/head"])[[0, 2]]
    assert task.get_reward(physics) == -1.0  # far from (0.3, 0.4)
    task.target_position = head + np.array([0.03, 0.0])
    assert task.get_reward(physics) == 0.0  # within d = 0.05
    task.target_position = head + np.array([0.0, 0.051])
    assert task.get_reward(physics) == -1.0


def test_lesson2_reward_is_eq10():
    env = _pose_env("lesson2", [0.3, 0.4])
    physics, task = env.physics, env.task
    _bend(physics, 0.08)
    head = np.array(physics.named.data.site_xpos["arm/head"])[[0, 2]]
    axis = np.array(physics.named.data.xmat["arm/atlas"]).reshape(3, 3)[:, 2]
    attitude = np.degrees(np.arctan2(axis[0], axis[2]))
    assert attitude == pytest.approx(np.degrees(0.08 * 18), abs=1e-6)  # 18 joints bent equally
    error = np.linalg.norm(head - [0.3, 0.4])
    w = task.weights
    expected = (-w.position_miss * (error > 0.05) - w.attitude_miss * (abs(attitude - 90) > 5)
                - w.position_error * error - w.attitude_error * abs(attitude - 90))
    assert task.get_reward(physics) == pytest.approx(expected, abs=1e-9)
    # Inside both tolerances only the shaping terms remain.
    task.target_position = head + [0.01, 0.0]
    task.desired_attitude = attitude + 2.0
    assert task.get_reward(physics) == pytest.approx(
        -w.position_error * 0.01 - w.attitude_error * 2.0, abs=1e-9)


def test_reward_weights_are_task_kwargs():
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(
        random=0, weights=dict(position_miss=0, attitude_miss=0, position_error=1,
                               attitude_error=0)))
    env.reset()
    error = env.task.position_error(env.physics)
    assert env.task.get_reward(env.physics) == pytest.approx(-error)
    assert rewards.lesson2_reward(0.0, 0.0, 0.05, 5.0) == 0.0


def test_precision_term_pays_inside_the_tolerance():
    """Eq. 10 pays 2 per metre inside 5 cm; the optional Gaussian term makes 1 cm clearly
    better than 3 cm, equals eq. 10 at 0 weight, and the array form agrees."""
    plain = rewards.RewardWeights()
    precise = rewards.RewardWeights(position_precision=1.0, precision_scale=0.01)
    errors = np.array([0.0, 0.01, 0.03, 0.2])
    eq10 = [rewards.lesson2_reward(e, 1.0, 0.05, 5.0, plain) for e in errors]
    with_term = [rewards.lesson2_reward(e, 1.0, 0.05, 5.0, precise) for e in errors]
    np.testing.assert_allclose(np.subtract(eq10, with_term),
                               [0.0, 1 - np.exp(-0.5), 1 - np.exp(-4.5), 1.0], atol=1e-9)
    assert with_term[1] - with_term[2] > 0.5 > eq10[1] - eq10[2]
    np.testing.assert_allclose(rewards.lesson2_rewards(errors, np.ones(4), 0.05, 5.0, precise),
                               with_term)
    level = rewards.RewardWeights(attitude_precision=1.0, attitude_precision_scale=1.0)
    assert (rewards.lesson2_reward(0.01, 0.0, 0.05, 5.0, level)
            - rewards.lesson2_reward(0.01, 2.0, 0.05, 5.0, level)) == pytest.approx(
        0.02 * 2.0 + 1 - np.exp(-2.0))
    np.testing.assert_allclose(rewards.lesson2_rewards([0.01, 0.01], [0.0, -2.0], 0.05, 5.0, level),
                               [rewards.lesson2_reward(0.01, a, 0.05, 5.0, level) for a in (0.0, -2.0)])
    with pytest.raises(ValueError, match="precision_scale"):
        rewards.RewardWeights(precision_scale=0.0)
    with pytest.raises(ValueError, match="position_precision"):
        rewards.RewardWeights(position_precision=float("nan"))


def test_action_change_term_charges_the_inputs_change_per_step():
    """With ``weights.action_change`` the reward drops by the weight times the mean |change| of the
    tendon inputs written this step (after clipping, so a request beyond the range costs only what
    moved); a repeated input costs nothing, and the weight 0 default leaves the reward as it was."""
    weights = dict(position_precision=1.0, attitude_precision=0.5)
    charged = robostrich_suite.load("robostrich", "lesson2",
                                    task_kwargs=dict(random=0, weights={**weights, "action_change": 50.0}))
    plain = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=0, weights=weights))
    charged.reset(), plain.reset()
    high = charged.action_spec().maximum
    for action in (np.zeros(9), np.full(9, 0.004), np.full(9, 0.004), np.full(9, 1.0), np.zeros(9)):
        before = charged.physics.arm_control()
        difference = charged.step(action).reward - plain.step(action).reward
        moved = np.mean(np.abs(charged.physics.arm_control() - before))
        assert difference == pytest.approx(-50.0 * moved, abs=1e-12)
        np.testing.assert_array_equal(charged.physics.data.qpos, plain.physics.data.qpos)  # same motion
    assert moved == pytest.approx(np.mean(high))  # the last step: from the clipped maximum back to 0


def _rollout(seed, actions):
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=seed))
    ts = env.reset()
    states = [ts.observation["target_position"].copy()]
    for action in actions:
        ts = env.step(action)
        states.append(np.concatenate([env.physics.data.qpos, env.physics.data.qvel, [ts.reward]]))
    return states


def test_same_seed_same_actions_same_trajectory():
    rng = np.random.default_rng(3)
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=0))
    spec = env.action_spec()
    actions = rng.uniform(spec.minimum, spec.maximum, size=(60, 9))
    first, second = _rollout(7, actions), _rollout(7, actions)
    for a, b in zip(first, second):
        np.testing.assert_array_equal(a, b)
    other = _rollout(8, actions)
    assert not np.array_equal(first[0], other[0])  # another seed, another target


@pytest.mark.parametrize("domain", ["robostrich", "robostrich_a1"])
@pytest.mark.parametrize("action, message", [
    (np.zeros((1, 9)), r"shape \(9,\), got shape \(1, 9\)"),
    (np.zeros(1), r"shape \(9,\), got shape \(1,\)"),
    (0.01, r"shape \(9,\), got shape \(\)"),
    (np.zeros(8), r"got shape \(8,\)"),
    (np.zeros(10), r"got shape \(10,\)"),
    (["a"] * 9, r"real numbers .*dtype <U1"),
    (np.zeros(9, bool), r"dtype bool"),
    (np.zeros(9, complex), r"dtype complex128"),
    (None, r"dtype object"),
])
def test_malformed_actions_raise_naming_expected_and_received(domain, action, message):
    env = robostrich_suite.load(domain, "lesson1", task_kwargs=dict(random=0))
    env.reset()
    with pytest.raises(ValueError, match=message):
        env.step(action)


def test_nan_action_raises_and_out_of_range_is_clipped():
    env = robostrich_suite.load("robostrich", "lesson1", task_kwargs=dict(random=0))
    env.reset()
    spec = env.action_spec()
    env.step(np.full(9, 0.01))
    action = np.zeros(9)
    action[4] = np.nan
    with pytest.raises(ValueError, match=r"non-finite values at indices \[4\]"):
        env.step(action)
    # The check clips straight into the simulation's controls, and writes nothing it rejects.
    np.testing.assert_array_equal(env.physics.data.ctrl, np.minimum(0.01, spec.maximum))
    with pytest.raises(ValueError, match=r"shape \(9,\), got shape \(8,\)"):
        env.step(np.zeros(8))
    np.testing.assert_array_equal(env.physics.data.ctrl, np.minimum(0.01, spec.maximum))
    env.step(np.full(9, 1e-3, dtype=np.float32))  # float32 and ints clip like float64
    np.testing.assert_array_equal(env.physics.data.ctrl, np.float64(np.float32(1e-3)))
    env.step(np.full(9, 10.0))
    np.testing.assert_array_equal(env.physics.data.ctrl, spec.maximum)
    env.step(np.full(9, -10.0))
    np.testing.assert_array_equal(env.physics.data.ctrl, spec.minimum)
    # The per-step readers follow an edit of the model's ranges, each physics its own model's.
    copy = env.physics.copy()
    env.physics.model.actuator_ctrlrange[:, 1] = 0.5 * spec.maximum
    env.physics.model.actuator_forcerange[:, 0] *= 2.0
    env.step(np.full(9, 10.0))
    np.testing.assert_array_equal(env.physics.data.ctrl, 0.5 * spec.maximum)
    np.testing.assert_allclose(env.physics.tendon_tensions(), env.physics.tendon_forces()
                               / -env.physics.model.actuator_forcerange[:, 0])
    np.testing.assert_array_equal(copy.arm_control_bounds()[1], spec.maximum)  # its model is unchanged


def test_divergence_ends_the_episode_with_a_logged_reason(caplog):
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=0))
    env.reset()
    env.step(np.zeros(9))
    env.physics.data.qvel[3] = np.inf
    with caplog.at_level(logging.WARNING):
        ts = env.step(np.zeros(9))
    assert ts.last() and ts.discount == 0.0
    assert np.isfinite(ts.reward)
    assert "diverged" in caplog.text
    ts = env.step(np.zeros(9))  # the next step starts a fresh, finite episode
    assert ts.first() and np.all(np.isfinite(env.physics.data.qpos))


def _records_of_divergence(caplog):
    return [r for r in caplog.records if "diverged" in r.getMessage()]


@pytest.mark.parametrize("domain", ["robostrich", "robostrich_a1"])
def test_a_stiff_arm_diverges_and_each_episode_logs_it_once_with_a_count(domain, caplog):
    # Joints 10^6 times stiffer than the real ones blow up within the first control step.
    stiff_arm = arm.ArmSpec.from_table1(joint_stiffness=1e6)
    with pytest.warns(UserWarning, match="another arm|default arm"):
        env = robostrich_suite.load(domain, "lesson2", task_kwargs=dict(
            random=0, arm_spec=stiff_arm, time_limit=1.0))
    spec = env.action_spec()
    with caplog.at_level(logging.WARNING):
        for episode in (1, 2, 3):
            caplog.clear()
            ts = env.reset()
            while not ts.last():
                ts = env.step(spec.maximum)
            assert ts.discount == 0.0
            lines = _records_of_divergence(caplog)
            assert len(lines) == 1, [r.getMessage() for r in caplog.records]
            assert f"in episode {episode}, ending it ({episode} of {episode} episodes" \
                in lines[0].getMessage()
            assert "QACC" in lines[0].getMessage()  # MuJoCo's own warning, quoted in the line
            assert not [r for r in caplog.records if r.name == "absl"]


def test_lesson2_starts_fixed_and_lesson3_continues():
    action = np.full(9, 0.01)
    for task_name, continues in (("lesson2", False), ("lesson3", True)):
        env = robostrich_suite.load("robostrich", task_name,
                                    task_kwargs=dict(random=0, time_limit=0.4))
        ts = env.reset()
        np.testing.assert_array_equal(ts.observation["joint_angles"], np.zeros(18))
        while not ts.last():
            ts = env.step(action)
        final = ts.observation["joint_angles"]
        assert np.abs(final).max() > 0.02
        ts = env.reset()
        if continues:
            np.testing.assert_array_equal(ts.observation["joint_angles"], final)
        else:
            np.testing.assert_array_equal(ts.observation["joint_angles"], np.zeros(18))


def test_lesson3_continues_from_wherever_the_arm_was_reset():
    """A reset in mid-episode, and one after pickling (a checkpoint), continue from the live pose;
    after forget_last_state, from the fixed pose."""
    env = robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(random=0))
    env.reset()
    for _ in range(30):
        ts = env.step(np.full(9, 0.01))
    moved = ts.observation["joint_angles"].copy()
    assert np.abs(moved).max() > 0.02
    ts = env.reset()  # mid-episode
    np.testing.assert_array_equal(ts.observation["joint_angles"], moved)
    for _ in range(5):
        env.step(np.zeros(9))
    unpickled = pickle.loads(pickle.dumps(env))
    np.testing.assert_array_equal(unpickled.reset().observation["joint_angles"], env.reset().observation["joint_angles"])
    env.task.forget_last_state()
    np.testing.assert_array_equal(env.reset().observation["joint_angles"], np.zeros(18))


def test_track_visits_targets_in_order():
    three = np.array([[0.2, 0.3], [0.3, 0.2], [0.1, 0.4]])
    env = robostrich_suite.load("robostrich", "track",
                                task_kwargs=dict(random=0, targets=three, steps_per_target=5))
    ts = env.reset()
    seen = [ts.observation["target_position"].copy()]
    count = 0
    while not ts.last():
        ts = env.step(np.zeros(9))
        count += 1
        seen.append(ts.observation["target_position"].copy())
        head = env.physics.head_position()[[0, 2]]
        assert ts.observation["position_error"][0] == pytest.approx(
            np.linalg.norm(head - ts.observation["target_position"]))
    assert count == 15
    np.testing.assert_array_equal(np.unique(np.array(seen), axis=0), np.unique(three, axis=0))
    np.testing.assert_array_equal(seen[0], three[0])
    np.testing.assert_array_equal(seen[-1], three[2])


def test_default_track_targets_are_held_out_level_poses():
    env = robostrich_suite.load("robostrich", "track", task_kwargs=dict(random=0))
    held_out = targets.heldout_targets()
    assert len(env.task.targets) == 3
    for target in env.task.targets:
        assert np.min(np.linalg.norm(held_out - target, axis=1)) == 0.0


@pytest.mark.parametrize("bend_deg", [9.0, 10.5, 11.5, 13.0, -12.0, -16.0, -20.0])
def test_head_attitude_is_continuous_past_180_degrees(bend_deg):
    """The attitude is the sum of the joint angles, also where atan2 would wrap (issue: lesson-2
    reward jumped at +-180 deg): 18 joints at 11.5 deg put the head at 207 deg, not -153.
    At -20 deg per joint (-360) the head points up again: attitude error -90, as at 0."""
    env = _pose_env("lesson2", [0.3, 0.4])
    physics, task = env.physics, env.task
    _bend(physics, np.radians(bend_deg))
    assert physics.head_attitude() == pytest.approx(18 * bend_deg, abs=1e-6)
    # The error is where the head points: modulo a turn, in [-180, 180).
    assert task.attitude_error(physics) == pytest.approx((18 * bend_deg - 90 + 180) % 360 - 180, abs=1e-6)
    obs = task.get_observation(physics)
    assert obs["head_attitude"][0] == pytest.approx(np.radians(18 * bend_deg), abs=1e-8)


def test_attitude_error_and_reward_have_no_jump_under_bang_bang_inputs():
    """Bang-bang tendon inputs swing the head through 180 deg; per control step the attitude
    can change only by what the joints moved, so the attitude never jumps by ~360 deg, and
    neither does the attitude part of the reward."""
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=1, time_limit=40.0))
    rng = np.random.default_rng(0)
    spec = env.action_spec()
    env.reset()
    physics = env.physics
    previous = physics.head_attitude()
    largest_step = 0.0
    crossed = False
    for step in range(1500):
        if step % 60 == 0:
            action = np.where(rng.random(9) < 0.5, spec.minimum, spec.maximum)
            action[0] = spec.minimum[0]  # dorsal slack: ventral pulls curl the head down and back
        timestep = env.step(action)
        attitude = physics.head_attitude()
        joint_sum = np.degrees(physics.joint_angles().sum())
        assert attitude == pytest.approx(joint_sum, abs=1e-6)
        largest_step = max(largest_step, abs(attitude - previous))
        miss = abs(env.task.attitude_error(physics))
        assert miss <= 180.0 and miss == pytest.approx(
            min(abs(attitude - 90) % 360, 360 - abs(attitude - 90) % 360), abs=1e-6)
        crossed |= attitude > 180.0
        previous = attitude
        if timestep.last():
            break
    assert largest_step < 60.0
    assert crossed, "the inputs should swing the head past 180 deg (straight down)"


@pytest.mark.parametrize("task, kwargs, message", [
    ("lesson2", dict(target_pool=np.zeros((4, 3))), r"target_pool must be .*\(n, 2\).*\(4, 3\)"),
    ("lesson2", dict(target_pool=np.zeros((1, 4))), r"got shape \(1, 4\)"),
    ("lesson2", dict(target_pool=[[0.3, np.nan]]), "finite"),
    ("lesson2", dict(position_tolerance=-0.05), "position_tolerance must be a positive"),
    ("lesson2", dict(attitude_tolerance=float("nan")), "attitude_tolerance must be a positive"),
    ("lesson2", dict(desired_attitude=float("nan")), "desired_attitude must be a finite"),
    ("lesson2", dict(time_limit=0.0), "time_limit must be positive"),
    ("lesson2", dict(time_limit=float("nan")), "time_limit must be positive"),
    ("track", dict(targets=np.zeros((3, 3))), r"targets must be .*\(3, 3\)"),
    ("track", dict(steps_per_target=2.5), "steps_per_target"),
])
def test_bad_task_options_raise_naming_the_option(task, kwargs, message):
    with pytest.raises(ValueError, match=message):
        robostrich_suite.load("robostrich", task, task_kwargs=dict(random=0, **kwargs))


def test_one_target_may_be_given_as_a_pair():
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=0, target_pool=[0.3, 0.4]))
    env.reset()
    np.testing.assert_array_equal(env.task.target_position, [0.3, 0.4])


def _start_and_far_targets():
    """A target pool of the head's fixed start position (a hold-still policy reaches it) and one
    58 cm away (it never does): (the far target, the (2, 2) pool)."""
    start = robostrich_suite.load("robostrich", "lesson1").reset().observation["head_position"]
    far = start + np.array([0.3, -0.5])
    return far, np.stack([start, far])


def test_failure_sampling_draws_the_targets_the_agent_misses_more_often():
    """target_sampling="failures": with a hold-still policy, the target at the start pose is
    reached and the one 58 cm away never is; the far one must then be drawn far more often
    than uniform sampling's half, and continued episodes still start where the last one ended."""
    far, pool = _start_and_far_targets()
    draws = {}
    for sampling in ("uniform", "failures", "continue_failures"):
        env = robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(
            target_sampling=sampling, target_pool=pool, time_limit=0.1, random=3,
            attitude_tolerance=180.0))
        far_draws = 0
        final = None
        for _ in range(40):
            ts = env.reset()
            if final is not None:  # scoring the last episode must not move the continued start
                np.testing.assert_array_equal(ts.observation["joint_angles"], final)
            far_draws += int(np.array_equal(ts.observation["target_position"], far))
            while not ts.last():
                ts = env.step(np.zeros(9))
            final = ts.observation["joint_angles"]
        draws[sampling] = far_draws
        if sampling != "uniform":
            tries, failures = env.task.target_tries, env.task.target_failures
            assert tries.sum() == 39  # every episode but the one still running
            assert failures[0] == 0 and failures[1] == tries[1]
    assert 12 <= draws["uniform"] <= 28
    assert draws["failures"] >= 32
    assert draws["continue_failures"] == draws["failures"]  # lesson 3 continues: the same draws
    with pytest.raises(ValueError, match="unknown target_sampling 'worst'"):
        robostrich_suite.load("robostrich", "lesson1", task_kwargs=dict(target_sampling="worst"))


def test_continue_failures_leaves_fixed_start_lessons_uniform():
    """target_sampling="continue_failures" in a fixed-start lesson draws exactly the targets of
    uniform sampling (so lessons 1-2 of a run stay the paper's, episode for episode), where
    "failures" draws the missed far target more often."""
    far, pool = _start_and_far_targets()
    targets = {}
    for sampling in ("uniform", "failures", "continue_failures"):
        env = robostrich_suite.load("robostrich", "lesson1", task_kwargs=dict(
            target_sampling=sampling, target_pool=pool, time_limit=0.1, random=3))
        targets[sampling] = []
        for _ in range(30):
            ts = env.reset()
            targets[sampling].append(tuple(ts.observation["target_position"]))
            while not ts.last():
                ts = env.step(np.zeros(9))
        assert env.task.target_tries.sum() == (29 if sampling == "failures" else 0)
    assert targets["continue_failures"] == targets["uniform"]
    assert targets["failures"] != targets["uniform"]


def test_stored_starts_begin_lesson3_episodes_where_a_stored_input_holds_the_arm():
    """stored_starts=1: every lesson-3 episode starts at rest where the stored input holds the head
    (the stored pose itself: its head position within 1 cm, level), with the clock at 0; 0 (the
    default) keeps the paper's continued starts; bad values are errors that name the option."""
    poses = targets.level_head_poses()
    inputs, positions = poses["control"][:2], poses["head_position"][:2]
    env = robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(
        stored_starts=1.0, start_inputs=inputs, random=0, time_limit=0.1))
    started = set()
    for _ in range(6):
        ts = env.reset()
        assert env.physics.time() == 0.0
        head = ts.observation["head_position"]
        nearest = int(np.argmin(np.linalg.norm(positions - head, axis=1)))
        assert np.linalg.norm(positions[nearest] - head) < 0.01
        assert abs(env.task.attitude_error(env.physics)) < 5.0
        assert np.abs(env.physics.data.qvel).max() < 0.05  # at rest, not mid-swing
        started.add(nearest)
        while not ts.last():
            ts = env.step(np.full(9, 0.01))
    assert started == {0, 1}  # both inputs drawn in 6 episodes
    # lesson 2 starts fixed whatever the option says (one --task-kwargs serves every lesson)
    fixed = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(stored_starts=1.0, start_inputs=inputs))
    np.testing.assert_array_equal(fixed.reset().observation["joint_angles"], np.zeros(18))
    with pytest.raises(ValueError, match="stored_starts must be a share between 0 and 1, got 1.5"):
        robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(stored_starts=1.5, start_inputs=inputs))
    with pytest.raises(ValueError, match="stored_starts > 0 needs start_inputs"):
        robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(stored_starts=0.5))
    with pytest.raises(ValueError, match="start_inputs must be a non-empty"):
        robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(stored_starts=0.5, start_inputs=[np.nan] * 9))


def test_fixed_stored_starts_begin_lesson1_and_2_episodes_at_stored_poses():
    """fixed_stored_starts: that share of a fixed-start lesson's episodes starts at rest at a stored
    pose (about half of 16 with 0.5, the others fixed); lesson 3 continues as before."""
    poses = targets.level_head_poses()
    inputs, positions = poses["control"][:2], poses["head_position"][:2]
    for lesson in ("lesson1", "lesson2"):
        env = robostrich_suite.load("robostrich", lesson, task_kwargs=dict(
            fixed_stored_starts=0.5, start_inputs=inputs, random=1, time_limit=0.04))
        stored = 0
        for _ in range(16):
            ts = env.reset()
            head = ts.observation["head_position"]
            if np.abs(ts.observation["joint_angles"]).max() == 0.0:
                continue  # the fixed pose
            assert np.min(np.linalg.norm(positions - head, axis=1)) < 0.01
            assert np.abs(env.physics.data.qvel).max() < 0.05
            stored += 1
        assert 4 <= stored <= 12, stored
    continued = robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(
        fixed_stored_starts=1.0, start_inputs=inputs, random=0, time_limit=0.1))
    continued.reset()
    for _ in range(5):
        ts = continued.step(np.full(9, 0.01))
    np.testing.assert_array_equal(continued.reset().observation["joint_angles"], ts.observation["joint_angles"])
    with pytest.raises(ValueError, match="fixed_stored_starts must be a share between 0 and 1, got -0.1"):
        robostrich_suite.load("robostrich", "lesson1", task_kwargs=dict(fixed_stored_starts=-0.1, start_inputs=inputs))
    with pytest.raises(ValueError, match="fixed_stored_starts > 0 needs start_inputs"):
        robostrich_suite.load("robostrich", "lesson1", task_kwargs=dict(fixed_stored_starts=0.5))


def test_release_starts_begin_lesson3_episodes_on_the_way_out_of_a_curled_neck():
    """release_starts=1: every continued lesson-3 episode starts after the tendons were released
    for up to release_time: from a neck curled back by a turn (antagonist_pairs' stored pose for a
    low target, attitude -270 deg) the starts spread along its way up (one still below -150 deg,
    one past -30 deg), with the clock at 0 and the servos at zero contraction; release_starts=0
    starts exactly where the last episode ended; bad values are errors naming the option."""
    from robostrich_suite.model import layouts
    layout = layouts.build("antagonist_pairs")
    poses = targets.level_head_poses(layouts.target_file("antagonist_pairs"))
    curled = int(np.argmin(poses["head_attitude"]))
    assert poses["head_attitude"][curled] < -260
    hold = poses["control"][curled]
    starts = {}
    for share in (0.0, 1.0):
        env = robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(
            tendon_layout=layout, target_pool=targets.training_targets(layouts.target_file("antagonist_pairs")),
            release_starts=share, random=0))
        timestep, starts[share] = env.reset(), []
        for _ in range(8):
            while not timestep.last():
                timestep = env.step(hold)
            end = env.physics.data.qpos.copy()
            assert env.physics.head_attitude() < -260  # curled back when the episode ends
            timestep = env.reset()
            assert env.physics.time() == 0.0
            starts[share].append(env.physics.head_attitude())
            if share == 0.0:
                np.testing.assert_array_equal(env.physics.data.qpos, end)
            else:
                np.testing.assert_array_equal(env.physics.arm_control(), np.zeros(9))
    assert max(starts[0.0]) < -260
    assert min(starts[1.0]) < -150 and max(starts[1.0]) > -30, starts[1.0]
    with pytest.raises(ValueError, match="release_starts must be a share between 0 and 1, got -0.1"):
        robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(release_starts=-0.1))
    with pytest.raises(ValueError, match="release_time must be a positive finite time"):
        robostrich_suite.load("robostrich", "lesson3", task_kwargs=dict(release_starts=0.5, release_time=0))


@pytest.mark.parametrize("domain", ["robostrich", "robostrich_a1"])
def test_the_arm_physics_steps_exactly_as_dm_controls_physics_step(domain):
    """The per-step path calls MuJoCo directly (dm_control's wrapper cost as much as the
    task's observation): same states, bit for bit, as dm_control's own Physics.step, and a
    diverging step is still caught by dm_control's test (a grown MuJoCo warning count)."""
    from dm_control.mujoco import engine
    ours = robostrich_suite.load(domain, "lesson2", task_kwargs=dict(random=0)).physics
    reference = ours.copy(share_model=False)
    inputs = np.random.default_rng(0).uniform(*ours.arm_control_range().T, size=(60, 9))
    for action in inputs:
        for physics in (ours, reference):
            physics.set_arm_control(action)
        ours.step(4)
        engine.Physics.step(reference, 4)
        np.testing.assert_array_equal(ours.data.qpos, reference.data.qpos)
        np.testing.assert_array_equal(ours.data.qacc, reference.data.qacc)  # mj_step1/2 alike
    assert ours.divergence is None
    ours.data.qvel[3] = np.inf
    ours.step(4)
    assert "Physics state is invalid" in ours.divergence and "BADQ" in ours.divergence


def test_per_step_index_slices_read_the_same_elements():
    from robostrich_suite import physics as physics_lib
    values = np.arange(20.0)
    for ids in ([3, 4, 5], [17, 16, 15, 0 + 14], list(range(17, -1, -1)), [0, 2], [2, 0], [5, 9, 6], [4]):
        select = physics_lib.as_slice(ids)
        np.testing.assert_array_equal(values[select], values[ids])
    assert isinstance(physics_lib.as_slice(list(range(17, -1, -1))), slice)
    assert not isinstance(physics_lib.as_slice([5, 9, 6]), slice)
    indices = robostrich_suite.load("robostrich", "lesson1", task_kwargs=dict(random=0)).physics.arm_indices
    assert isinstance(indices.qpos_select, slice) and isinstance(indices.actuator_select, slice)


def test_reward_and_observation_read_the_state_they_are_asked_about():
    """get_reward hands its head reading to the get_observation dm_control calls next (one
    reading per step); a reward asked for again after the state moved reads the new state, and
    the observation that uses the handed-over reading equals a freshly read one."""
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=0))
    env.reset()
    for _ in range(50):
        env.step(np.full(9, 0.01))
    task, physics = env.task, env.physics
    bent = task.get_reward(physics)
    with physics.reset_context():  # back to the straight start, no step taken
        pass
    straight = task.get_reward(physics)
    handed_over = task.get_observation(physics)  # uses get_reward's reading
    fresh = task.get_observation(physics)  # reads the head itself
    assert straight != bent
    for key in fresh:
        np.testing.assert_array_equal(handed_over[key], fresh[key])
    np.testing.assert_array_equal(fresh["head_position"], physics.head_position()[[0, 2]])


@pytest.mark.parametrize("domain", ["robostrich", "robostrich_a1"])
def test_per_step_views_read_their_own_physics_live_after_copy_and_unpickling(domain):
    """The accessors read through views into the simulation's buffers (``ArmViews``): each
    physics, copied or unpickled, reads its own live state after each step, equal to what the
    raw MuJoCo data holds, and writes its controls into its own data only."""
    env = robostrich_suite.load(domain, "lesson2", task_kwargs=dict(random=0))
    env.reset()
    copied, unpickled = env.physics.copy(share_model=False), pickle.loads(pickle.dumps(env.physics))
    inputs = np.random.default_rng(1).uniform(*env.physics.arm_control_range().T, size=(3, 9))
    for physics, action in zip((env.physics, copied, unpickled), inputs):
        assert physics._views is not None  # the real models' indices are slices
        before = [other.head_position() for other in (env.physics, copied, unpickled)]
        physics.set_arm_control(action)
        physics.step(20)
        after = [other.head_position() for other in (env.physics, copied, unpickled)]
        moved = [not np.array_equal(b, a) for b, a in zip(before, after)]
        assert moved == [other is physics for other in (env.physics, copied, unpickled)]
        indices, data = physics.arm_indices, physics.data
        np.testing.assert_array_equal(physics.arm_control(), action)
        np.testing.assert_array_equal(data.ctrl[indices.actuators], action)
        np.testing.assert_array_equal(physics.head_position(), data.site_xpos[indices.head_site])
        np.testing.assert_array_equal(physics.joint_angles(), data.qpos[indices.qpos])
        np.testing.assert_array_equal(physics.tendon_lengths(), data.ten_length[indices.tendons])
        np.testing.assert_array_equal(physics.tendon_forces(), -data.actuator_force[indices.actuators])
        np.testing.assert_array_equal(physics.head_velocity(),
                                      data.sensordata[indices.head_velocity:indices.head_velocity + 3])
        axis = np.asarray(data.xmat[indices.head_body]).reshape(3, 3)[:, 2]
        if domain == "robostrich":  # the frame's head turns in the x-z plane; modulo a turn
            turned = physics.head_attitude() - np.degrees(np.arctan2(axis[0], axis[2]))
            assert (turned + 180.0) % 360.0 - 180.0 == pytest.approx(0.0, abs=1e-9)
        # What an accessor returns is a copy: a later step does not change it.
        angles = physics.joint_angles()
        physics.step(4)
        assert not np.array_equal(angles, physics.joint_angles())
    # A model whose arm indices are no slices reads without views: the same values.
    physics = env.physics
    names = ("head_position", "head_velocity", "head_attitude", "joint_angles", "tendon_lengths",
             "tendon_contractions", "tendon_forces", "tendon_tensions", "arm_control", "arm_control_bounds")
    through_views = {name: getattr(physics, name)() for name in names}
    views, physics.__dict__["_views"] = physics._views, None
    for name in names:
        np.testing.assert_array_equal(getattr(physics, name)(), through_views[name], err_msg=name)
    assert physics.arm_control_view() is None
    env.task.before_step(np.full(9, 1e-3), physics)  # checked, clipped, written without the view
    np.testing.assert_array_equal(views.controls, 1e-3)
