"""Trot generator, leg IK and gait files (format, replay, errors)."""
import numpy as np
import pytest

from robostrich_suite.model import legs
from robostrich_suite.model import quadruped as quad
from robostrich_suite.studies import gait as gait_command
from robostrich_suite.tasks import gait


def test_leg_ik_inverts_fk_over_the_workspace():
    rng = np.random.default_rng(0)
    hip = rng.uniform(0.2, 1.5, 200)
    knee = rng.uniform(-2.6, -1.0, 200)
    x, z = legs.leg_fk(hip, knee)
    hip2, knee2 = legs.leg_ik(x, z)
    np.testing.assert_allclose(hip2, hip, atol=1e-9)
    np.testing.assert_allclose(knee2, knee, atol=1e-9)
    # The per-step path (4 feet, plain floats) agrees with the vectorised one.
    few = legs.leg_ik(x[:4], z[:4])
    np.testing.assert_allclose(few[0], hip2[:4], atol=1e-12)
    np.testing.assert_allclose(few[1], knee2[:4], atol=1e-12)


def test_standing_targets_are_the_a1_standing_pose():
    depth = -legs.leg_fk(0.9, -1.8)[1]
    targets = gait.Standing().joint_targets(0.0, depth + quad.FOOT_RADIUS)
    np.testing.assert_allclose(targets, quad.STANDING_TARGETS, atol=1e-9)
    assert quad.standing_hip_height() == pytest.approx(quad.STANDING_TRUNK_HEIGHT, abs=0.002)


def test_trot_moves_diagonal_pairs_together_half_a_cycle_apart():
    trot = gait.TrotGait()
    t = np.linspace(0, 2 * trot.period, 101)
    x, z = trot.foot_positions(t)  # (101, 4) in FR, FL, RR, RL order
    np.testing.assert_allclose(x[:, 0], x[:, 3])  # FR with RL
    np.testing.assert_allclose(x[:, 1], x[:, 2])  # FL with RR
    half = trot.period / 2
    np.testing.assert_allclose(trot.foot_positions(t + half)[0][:, 0], x[:, 1], atol=1e-12)
    assert x.max() == pytest.approx(trot.stride / 2) and x.min() == pytest.approx(-trot.stride / 2)
    depth = trot.trunk_height - quad.FOOT_RADIUS
    assert z.min() == pytest.approx(-depth)
    assert z.max() == pytest.approx(-depth + trot.lift, abs=1e-3)
    # In stance (foot on the ground) the foot moves backwards at stride / half-period.
    stance = np.isclose(z[:, 0], -depth)
    speeds = np.diff(x[:, 0])[stance[:-1] & stance[1:]] / np.diff(t)[0]
    assert len(speeds) >= 40  # half of the 100 intervals (measured 50), not a vacuous comparison
    np.testing.assert_allclose(speeds, -trot.stride / half, rtol=1e-9)


def test_trot_targets_follow_the_trunk_height_command():
    trot = gait.TrotGait(stride=0.0, lift=0.0)
    for height in (0.2, 0.3):
        targets = trot.joint_targets(0.1, trunk_height=height)
        _, z = legs.leg_fk(targets[1::3], targets[2::3])
        np.testing.assert_allclose(z, -(height - quad.FOOT_RADIUS), atol=1e-12)
    with pytest.raises(ValueError, match="trunk height"):
        trot.joint_targets(0.0, trunk_height=0.45)


def test_gait_file_round_trips(tmp_path):
    times, targets = gait_command.sample_trot(gait.TrotGait(frequency=2.0), rate=50)
    path = tmp_path / "trot.csv"
    gait.write_gait_file(path, times, targets, comment="test\nsecond comment line")
    times2, targets2 = gait.read_gait_file(path)
    np.testing.assert_allclose(times2, times, atol=1e-4)
    np.testing.assert_allclose(targets2, targets, atol=1e-6)


def test_replay_interpolates_linearly_and_loops(tmp_path):
    times = np.array([0.0, 0.1, 0.3])
    targets = np.tile(quad.STANDING_TARGETS, (3, 1))
    targets[1, 1] += 0.2
    replay = gait.GaitReplay(times, targets)
    assert replay.period == pytest.approx(0.3)
    assert replay.raw_targets(0.05)[1] == pytest.approx(targets[0, 1] + 0.1)
    assert replay.raw_targets(0.2)[1] == pytest.approx(targets[0, 1] + 0.1)
    np.testing.assert_allclose(replay.raw_targets(0.05 + 3 * 0.3), replay.raw_targets(0.05))
    np.testing.assert_allclose(replay.raw_targets([0.05, 0.35])[1], replay.raw_targets(0.05))


