"""The A1-like quadruped: the public A1 facts, and it walks with the arm on it."""
import numpy as np
import pytest
from dm_control import mjcf

import robostrich_suite
from robostrich_suite import robostrich_a1
from robostrich_suite.model import quadruped as quad
from robostrich_suite.tasks import gait


@pytest.fixture(scope="module")
def robot():
    return mjcf.Physics.from_mjcf_model(quad.build_quadruped())


def test_masses_match_the_a1(robot):
    named = robot.named.model
    assert named.body_mass["trunk"] == pytest.approx(quad.TRUNK_MASS)
    for leg in quad.LEGS:
        assert named.body_mass[f"{leg}_hip"] == pytest.approx(quad.HIP_MASS)
        assert named.body_mass[f"{leg}_thigh"] == pytest.approx(quad.THIGH_MASS)
        assert named.body_mass[f"{leg}_calf"] == pytest.approx(quad.CALF_MASS)
    assert robot.model.body_subtreemass[1] == pytest.approx(12.45, abs=0.01)


def test_dimensions_match_the_a1(robot):
    named = robot.named.model
    np.testing.assert_allclose(named.geom_size["trunk"], np.array(quad.TRUNK_SIZE) / 2)
    np.testing.assert_allclose(named.body_pos["FL_hip"], [0.183, 0.047, 0])
    np.testing.assert_allclose(named.body_pos["RR_hip"], [-0.183, -0.047, 0])
    np.testing.assert_allclose(named.body_pos["FR_thigh"], [0, -0.08505, 0])
    np.testing.assert_allclose(named.body_pos["FR_calf"], [0, 0, -0.2])
    np.testing.assert_allclose(named.geom_pos["FR_foot"], [0, 0, -0.2])
    assert named.geom_size["FR_foot"][0] == pytest.approx(0.02)


def test_twelve_position_servos_with_a1_gains_and_limits(robot):
    model = robot.model
    assert model.nu == 12 and model.njnt == 12
    assert [model.id2name(i, "actuator") for i in range(12)] == list(quad.JOINT_NAMES)
    np.testing.assert_allclose(model.actuator_gainprm[:, 0], 100.0)
    np.testing.assert_allclose(model.actuator_biasprm[:, 1], -100.0)
    np.testing.assert_allclose(model.actuator_forcerange, [[-33.5, 33.5]] * 12)
    ranges = robot.named.model.jnt_range
    np.testing.assert_allclose(ranges["FL_hip"], [-0.8029, 0.8029])
    np.testing.assert_allclose(ranges["RR_thigh"], [-1.0472, 4.1888])
    np.testing.assert_allclose(ranges["RL_calf"], [-2.6965, -0.9163])
    np.testing.assert_allclose(model.actuator_ctrlrange, model.jnt_range)


def test_no_free_joint_but_a_mount_site_on_top_of_the_trunk(robot):
    assert all(robot.model.jnt_type != 0)
    mount = robot.named.model.site_pos[quad.MOUNT_SITE]
    assert mount[2] > quad.TRUNK_SIZE[2] / 2 and mount[0] > 0


def run_walk(duration, trunk_heights=None, gait_source=None, steer=True):
    """Zero tendon input while the quadruped trots; returns per-step records."""
    env = robostrich_suite.load("robostrich_a1", "head_stabilize", task_kwargs=dict(
        random=0, time_limit=duration, trunk_heights=trunk_heights, gait=gait_source,
        steer=steer))
    env.reset()
    physics = env.physics
    start = physics.trunk_position()
    records = []
    zero = np.zeros(9)
    for _ in range(int(round(duration / robostrich_a1.CONTROL_TIMESTEP))):
        env.step(zero)
        t = env.task.episode_time(physics)
        records.append((t, *physics.trunk_position(), physics.trunk_uprightness(),
                        float(env.task.height_schedule(t))))
    records = np.array(records)
    records[:, 1:3] -= start[:2]
    return records  # t, x, y, z, up, commanded height


@pytest.fixture(scope="module")
def ten_second_walk():
    return run_walk(10.0)


def test_trots_forward_faster_than_a_tenth_m_per_s_with_the_arm(ten_second_walk):
    t, x, y, z, up, _ = ten_second_walk.T
    speed = x[-1] / t[-1]
    print(f"walking speed {speed:.3f} m/s, lateral drift {y[-1]:.3f} m")
    assert speed > 0.1
    assert t[-1] == pytest.approx(10.0)
    assert abs(y).max() < 0.15  # the steering keeps it on the line


def test_stays_upright_for_ten_seconds(ten_second_walk):
    _, _, _, z, up, _ = ten_second_walk.T
    assert up.min() > 0.9
    assert z.min() > 0.18


def test_trunk_height_follows_its_command():
    schedule = gait.TrunkHeightSchedule((0.0, 2.0, 3.0, 6.0, 7.0), (0.28, 0.28, 0.22, 0.22, 0.28))
    records = run_walk(8.0, trunk_heights=schedule)
    t, z, command = records[:, 0], records[:, 3], records[:, 5]
    high = (t > 1.0) & (t < 2.0)
    low = (t > 4.0) & (t < 6.0)
    back = (t > 7.5)
    errors = [abs(z[w].mean() - command[w].mean()) for w in (high, low, back)]
    print(f"trunk height error (mean over windows): {np.round(errors, 4)} m")
    assert max(errors) < 0.01
    # The change follows the commanded change (servo sag is nearly the same at both heights).
    assert z[high].mean() - z[low].mean() == pytest.approx(0.06, abs=0.01)
    assert z[back].mean() - z[low].mean() == pytest.approx(0.06, abs=0.01)


def test_the_trot_generator_walks_too_open_loop():
    records = run_walk(4.0, gait_source=gait.TrotGait(frequency=3.0, stride=0.08, lift=0.04),
                       steer=False)
    assert records[-1, 1] / 4.0 > 0.1
    assert records[:, 4].min() > 0.9
