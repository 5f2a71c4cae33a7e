"""Kinematic and actuated workspace (paper Fig. 6 and beyond), from real MuJoCo runs."""
import numpy as np
import pytest

from robostrich_suite import physics as physics_lib
from robostrich_suite.model import arm
from robostrich_suite import fingerprint as fingerprint_lib
from robostrich_suite import scenes
from robostrich_suite.studies import target_generation, workspace


@pytest.fixture(scope="module")
def physics():
    return scenes.frame_physics()


@pytest.fixture(scope="module")
def kinematic(physics):
    # 3000 uniform + 3000 edge samples: ~0.1 s of forward kinematics per thousand.
    return workspace.kinematic_samples(3000, seed=1, physics=physics, num_edge=3000)


@pytest.fixture(scope="module")
def actuated(physics):
    return workspace.actuated_samples(32, seed=3, physics=physics)  # 15 come to rest within an episode


def test_head_stays_within_the_sum_of_link_lengths(kinematic, physics):
    base = workspace.base_joint_xz(physics)
    distance = np.linalg.norm(kinematic.head_position - base, axis=1)
    spec = arm.ArmSpec.from_table1()
    # Table 1's lengths sum to 611.4 mm; the head site sits half a head length further.
    assert workspace.reach_radius() == pytest.approx(0.6114 + spec.head_site_fraction
                                                     * spec.head_length)
    assert distance.max() <= workspace.reach_radius() + 1e-9
    # ... and the sample really spreads out: from curled up to nearly straight.
    assert distance.min() < 0.25 and distance.max() > 0.6


def _neighbour_correlation(fractions):
    """Mean correlation of neighbouring joints' positions within their ranges."""
    return np.mean([np.corrcoef(fractions[:, j], fractions[:, j + 1])[0, 1]
                    for j in range(fractions.shape[1] - 1)])


def test_sampler_fills_each_joint_range_and_edge_samples_bend_neighbours_alike(kinematic):
    """Uniform samples spread over each joint's whole range and none sits on a limit (a sampler
    drawing past the limits would show as samples piled on them by its final clip); edge samples
    bend neighbouring joints the same way (measured correlation 0.81; uniform 0.005)."""
    limits = arm.ArmSpec.from_table1().joint_range_rad()
    fraction = (kinematic.joint_angles - limits[:, 0]) / (limits[:, 1] - limits[:, 0])
    uniform, edge = fraction[kinematic.uniform], fraction[~kinematic.uniform]
    assert len(uniform) == len(edge) == 3000
    assert np.all((uniform > 0) & (uniform < 1))
    assert np.all(uniform.min(axis=0) < 0.01) and np.all(uniform.max(axis=0) > 0.99)  # measured 0.0013
    np.testing.assert_allclose(uniform.mean(axis=0), 0.5, atol=0.03)  # 5.7 standard errors
    assert abs(_neighbour_correlation(uniform)) < 0.05
    assert _neighbour_correlation(edge) > 0.6


def test_attitude_is_the_sum_of_joint_angles(kinematic):
    """A planar chain: the head attitude equals the summed joint angles, with no wrap at 180."""
    summed = np.degrees(kinematic.joint_angles.sum(axis=1))
    np.testing.assert_allclose(kinematic.head_attitude, summed, atol=1e-6)
    assert summed.min() < -180 and summed.max() > 180  # the edge samples curl past a half turn


def test_blue_region_is_where_mujoco_points_the_head_forward_within_5_degrees(kinematic, physics):
    """The blue mask (attitude 90 +- 5 deg) against what it stands for: posed in MuJoCo, exactly
    the blue samples have the head's long axis within 5 deg of +x (level, facing forward).  Among
    them are necks curled back by about -270 deg (measured 32 of 96), which count because the
    attitude error is taken modulo a turn."""
    indices = physics_lib.arm_indices(physics.model)
    forward = np.empty(len(kinematic.joint_angles))
    for i, angles in enumerate(kinematic.joint_angles):
        physics.data.qpos[indices.qpos] = angles
        physics.forward()
        forward[i] = physics.data.xmat[indices.head_body].reshape(3, 3)[0, 2]  # head axis, world x
    level = kinematic.level()
    np.testing.assert_array_equal(level, forward >= np.cos(np.radians(5)))
    assert 0 < level.sum() < len(level)
    curled_back = np.degrees(kinematic.joint_angles[level].sum(axis=1)) < -180
    assert curled_back.sum() >= 10


def test_actuated_poses_lie_in_the_kinematic_workspace(actuated, physics):
    """Settled poses stay within Table 1's limits up to LIMIT_TOLERANCE_DEG (soft limits;
    measured worst case 0.8 deg over 1200 random inputs), so clamping them onto the
    limits moves the head by at most a few millimetres."""
    assert actuated.settled.sum() >= 10
    spec = arm.ArmSpec.from_table1()
    limits = spec.joint_range_rad()
    tolerance = np.radians(workspace.LIMIT_TOLERANCE_DEG)
    angles = actuated.joint_angles[actuated.settled]
    assert np.all(angles >= limits[:, 0] - tolerance)
    assert np.all(angles <= limits[:, 1] + tolerance)
    clamped = np.clip(angles, limits[:, 0], limits[:, 1])
    qpos_adr = physics_lib.arm_indices(physics.model).qpos
    for pose, head in zip(clamped, actuated.head_position[actuated.settled]):
        with physics.reset_context():
            physics.data.qpos[qpos_adr] = pose
        assert np.linalg.norm(physics.head_position()[[0, 2]] - head) < 0.01
    base = workspace.base_joint_xz(physics)
    distance = np.linalg.norm(actuated.head_position - base, axis=1)
    assert distance.max() <= workspace.reach_radius() + 1e-9