def test_shipped_gait_file_replays_the_trot():
    replay = gait.GaitReplay.from_file()
    trot = gait.TrotGait()
    assert replay.period == pytest.approx(trot.period)
    t = np.linspace(0, 3, 77)
    np.testing.assert_allclose(replay.joint_targets(t), trot.joint_targets(t), atol=0.02)
    assert replay.recorded_trunk_height == pytest.approx(trot.trunk_height, abs=1e-6)


def test_replay_applies_a_new_trunk_height_by_moving_the_feet():
    replay = gait.GaitReplay.from_file()
    t = np.linspace(0, 1, 13)
    lowered = replay.joint_targets(t, trunk_height=0.22)
    x0, z0 = legs.leg_fk(replay.raw_targets(t)[:, 1::3], replay.raw_targets(t)[:, 2::3])
    x1, z1 = legs.leg_fk(lowered[:, 1::3], lowered[:, 2::3])
    # Feet are interpolated in Cartesian space, joints in joint space: equal to ~0.1 mm.
    np.testing.assert_allclose(x1, x0, atol=2e-4)
    np.testing.assert_allclose(z1 - z0, replay.recorded_trunk_height - 0.22, atol=2e-4)
    at_samples = replay.joint_targets(replay.times, trunk_height=0.22)
    xs, zs = legs.leg_fk(at_samples[:, 1::3], at_samples[:, 2::3])
    np.testing.assert_allclose(zs, legs.leg_fk(replay.targets[:, 1::3], replay.targets[:, 2::3])[1]
                               + (replay.recorded_trunk_height - 0.22), atol=1e-9)


def test_stride_scale_scales_the_fore_aft_foot_travel():
    for source in (gait.TrotGait(), gait.GaitReplay.from_file()):
        t = np.linspace(0, 0.4, 9)
        plain = source.joint_targets(t, 0.27)
        scaled = source.joint_targets(t, 0.27, stride_scale=np.array([1.2, 0.8, 1.0, 1.0]))
        x0, z0 = legs.leg_fk(plain[:, 1::3], plain[:, 2::3])
        x1, z1 = legs.leg_fk(scaled[:, 1::3], scaled[:, 2::3])
        np.testing.assert_allclose(x1, x0 * [1.2, 0.8, 1.0, 1.0], atol=1e-9)
        np.testing.assert_allclose(z1, z0, atol=1e-9)


def _write(tmp_path, rows, header=True):
    lines = ["# a comment"] + ([",".join(gait.COLUMNS)] if header else []) + rows
    path = tmp_path / "bad.csv"
    path.write_text("\n".join(lines) + "\n")
    return path


def _row(t, **changes):
    values = dict(zip(quad.JOINT_NAMES, quad.STANDING_TARGETS))
    values.update(changes)
    return ",".join([str(t)] + [str(values[n]) for n in quad.JOINT_NAMES])


@pytest.mark.parametrize("rows, message", [
    ([_row(0), _row(0.1) + ",0.5"], r"line 4: 14 columns, expected 13"),
    ([_row(0), ",".join(_row(0.1).split(",")[:-1])], r"line 4: 12 columns, expected 13"),
    ([_row(0), _row(0.2), _row(0.1)], r"line 5, column 1 \(time\): time 0.1 does not increase"),
    ([_row(0), _row(0.1), _row(0.1)], r"line 5, column 1 \(time\).*does not increase"),
    ([_row(0), _row(0.1, FL_thigh=float("nan"))], r"line 4, column 6 \(FL_thigh\).*not finite"),
    ([_row(0), _row("nan")], r"line 4, column 1 \(time\).*not finite"),
    ([_row(0), _row(0.1, RL_calf=-0.2)],
     r"line 4, column 13 \(RL_calf\): angle -0.2 rad is outside the joint range"),
    ([_row(0), _row(0.1, FR_hip=1.0)], r"line 4, column 2 \(FR_hip\).*outside the joint range"),
    ([_row(0), _row(0.1).replace("0.1,", "abc,", 1)], r"line 4, column 1: 'abc' is not a number"),
    ([_row(0)], r"at least 2 samples"),
    ([], r"no samples"),
])
def test_malformed_gait_file_raises_naming_the_problem(tmp_path, rows, message):
    path = _write(tmp_path, rows)
    with pytest.raises(ValueError, match=message):
        gait.read_gait_file(path)


