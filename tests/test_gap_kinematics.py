"""tools/gap_kinematics.py: the level-pose families and the measures that place a narrow gap."""
import numpy as np

from robostrich_suite import targets
from test_benchmarks import load_tool

tool = load_tool("gap_kinematics")


def test_swept_heights_interpolates_every_crossing_of_the_line():
    down = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 1.0]])  # crosses x = 0.5 at 0.5
    arch = np.array([[0.0, 0.0], [1.0, 2.0], [0.2, 3.0]])  # crosses x = 0.5 at 1.0 and 2.625
    neck = np.stack([down, arch])
    assert tool.swept_heights(neck, np.array([True, True]), 0.5) == [0.5, 2.625]
    assert tool.swept_heights(neck, np.array([True, False]), 0.5) == [0.5, 0.5]
    assert tool.swept_heights(neck, np.array([True, True]), 5.0) is None


def test_pivot_is_where_the_poses_part():
    shared = np.array([[0.0, 0.0], [0.0, 0.1], [0.0, 0.2]])
    up, down = np.array([[0.1, 0.3], [0.2, 0.4]]), np.array([[0.1, 0.1], [0.2, 0.0]])
    neck = np.stack([np.vstack([shared, up]), np.vstack([shared, down])])
    index, point = tool.pivot(neck, np.array([True, True]))
    assert index == 2 and np.allclose(point, [0.0, 0.2])


def test_held_stored_inputs_sort_into_families_on_the_standing_quadruped():
    import robostrich_suite
    env = robostrich_suite.load("robostrich_a1", "lesson2")
    controls = targets.level_head_poses()["control"][::100]
    head, attitude, neck, geoms = tool.hold_all(env, controls)
    assert neck.shape == (len(controls), len(geoms) * tool.SAMPLES_PER_CAPSULE, 2)
    np.testing.assert_allclose(neck[:, -tool.SAMPLES_PER_CAPSULE:].mean(1), head, atol=0.02)  # last geom: the head
    masks = tool.families(head, attitude)
    total = sum(m.astype(int) for m in masks.values())
    assert total.max() == 1 and total.sum() >= len(controls) // 2  # stored poses are level ones
    assert masks["curled"].any() and masks["forward"].any() and masks["raised"].any()
    assert np.all(head[masks["curled"], 1] < 0.45) and np.all(attitude[masks["curled"]] < -180)
    assert np.all(head[masks["raised"], 1] > 0.6)
