"""Targets come from poses the arm really held with its head level."""
import warnings

import numpy as np
import pytest

import robostrich_suite
from robostrich_suite import physics as physics_lib
from robostrich_suite import targets
from robostrich_suite.model import arm
from robostrich_suite.model import layouts as layouts_lib
from robostrich_suite import fingerprint as fingerprint_lib
from robostrich_suite import scenes
from robostrich_suite.studies import pose_seek, target_generation, workspace


def test_pose_set_was_made_with_the_current_arm():
    assert str(targets.level_head_poses()["fingerprint"]) == fingerprint_lib.model_fingerprint(), (
        "data/level_head_poses.npz is stale: run robostrich-targets --out robostrich_suite/data/level_head_poses.npz")


def test_poses_are_level_and_split_without_overlap():
    poses = targets.level_head_poses()
    assert len(poses["head_position"]) >= 50
    assert np.all(np.abs(physics_lib.attitude_error_deg(poses["head_attitude"], 90)) <= 5)
    train, held_out = targets.training_targets(), targets.heldout_targets()
    assert len(train) >= 60 and len(held_out) >= 15
    distances = np.linalg.norm(train[:, None] - held_out[None], axis=2)
    assert distances.min() >= targets.MIN_TARGET_SPACING
    for target in np.concatenate([train, held_out]):  # each one is a stored pose
        assert np.min(np.linalg.norm(poses["head_position"] - target, axis=1)) == 0.0


@pytest.mark.parametrize("index", [0, 21, 700, -1])  # random draws first, then sought blue-region poses
def test_stored_inputs_really_hold_the_head_level_there(index):
    """Re-simulated: the stored inputs, held from the fixed start for one episode, bring the
    default arm to rest at the stored head position with the head level."""
    poses = targets.level_head_poses()
    physics = scenes.frame_physics()
    assert workspace.settle(physics, poses["control"][index], pose_seek.HOLD_TIME)
    np.testing.assert_allclose(physics.head_position()[[0, 2]], poses["head_position"][index], atol=1e-6)
    assert abs(physics_lib.attitude_error_deg(physics.head_attitude(), 90)) <= 5


def test_another_arm_gets_a_warning_and_its_own_targets(tmp_path):
    slips = arm.TendonLayout.ventral_slips(span=6)
    with pytest.warns(UserWarning, match="shipped targets were made with the default arm"):
        robostrich_suite.load("robostrich", "lesson1",
                              task_kwargs=dict(tendon_layout=slips))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the default arm, passed explicitly: no warning
        robostrich_suite.load("robostrich", "lesson1",
                              task_kwargs=dict(arm_spec=arm.ArmSpec.from_table1()))

    path = tmp_path / "slip_targets.npz"
    count = target_generation.generate(12, seed=3, path=path, workers=1, spec=None, layout=slips,
                                       blue_samples=3000)
    with np.load(path) as data:
        assert str(data["fingerprint"]) == fingerprint_lib.model_fingerprint(None, slips)
        assert len(data["head_position"]) == count > 0
        assert np.all(np.abs(physics_lib.attitude_error_deg(data["head_attitude"], 90)) <= 5)
    # Re-held on the same arm every pose stays (the file is rewritten unchanged); a file of
    # another arm's inputs is refused by name.
    before = targets.level_head_poses(path)["head_position"].copy()
    assert target_generation.recheck(path, layout=slips) == (count, count)
    np.testing.assert_allclose(targets.level_head_poses(path)["head_position"], before, atol=1e-9)
    two = arm.TendonLayout(slips.tendons[:2])
    with pytest.raises(ValueError, match="inputs for 9 tendons, the arm has 2"):
        target_generation.recheck(path, layout=two)
    with pytest.raises(ValueError, match=r"only \d+ of \d+ poses .* left as it was"):  # the default arm's routing
        target_generation.recheck(path, layout=arm.TendonLayout.ventral_from_base())
    np.testing.assert_allclose(targets.level_head_poses(path)["head_position"], before, atol=1e-9)
    pool = np.concatenate([targets.training_targets(path), targets.heldout_targets(path)])
    assert len(pool) >= 1
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        env = robostrich_suite.load("robostrich", "lesson1", task_kwargs=dict(
            tendon_layout=slips, target_pool=pool))
    env.reset()
    assert any(np.allclose(env.task.target_position, p) for p in pool)


def test_running_the_module_prints_no_runpy_warning():
    """`python -m robostrich_suite.studies.targets` without runpy's RuntimeWarning about
    sys.modules: importing the package must not import the command module."""
    import os
    import subprocess
    import sys
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    result = subprocess.run([sys.executable, "-W", "default", "-m", "robostrich_suite.studies.targets",
                             "--help"],
                            capture_output=True, text=True, env=env, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "RuntimeWarning" not in result.stderr and "Warning" not in result.stderr, result.stderr
    assert "--samples" in result.stdout


def test_robostrich_targets_rechecks_a_file_and_names_bad_input(tmp_path):
    """The installed command: --recheck rewrites a file with the poses still held; a missing file
    or a renamed layout is one line on stderr and exit status 2."""
    import os
    import subprocess
    from conftest import console_script
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    command = console_script("robostrich-targets")
    path = tmp_path / "from_base.npz"
    poses = targets.level_head_poses(layouts_lib.target_file("ventral_from_base"))
    target_generation.save_level_poses(path, {k: poses[k][:5] for k in ("head_position", "head_attitude", "control")},
                                       str(poses["fingerprint"]))
    result = subprocess.run([command, "--recheck", "--out", path, "--layout", "ventral_from_base"],
                            capture_output=True, text=True, env=env, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "kept 5 of 5 level-head poses" in result.stdout
    for args, message in ((["--recheck", "--out", tmp_path / "missing.npz"], "no target file at"),
                          (["--recheck", "--out", path, "--layout", "paper"], "'paper' is now called 'ventral_from_base'")):
        result = subprocess.run([command, *map(str, args)], capture_output=True, text=True, env=env, timeout=300)
        lines = result.stderr.strip().splitlines()
        assert result.returncode == 2 and len(lines) == 1 and message in lines[0], result.stderr
        assert lines[0].startswith("robostrich-targets: error: ")
