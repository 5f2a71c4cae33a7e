"""The robostrich_a1 domain: registry, dm_env conformance, Table 2, gait-driven legs, narrow gap."""
import mujoco
import numpy as np
import pytest
from absl.testing import absltest
from dm_env import test_utils

import robostrich_suite
from robostrich_suite import robostrich_a1 as a1
from robostrich_suite import scenes
from robostrich_suite.model import arm, quadruped as quad
from robostrich_suite.studies import walk
from robostrich_suite.tasks import gait, quadruped_tasks

TASKS = ("lesson1", "lesson2", "lesson3", "lesson4", "head_stabilize", "narrow_gap")
TABLE2 = {"head_position": 3, "head_velocity": 3, "joint_angles": 18, "trunk_position": 3,
          "trunk_velocity": 3}  # the paper's 30 inputs


def test_registry_has_every_task():
    assert robostrich_suite.TASKS_BY_DOMAIN["robostrich_a1"] == TASKS
    assert set(a1.SUITE.tagged("curriculum")) == {"lesson1", "lesson2", "lesson3", "lesson4"}


def _short(task_name):
    if task_name == "narrow_gap":
        return dict(random=0, steps_per_target=2)
    return dict(random=0, time_limit=0.08)


def _conformance_case(task_name):
    class Case(test_utils.EnvironmentTestMixin, absltest.TestCase):
        def make_object_under_test(self):
            return robostrich_suite.load("robostrich_a1", task_name, task_kwargs=_short(task_name))
    Case.__name__ = f"Conformance_{task_name}"
    return Case


for _task in TASKS:
    globals()[f"TestConformance_{_task}"] = _conformance_case(_task)


@pytest.mark.parametrize("task_name", TASKS)
def test_action_is_the_nine_tendons_only(task_name):
    env = robostrich_suite.load("robostrich_a1", task_name, task_kwargs=_short(task_name))
    spec = env.action_spec()
    assert spec.shape == (9,)
    assert env.physics.model.nu == 21  # 9 tendons + 12 leg servos
    np.testing.assert_allclose(spec.minimum, env.physics.arm_control_range()[:, 0])
    assert env.control_timestep() == pytest.approx(0.008)


def test_observation_layout_matches_table2():
    env = robostrich_suite.load("robostrich_a1", "lesson2", task_kwargs=dict(random=0))
    shapes = [(k, v.shape) for k, v in env.observation_spec().items()]
    assert shapes[:5] == [(k, (n,)) for k, n in TABLE2.items()]
    assert shapes[5:] == [("target_position", (2,)), ("to_target", (2,)),
                          ("attitude_error", (1,)), ("head_attitude", (1,)),
                          ("tendon_contraction", (9,)), ("tendon_tension", (9,))]


def test_observation_values_are_in_the_trunk_frame():
    env = robostrich_suite.load("robostrich_a1", "lesson4", task_kwargs=dict(random=1))
    env.reset()
    start = env.physics.trunk_position()
    for _ in range(120):
        step = env.step(np.zeros(9))
    physics, obs = env.physics, step.observation
    head, trunk = physics.head_position(), physics.trunk_position()
    heading = physics.heading()
    assert obs["head_position"][2] == pytest.approx(head[2])  # height above the floor
    assert obs["head_position"][0] == pytest.approx((head - trunk)[:2] @ heading)
    # The trunk in its own frame: its height, and no odometer (the distance walked would be an
    # input a longer episode takes beyond anything training saw).
    np.testing.assert_array_equal(obs["trunk_position"], [0.0, 0.0, physics.trunk_height()])
    assert trunk[0] - start[0] > 0.1  # it did walk forward (~1 s)
    assert obs["trunk_velocity"][0] == pytest.approx(
        physics.trunk_velocity()[:2] @ heading)
    np.testing.assert_allclose(obs["joint_angles"], physics.joint_angles())
    np.testing.assert_allclose(obs["to_target"],
                               obs["target_position"] - obs["head_position"][[0, 2]])


def test_legs_follow_the_gait_not_the_action():
    env = robostrich_suite.load("robostrich_a1", "lesson4", task_kwargs=dict(random=0))
    env.reset()
    physics = env.physics
    legs = physics._robot()["leg_actuators"]
    for action in (np.zeros(9), env.action_spec().maximum, env.action_spec().minimum):
        expected = env.task.leg_targets(physics)
        env.step(action)
        np.testing.assert_allclose(physics.data.ctrl[legs], expected)
        np.testing.assert_allclose(physics.arm_control(), action)