def test_wrong_header_is_named(tmp_path):
    path = tmp_path / "bad.csv"
    header = list(gait.COLUMNS)
    header[4] = "FL_knee"
    path.write_text(",".join(header) + "\n" + _row(0) + "\n" + _row(0.1) + "\n")
    with pytest.raises(ValueError, match=r"line 1, column 5: header 'FL_knee', expected 'FL_hip'"):
        gait.read_gait_file(path)


def test_gait_main_writes_a_loadable_file(tmp_path):
    path = tmp_path / "trot.csv"
    gait_command.main(["--out", str(path), "--frequency", "3", "--stride", "0.08"])
    replay = gait.GaitReplay.from_file(path)
    assert replay.period == pytest.approx(1 / 3)


def test_trunk_height_schedule_interpolates_and_holds():
    schedule = gait.TrunkHeightSchedule((0, 1, 2), (0.27, 0.27, 0.22))
    assert schedule(0.5) == pytest.approx(0.27)
    assert schedule(1.5) == pytest.approx(0.245)
    assert schedule(10) == pytest.approx(0.22)
    with pytest.raises(ValueError, match="increase strictly"):
        gait.TrunkHeightSchedule((0, 0), (0.27, 0.27))
    with pytest.raises(ValueError, match="outside the range"):
        gait.TrunkHeightSchedule((0, 1), (0.27, 0.5))


def test_gait_file_problems_are_value_errors_naming_the_file(tmp_path):
    missing = tmp_path / "missing.csv"
    with pytest.raises(ValueError, match="no such gait file"):
        gait.read_gait_file(missing)
    binary = tmp_path / "binary.csv"
    binary.write_bytes(bytes(range(256)))
    with pytest.raises(ValueError, match="not a text"):
        gait.read_gait_file(binary)
    times, targets = gait.read_gait_file(gait.DATA_PATH)  # the shipped sample still reads
    assert len(times) == len(targets) > 2


def test_gait_file_needs_its_header_and_tolerates_a_byte_order_mark(tmp_path):
    good = tmp_path / "good.csv"
    times = np.array([0.0, 0.5, 1.0])
    targets = np.tile([0.0, 0.9, -1.8] * 4, (3, 1))
    gait.write_gait_file(good, times, targets)
    text = good.read_text()
    bom = tmp_path / "bom.csv"
    bom.write_text("\ufeff" + text, encoding="utf-8")
    np.testing.assert_array_equal(gait.read_gait_file(bom)[0], times)
    headless = tmp_path / "headless.csv"
    headless.write_text("\n".join(l for l in text.splitlines() if not l.startswith("time")) + "\n")
    with pytest.raises(ValueError, match=r"line 1, column 1: header '0\.0+', expected 'time' .the first row must name the columns"):
        gait.read_gait_file(headless)


def test_trunk_height_schedule_rejects_nan_times():
    with pytest.raises(ValueError, match="finite"):
        gait.TrunkHeightSchedule(times=(0.0, float("nan")), heights=(0.27, 0.25))


def test_gait_option_takes_a_path_or_a_gait_object_and_names_anything_else(tmp_path):
    """What README says `gait=` accepts; a standing task refuses a gait instead of ignoring it."""
    import robostrich_suite
    path = tmp_path / "trot.csv"
    gait.write_gait_file(path, *gait_command.sample_trot())
    for accepted in (str(path), path, gait.TrotGait(), gait.GaitReplay.from_file(path)):
        env = robostrich_suite.load("robostrich_a1", "lesson4", task_kwargs=dict(gait=accepted, time_limit=0.016))
        env.reset()
        env.step(np.zeros(9))
        assert hasattr(env.task.gait, "joint_targets")
    with pytest.raises(TypeError, match="a gait must be a gait file path.*got int 42"):
        robostrich_suite.load("robostrich_a1", "lesson4", task_kwargs=dict(gait=42))
    with pytest.raises(ValueError, match="gait applies to the walking tasks"):
        robostrich_suite.load("robostrich_a1", "lesson1", task_kwargs=dict(gait=gait.TrotGait()))
