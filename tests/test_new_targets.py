"""New targets: level poses a policy never trained near (robostrich_suite/studies/new_targets.py),
the measure of a policy between the stored poses."""
import numpy as np
import pytest

from agents.robostrich.domains import Domain
from robostrich_suite import targets
from robostrich_suite.model import layouts
from robostrich_suite.studies import new_targets
from robostrich_suite.tasks.conventions import LEVEL_ATTITUDE_DEG, LEVEL_TOLERANCE_DEG


def _closest(points: np.ndarray, others: np.ndarray) -> float:
    return float(np.min(np.linalg.norm(points[:, None, :] - others[None, :, :], axis=2)))


@pytest.mark.parametrize("layout", ["ventral_slips", "antagonist_pairs", "ventral_from_base"])
def test_every_shipped_set_keeps_1_cm_from_the_training_poses_and_between_its_targets(layout):
    """Each routing whose targets ship has its set shipped too (a run never pays for it): the
    default count of level poses, none within 1 cm of a pose of the routing's target file or of
    another new target."""
    path = layouts.target_file(layout)
    shipped = new_targets.SHIPPED_DIR / new_targets.set_name(path)
    assert shipped.is_file(), f"{layout}: no shipped set {shipped.name}"
    poses = targets.level_head_poses(shipped)
    new = poses["head_position"]
    assert len(new) == new_targets.COUNT
    assert str(poses["fingerprint"]) == str(targets.level_head_poses(path)["fingerprint"])
    off_level = (poses["head_attitude"] - LEVEL_ATTITUDE_DEG + 180.0) % 360.0 - 180.0  # -270 is level after a loop
    assert np.all(np.abs(off_level) <= LEVEL_TOLERANCE_DEG)
    assert _closest(new, targets.level_head_poses(path)["head_position"]) >= targets.MIN_TARGET_SPACING
    apart = np.linalg.norm(new[:, None, :] - new[None, :, :], axis=2) + np.eye(len(new))
    assert apart.min() >= targets.MIN_TARGET_SPACING


def test_a_set_is_made_again_from_its_seed_alone_then_read_from_the_cache(tmp_path, monkeypatch):
    """Drawn here in one process, the set's first targets are the shipped set's (drawn by two): a
    set depends on its seed alone. Made once, it is cached, and the next call draws nothing."""
    shipped = targets.level_head_poses(new_targets.SHIPPED_DIR / new_targets.set_name(targets.DATA_PATH))
    monkeypatch.setenv("ROBOSTRICH_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(new_targets, "SHIPPED_DIR", tmp_path / "nothing_ships")
    made = new_targets.new_targets(targets.DATA_PATH, count=2, workers=1, progress=False)
    np.testing.assert_allclose(made, shipped["head_position"][:2], atol=1e-9)
    assert [p.name for p in (tmp_path / "cache").iterdir()] == [new_targets.set_name(targets.DATA_PATH)]

    def draw(*args, **kwargs):
        raise AssertionError("a cached set was drawn again")
    monkeypatch.setattr(new_targets, "make", draw)
    np.testing.assert_array_equal(new_targets.new_targets(targets.DATA_PATH, count=2), made)
    np.testing.assert_array_equal(new_targets.new_targets(targets.DATA_PATH, count=1), made[:1])


def test_the_quadruped_gets_the_frame_sets_targets_in_its_trunk_frame():
    frame, quadruped = Domain("robostrich").new_targets(3), Domain("robostrich_a1").new_targets(3)
    assert frame.shape == quadruped.shape == (3, 2)
    assert not np.allclose(frame, quadruped)
    heldout = Domain("robostrich").heldout_targets(), Domain("robostrich_a1").heldout_targets()
    np.testing.assert_allclose(quadruped - frame, heldout[1][:3] - heldout[0][:3], atol=1e-12)  # one shift


def test_another_seed_is_another_set_and_off_the_arm_there_is_none(tmp_path, monkeypatch):
    monkeypatch.setenv("ROBOSTRICH_CACHE", str(tmp_path))
    assert new_targets.set_name(targets.DATA_PATH, 1) != new_targets.set_name(targets.DATA_PATH)
    assert Domain("cartpole").new_targets(5) is None
