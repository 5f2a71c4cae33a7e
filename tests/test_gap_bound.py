"""The links' own bound at the narrow gap: level poses through a slot, sought over the joint angles."""
import json

import numpy as np

from robostrich_suite.studies import gap_bound, gap_column


def test_over_the_mount_the_links_hold_a_column_and_out_of_reach_none():
    arm = gap_bound.Arm()
    starts = arm.random_angles(np.random.default_rng(0), 3)
    over_mount = gap_bound.column_at(arm, 0.0, gap_column.SHELF_Z, starts, steps=3)
    assert over_mount["seeds_found"] >= 1 and over_mount["column_height_m"] >= gap_column.TASK_NEED["column_height_m"]
    scene = gap_column.Scene(0.0, gap_column.SHELF_Z)
    lowest, highest = over_mount["poses"][0], over_mount["poses"][-1]
    for pose in (lowest, highest):  # the gap measure's own test agrees: level, over the slot, touching nothing
        assert abs(gap_bound.attitude_error(pose.attitude)) <= 5.0 and abs(pose.head[0]) <= gap_column.COLUMN_TOLERANCE
        assert not scene.touches(pose.points[None], arm.radii)[0]
        assert np.all(arm.low <= pose.joint_angles) and np.all(pose.joint_angles <= arm.high)
    assert highest.head[1] - lowest.head[1] == over_mount["column_height_m"] or \
        abs(highest.head[1] - lowest.head[1] - over_mount["column_height_m"]) < 1e-4
    # Beyond the arm's reach (0.64 m straight) no pose has its head over the slot at all.
    far = gap_bound.column_at(arm, 0.9, gap_column.SHELF_Z, starts[:2])
    assert far["seeds_found"] == 0 and far["column_height_m"] is None and far["least_miss_m"] is None


def test_a_survey_writes_its_numbers_and_figure(tmp_path):
    rows = gap_bound.survey([0.0, 0.9], [], starts=3, steps=1, pushed=1, task_starts=2)
    result = gap_bound.summary(rows, "test")
    assert result["slots"][0]["column_height_m"] > 0 and result["slots"][1]["column_height_m"] is None
    assert result["task_slot"]["starts"] == 2 and result["task_slot"]["slot_x_m"] == gap_column.TASK_NEED["slot_x_m"]
    assert result["farthest_slot_pushed_m"] >= 0.0 and result["need"] == gap_column.TASK_NEED
    assert 0.0 < result["forward_curl"]["passes_shelf_height_at_x_m"] < result["forward_curl"]["highest_point_m"][0]
    json.dumps(result)  # no poses, only numbers
    gap_bound.plot(rows, result, tmp_path / "bound.png")
    assert (tmp_path / "bound.png").stat().st_size > 0