def test_lesson4_trunk_height_changes_over_the_episode():
    env = robostrich_suite.load("robostrich_a1", "lesson4", task_kwargs=dict(random=3))
    env.reset()
    heights = []
    while True:
        step = env.step(np.zeros(9))
        heights.append(env.physics.trunk_height())
        if step.last():
            break
    heights = np.array(heights)
    middle = env.task.height_schedule(quadruped_tasks.LESSON4_TIME_LIMIT / 2)
    assert abs(middle - quad.STANDING_TRUNK_HEIGHT) > 0.005
    n = len(heights)
    assert heights[n // 2 - 20: n // 2 + 20].mean() == pytest.approx(middle, abs=0.01)
    assert heights[: n // 8].mean() == pytest.approx(quad.STANDING_TRUNK_HEIGHT, abs=0.01)


def test_lesson4_standing_share_mixes_standing_episodes_into_the_walk():
    """A standing episode of lesson 4 keeps the quadruped in place at the nominal height; the
    others trot; the share is drawn per episode from the task's own random stream."""
    env = robostrich_suite.load("robostrich_a1", "lesson4", task_kwargs=dict(random=5, standing_share=0.5))
    kinds = []
    for _ in range(6):
        env.reset()
        start = env.physics.trunk_position()
        vz = []
        for _ in range(150):
            env.step(np.zeros(9))
            vz.append(env.physics.trunk_velocity()[2])
        walked = env.physics.trunk_position()[0] - start[0]
        rms = float(np.sqrt(np.mean(np.square(vz))))
        if env.task.episode_legs == "stand":
            assert abs(walked) < 0.02 and rms < 0.03
            assert env.physics.trunk_height() == pytest.approx(quad.STANDING_TRUNK_HEIGHT, abs=0.01)
        else:
            assert walked > 0.1 and rms > 0.1
        kinds.append(env.task.episode_legs)
    assert set(kinds) == {"stand", "walk"}
    for share in (-0.1, 1.5, float("nan")):
        with pytest.raises(ValueError, match="standing_share"):
            robostrich_suite.load("robostrich_a1", "lesson4", task_kwargs=dict(standing_share=share))


def test_trunk_height_can_be_commanded_during_an_episode():
    env = robostrich_suite.load("robostrich_a1", "head_stabilize", task_kwargs=dict(random=0))
    env.reset()
    for _ in range(60):
        env.step(np.zeros(9))
    env.task.command_trunk_height(env.physics, 0.23, ramp_time=0.4)
    heights = []
    for _ in range(250):
        env.step(np.zeros(9))
        heights.append(env.physics.trunk_height())
    assert env.task.trunk_height_command(env.physics) == pytest.approx(0.23)
    assert np.mean(heights[-100:]) == pytest.approx(0.23, abs=0.01)
    with pytest.raises(ValueError, match="outside the range"):
        env.task.command_trunk_height(env.physics, 0.05)


def test_standing_lessons_keep_the_quadruped_in_place():
    env = robostrich_suite.load("robostrich_a1", "lesson2", task_kwargs=dict(random=0))
    env.reset()
    start = env.physics.trunk_position()
    for _ in range(100):
        env.step(np.zeros(9))
    assert np.linalg.norm(env.physics.trunk_position()[:2] - start[:2]) < 0.01
    assert env.physics.trunk_height() == pytest.approx(quad.STANDING_TRUNK_HEIGHT, abs=0.01)


def test_lesson_targets_are_the_frame_targets_moved_onto_the_trunk():
    pool = quadruped_tasks.default_target_pool()
    assert pool.shape[1] == 2
    env = robostrich_suite.load("robostrich_a1", "lesson1", task_kwargs=dict(random=0))
    env.reset()
    assert any(np.allclose(env.task.target_position, p) for p in pool)
    np.testing.assert_allclose(quadruped_tasks.frame_to_trunk([[0.0, scenes.FRAME_MOUNT_HEIGHT]]),
                               [[quad.MOUNT_X, scenes.NOMINAL_MOUNT_HEIGHT]])
    # The arm's base (C18 joint) is where the mapping assumes it, once standing.
    physics = env.physics
    base = physics.to_trunk_frame(physics.arm_base_position())
    assert base[0] == pytest.approx(quad.MOUNT_X, abs=0.005)
    assert base[2] == pytest.approx(scenes.NOMINAL_MOUNT_HEIGHT, abs=0.01)


def test_lesson3_continues_from_the_previous_episode():
    env = robostrich_suite.load("robostrich_a1", "lesson3", task_kwargs=dict(
        random=0, time_limit=0.4))
    env.reset()
    action = env.action_spec().maximum * 0.5
    while not env.step(action).last():
        pass
    end = env.physics.joint_angles()
    env.reset()
    np.testing.assert_allclose(env.physics.joint_angles(), end)


def test_stored_starts_on_the_standing_quadruped_hold_the_frames_poses():
    """A stored start settles the arm on the standing quadruped holding a stored level pose's
    inputs: the head comes to rest within 2 cm of where it sits on the frame (moved onto the
    trunk), level, with the quadruped upright; the clock starts at 0."""
    from agents.robostrich.domains import Domain
    domain = Domain("robostrich_a1")
    table = domain.lookup_table()
    rows = np.arange(0, len(table["control"]), len(table["control"]) // 6)[:6]
    env = domain.make_environment("lesson1", 0, fixed_stored_starts=1.0, start_inputs=table["control"][rows])
    seen = set()
    for _ in range(8):
        ts = env.reset()
        head = ts.observation["head_position"][[0, 2]]
        nearest = int(np.argmin(np.linalg.norm(table["head_position"][rows] - head, axis=1)))
        assert np.linalg.norm(table["head_position"][rows][nearest] - head) < 0.02
        assert abs(env.task.attitude_error(env.physics)) < 5
        assert env.physics.trunk_uprightness() > 0.99 and env.task.episode_time(env.physics) == 0.0
        seen.add(nearest)
    assert len(seen) >= 3


def test_head_vertical_speed_term_charges_the_heads_bobbing_once_it_holds_its_target():
    """With ``weights.head_vertical_speed`` lesson 4's reward drops by the weight times the head's
    vertical speed in the world while the head is within the position tolerance of its target (here
    the start pose's head position); on the way to a far target it costs nothing. The motion is the
    same as without it."""
    start = robostrich_suite.load("robostrich_a1", "lesson4").reset().observation["head_position"][[0, 2]]

    def lesson4(target, weight):
        env = robostrich_suite.load("robostrich_a1", "lesson4", task_kwargs=dict(
            random=0, target_pool=[target], weights={"head_vertical_speed": weight}))
        env.reset()
        return env

    far = start + [0.3, -0.3]
    holding, plain, reaching, plain_far = lesson4(start, 3.0), lesson4(start, 0.0), lesson4(far, 3.0), lesson4(far, 0.0)
    speeds = []
    for _ in range(60):
        action = np.zeros(9)
        charge = holding.step(action).reward - plain.step(action).reward
        speeds.append(abs(holding.physics.head_velocity()[2]))
        assert holding.task.position_error(holding.physics) <= holding.task.position_tolerance
        assert charge == pytest.approx(-3.0 * speeds[-1], abs=1e-9)
        assert reaching.step(action).reward == plain_far.step(action).reward
        np.testing.assert_array_equal(holding.physics.data.qpos, plain.physics.data.qpos)
    assert max(speeds) > 0.02  # the trot moves the head: a real charge, not zero against zero


def test_head_stabilize_target_is_pd_ahead_and_constant_height():
    env = robostrich_suite.load("robostrich_a1", "head_stabilize", task_kwargs=dict(
        random=0, distance=0.38, height=0.55))
    env.reset()
    for _ in range(50):
        step = env.step(np.zeros(9))
    np.testing.assert_allclose(step.observation["target_position"], [0.38, 0.55])
    assert env.task.height_schedule(7.0) < quad.STANDING_TRUNK_HEIGHT - 0.03  # Fig. 9A dip


def test_narrow_gap_walks_up_to_the_wall_then_stands_and_steps_targets():
    env = robostrich_suite.load("robostrich_a1", "narrow_gap", task_kwargs=dict(random=0))
    env.reset()
    physics, task = env.physics, env.task
    indices, gaps = [], []
    for _ in range(700):  # 5.6 s
        env.step(np.zeros(9))
        indices.append(task.target_index)
        gaps.append(scenes.GAP_WALL_X - physics.arm_base_position()[0])
    assert not task.walking()
    gaps = np.array(gaps)
    # Stopped near the stopping distance, never touching the wall with the trunk.
    assert gaps[-1] == pytest.approx(quadruped_tasks.GAP_STOP_DISTANCE, abs=0.06)
    assert gaps.min() > 0.05
    assert np.all(np.diff(indices) >= 0) and indices[-1] == 4
    # Targets stay fixed in the world while the robot moves (up to the projection of the
    # target onto the trunk's vertical plane, which the small yaw makes ~mm).
    world = physics.from_trunk_frame(*task.target_position)
    np.testing.assert_allclose(world[[0, 2]], task.world_targets[4], atol=0.01)


def _push_head_towards_the_wall(wall_collides: bool):
    physics = a1.Physics.from_xml_string(*a1.get_model_and_assets(scene="narrow_gap"))
    walls = [physics.model.name2id(n, "geom") for n in ("gap_wall", "gap_shelf_near",
                                                          "gap_shelf_far")]
    if not wall_collides:
        physics.model.geom_contype[walls] = 0
        physics.model.geom_conaffinity[walls] = 0
    trunk_x = scenes.GAP_WALL_X - quadruped_tasks.GAP_STOP_DISTANCE + 0.02 - quad.MOUNT_X
    with physics.reset_context():
        physics.place_standing(trunk_xy=(trunk_x, 0.0))
    low, high = physics.arm_control_range().T
    flex = 0.5 * high
    flex[0] = low[0]  # dorsal tendon paid out, ventral tendons pull the head forward
    physics.set_arm_control(flex)
    head_x, arm_wall_contacts = [], 0
    arm_geoms = {i for i in range(physics.model.ngeom)
                 if physics.model.id2name(i, "geom").startswith(f"{arm.ARM_MODEL_NAME}/")}
    for _ in range(750):
        physics.step()
        head_x.append(physics.head_position()[0])
        pairs = zip(physics.data.contact.geom1, physics.data.contact.geom2)
        arm_wall_contacts += sum((a in arm_geoms and b in walls) or (b in arm_geoms and a in walls)
                                 for a, b in pairs)
    return np.array(head_x), arm_wall_contacts


def test_narrow_gap_wall_blocks_the_head():
    blocked, contacts = _push_head_towards_the_wall(True)
    free, free_contacts = _push_head_towards_the_wall(False)
    assert free.max() > scenes.GAP_WALL_X + 0.1  # without the wall the head would go through
    assert blocked.max() < scenes.GAP_WALL_X  # with it, the head stops in front
    assert contacts > 0 and free_contacts == 0


def test_checked_in_xml_is_the_generated_model_and_loads_in_plain_mujoco(repo_xml_dir):
    path = repo_xml_dir / "robostrich_a1.xml"
    assert path.read_text() == a1.get_model_and_assets()[0], (
        "xml/robostrich_a1.xml is out of date: run robostrich-export-xml --out xml")
    model = mujoco.MjModel.from_xml_path(str(path))
    assert model.nu == 21 and model.nq == 7 + 12 + 18
    assert model.jnt_type[0] == mujoco.mjtJoint.mjJNT_FREE
    # Its "stand" keyframe stands: the trunk stays at the standing height in plain MuJoCo.
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("stand").id)
    mujoco.mj_step(model, data, 500)
    assert data.qpos[2] == pytest.approx(quad.STANDING_TRUNK_HEIGHT, abs=0.01)


def test_scene_name_is_checked():
    with pytest.raises(ValueError, match="unknown scene"):
        scenes.build_a1(scene="stairs")


def test_bad_task_options_raise():
    with pytest.raises(ValueError, match="unknown legs"):
        quadruped_tasks.QuadrupedReach(legs="run")
    with pytest.raises(ValueError, match="outside the range"):
        robostrich_suite.load("robostrich_a1", "head_stabilize", task_kwargs=dict(
            trunk_heights=gait.TrunkHeightSchedule((0, 1), (0.27, 0.5))))


def test_walk_tool_writes_a_recording_and_a_plot_into_its_out_directory(tmp_path, capsys, verify_rrd):
    """--out is a directory, as for robostrich-movement and robostrich-workspace."""
    walk.main(["--seconds", "0.4", "--tendons", "sine", "--out", str(tmp_path / "walk")])
    assert (tmp_path / "walk" / "walk.rrd").stat().st_size > 10_000
    assert (tmp_path / "walk" / "walk.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["walk"]
    assert "mean forward speed" in capsys.readouterr().out
    verify_rrd(tmp_path / "walk" / "walk.rrd")


@pytest.mark.parametrize("out", ["walk.png", "walk.rrd", "a_file"])
def test_walk_tool_refuses_a_file_as_out(tmp_path, capsys, out):
    """The old usage (a file name) and an existing file get a usage error naming --out."""
    (tmp_path / "a_file").write_text("")
    if out == "a_file":  # an existing file: the output check, before any work (robostrich_suite/outputs.py)
        with pytest.raises(NotADirectoryError, match="--out .*a_file is a file, not a directory"):
            walk.main(["--seconds", "0.1", "--no-rrd", "--out", str(tmp_path / out)])
    else:
        with pytest.raises(SystemExit) as exit_info:
            walk.main(["--seconds", "0.1", "--no-rrd", "--out", str(tmp_path / out)])
        assert exit_info.value.code == 2
        last = capsys.readouterr().err.strip().splitlines()[-1]
        assert "argument --out:" in last and "is a directory" in last
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]


def test_walk_series_show_the_trot_and_the_scripted_nod():
    zero = walk.record_walk("lesson4", seconds=1.5, tendons="zero")
    nod = walk.record_walk("lesson4", seconds=1.5, tendons="sine")
    assert len(zero["time"]) == round(1.5 / a1.CONTROL_TIMESTEP)
    assert zero["trunk_speed"].mean() > 0.1
    # The scripted ventral pull brings the head forward of where the passive neck is.
    assert nod["head_forward_distance"][-60:].mean() > zero["head_forward_distance"][-60:].mean()


def test_shared_arm_accessors_and_domain_randomisation_find_the_arm():
    from robostrich_suite.tasks import randomization
    env = robostrich_suite.load("robostrich_a1", "lesson2", task_kwargs=dict(
        random=0, randomization=randomization.DomainRandomization(mass_scale=(1.2, 1.3))))
    physics = env.physics
    assert physics.arm_joint_names()[0] == "arm/atlas" and len(physics.tendon_names()) == 9
    before = physics.model.body_mass.copy()
    arm_bodies = [i for i in range(physics.model.nbody)  # (the attachment frame is massless)
                  if physics.model.id2name(i, "body").startswith("arm/") and before[i] > 0]
    env.reset()
    after = physics.model.body_mass
    assert np.all(after[arm_bodies] > before[arm_bodies] * 1.19)
    legs = [i for i in range(1, physics.model.nbody) if i not in arm_bodies]
    np.testing.assert_allclose(after[legs], before[legs])  # the quadruped is not randomised


def test_trunk_frame_and_head_attitude_turn_with_the_trunk():
    physics = a1.Physics.from_xml_string(*a1.get_model_and_assets())
    physics.place_standing(trunk_xy=(1.0, 2.0))  # (forward() after each change below)
    physics.forward()
    straight = physics.to_trunk_frame(physics.head_position())
    assert physics.head_attitude() == pytest.approx(0.0, abs=1e-6)  # straight neck: head up
    physics.data.qpos[3:7] = [np.cos(np.pi / 4), 0, 0, np.sin(np.pi / 4)]  # yaw 90 deg
    physics.forward()
    np.testing.assert_allclose(physics.heading(), [0.0, 1.0], atol=1e-9)
    np.testing.assert_allclose(physics.to_trunk_frame(physics.head_position()), straight,
                               atol=1e-9)
    # Bend the neck forward by 90 deg in total: level in the trunk's (now +y) heading.
    physics.named.data.qpos[["arm/c2", "arm/c3", "arm/c4", "arm/c5", "arm/c6", "arm/c7"]] = (
        np.radians([10, 15, 15, 20, 15, 15]))
    physics.forward()
    assert physics.head_attitude() == pytest.approx(90.0, abs=1e-6)


def test_failure_sampling_leaves_the_standing_start_alone():
    """Scoring the last episode for target_sampling="failures" must not move the physics: the
    quadruped is placed and settled before the arm's episode starts."""
    starts = {}
    for sampling in ("uniform", "failures"):
        env = robostrich_suite.load("robostrich_a1", "lesson1", task_kwargs=dict(
            target_sampling=sampling, random=0, time_limit=0.05))
        for _ in range(2):
            ts = env.reset()
            starts[sampling] = (env.physics.data.qpos.copy(), env.physics.data.time)
            while not ts.last():
                ts = env.step(np.zeros(env.action_spec().shape))
        if sampling == "failures":
            assert env.task.target_tries.sum() == 1
    np.testing.assert_array_equal(starts["uniform"][0], starts["failures"][0])
    assert starts["uniform"][1] == starts["failures"][1]