def test_actuated_workspace_reaches_less_than_the_kinematic_one(actuated, kinematic, physics):
    """Under gravity the neck hangs forward: no settled pose curls far back."""
    x = actuated.head_position[actuated.settled, 0]
    assert x.min() > kinematic.head_position[:, 0].min() + 0.1


def test_level_seeking_finds_inputs_that_hold_the_head_level(physics):
    samples = workspace.actuated_samples(12, seed=2, physics=physics, seek_level_time=2.5)
    level = samples.level()
    assert level.sum() >= 3  # measured 5 of these 12 draws, about half of 40 (a few % without seeking)
    for control, head in zip(samples.control[level], samples.head_position[level]):
        assert workspace.settle(physics, control)  # the stored inputs alone, from reset
        np.testing.assert_allclose(physics.head_position()[[0, 2]], head, atol=1e-9)
        assert abs(physics_lib.attitude_error_deg(physics.head_attitude(), 90)) <= 5


def test_frame_physics_reads_the_arm_and_a_diverged_pose_never_counts_as_settled(caplog):
    """frame_physics gives the studies the tasks' accessors; an arm that blows up (joints 10^6
    times stiffer) is a pose that did not come to rest: neither a crash nor the resting straight
    neck that MuJoCo resets a diverged simulation to."""
    physics = scenes.frame_physics()
    with physics.reset_context():
        physics.data.qpos[physics_lib.arm_indices(physics.model).qpos] = np.radians(5.0)
    assert physics.head_attitude() == pytest.approx(18 * 5.0, abs=1e-9)
    np.testing.assert_allclose(physics.joint_angles(), np.radians(5.0))
    stiff = scenes.frame_physics(arm.ArmSpec.from_table1(joint_stiffness=1e6))
    top = stiff.model.actuator_ctrlrange[:, 1]
    # 5 steps: MuJoCo resets the blown-up state to the straight neck, which is still at rest
    assert not workspace.settle(stiff, top, settle_time=0.01)
    assert np.abs(stiff.data.qvel).max() < 0.05 and np.abs(stiff.joint_angles()).max() < 0.01
    assert stiff.divergence is not None and "diverged" in caplog.text
    assert workspace.settle(physics, np.zeros(physics.model.nu), settle_time=1.5)  # the default arm rests
    assert physics.divergence is None


def test_command_line_writes_the_figure_and_the_samples(tmp_path):
    out = tmp_path / "ws"
    written = workspace.main(["--out", str(out), "--samples", "2000", "--edge-samples", "2000",
                              "--actuated-samples", "4", "--workers", "1", "--settle-time",
                              "0.5", "--no-progress"])
    png = written["figure"]
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20_000
    with np.load(written["samples"]) as data:
        assert data["kinematic_head_position"].shape == (4000, 2)
        assert data["actuated_head_position"].shape == (4, 2)
        assert data["kinematic_level"].dtype == bool
        assert str(data["fingerprint"]) == fingerprint_lib.model_fingerprint()


def test_targets_are_generated_from_the_workspace_sampler(tmp_path, physics):
    """target_generation.generate writes exactly the level subset of workspace.actuated_samples
    (the one source of targets), with the inputs that hold each pose."""
    path = tmp_path / "poses.npz"
    count = target_generation.generate(4, seed=5, path=path, workers=1)
    samples = workspace.actuated_samples(4, seed=5, physics=physics,
                                         seek_level_time=target_generation.SEEK_LEVEL_TIME)
    level = samples.level()
    assert count == level.sum() > 0
    with np.load(path) as data:
        np.testing.assert_array_equal(data["head_position"], samples.head_position[level])
        np.testing.assert_array_equal(data["head_attitude"], samples.head_attitude[level])
        np.testing.assert_array_equal(data["control"], samples.control[level])
        assert np.all(np.abs(physics_lib.attitude_error_deg(data["head_attitude"], 90)) <= 5)


@pytest.mark.parametrize("args, message", [
    (["--samples", "-5"], "argument --samples: must be from 0 to 10000000, got -5"),
    (["--samples", "0", "--edge-samples", "0"], "no kinematic workspace"),
    (["--settle-time", "nan"], "argument --settle-time: must be a number of seconds > 0 and at most 600, got nan"),
    (["--settle-time", "0"], "argument --settle-time: must be a number of seconds > 0 and at most 600, got 0"),
    (["--seek-level", "-1"], "argument --seek-level: must be a number of seconds >= 0 and at most 600, got -1"),
    (["--workers", "0"], "argument --workers: must be from 1 to 256, got 0"),
    (["--actuated-samples", "2.5"], "argument --actuated-samples: invalid whole number: '2.5'"),
])
def test_command_line_refuses_bad_numbers_by_flag(tmp_path, capsys, args, message):
    """Before, these failed deep inside numpy ('negative dimensions are not allowed', 'cannot convert
    float NaN to integer', a zero-size reduction) or ran with a silent fallback (--workers 0)."""
    with pytest.raises(SystemExit) as exit_info:
        workspace.main(["--out", str(tmp_path / "ws"), "--no-progress", *args])
    assert exit_info.value.code == 2
    assert message in capsys.readouterr().err.strip().splitlines()[-1]
    assert not (tmp_path / "ws").exists()
