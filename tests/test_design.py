"""robostrich-design: the routing search, its gap measure, its study's resumption and its outputs."""
import json
import os
import signal
import sqlite3
import subprocess
import time

import numpy as np
import pytest

import robostrich_suite
from robostrich_suite import scenes, targets
from robostrich_suite.model import arm, layouts
from robostrich_suite.studies import design, design_objectives, design_space, design_study, gap_column, gap_passage, layout_compare

import results_page
from conftest import console_script

NECK_RADIUS, HEAD_RADIUS = 0.008, 0.0128
TINY = ["--pose-budget", str(design.MIN_POSE_BUDGET), "--quiet"]


# --------------------------------------------------------------------------- the gap measure

def _pose(points, head):
    """A pose of polyline ``points`` (neck, base to head's caudal end) and a level head forward of it."""
    neck = np.concatenate([np.linspace(a, b, 12, endpoint=False) for a, b in zip(points, points[1:])])
    start = np.asarray(points[-1], float)
    head_points = np.linspace(start, start + [0.06, 0.0], 5)
    assert np.allclose(head_points[2], head)
    return np.concatenate([neck, head_points]), np.r_[np.full(len(neck), NECK_RADIUS), np.full(5, HEAD_RADIUS)]


def _held(poses):
    points, radii = zip(*poses)
    n = len(poses)
    heads = np.array([p[-3] for p in points])
    return gap_column.HeldPoses(np.zeros((n, 9)), heads, np.full(n, 90.0), np.ones(n, bool), np.array(points),
                                radii[0])


def _rising_necks(heights):
    """Necks that reach forward low, then rise straight up to a level head at x 0.30."""
    return _held([_pose([(0.0, 0.0), (0.27, 0.05), (0.27, z)], (0.30, z)) for z in heights])


def _lever_necks(heights):
    """Necks straight from the base to the head, as a lever turning about the base."""
    return _held([_pose([(0.0, 0.0), (0.27, z)], (0.30, z)) for z in heights])


def test_a_column_of_necks_rising_through_the_slot_measures_its_height():
    held = _rising_necks([0.20, 0.24, 0.28])
    column = gap_column.tallest_column(held, lambda a, b, scene: True)
    assert column.height == pytest.approx(0.08)
    assert column.poses == (0, 1, 2)
    scene = column.scene
    assert abs(scene.slot_x - 0.30) <= gap_column.COLUMN_TOLERANCE
    assert scene.shelf_z + scenes.GAP_SHELF_THICKNESS < 0.20 and not scene.touches(held.points, held.radii).any()
    # A step the ramp cannot make splits the column: the taller part is what counts.
    cut = gap_column.tallest_column(held, lambda a, b, scene: (a, b) != (1, 2))
    assert cut.height == pytest.approx(0.04) and cut.poses == (0, 1)
    # Heads farther apart than a step are not neighbours.
    assert gap_column.tallest_column(_rising_necks([0.20, 0.30]), lambda a, b, s: True).height == 0.0


def test_necks_swinging_as_a_lever_have_no_column_and_a_shelf_across_a_neck_touches_it():
    held = _lever_necks([0.20, 0.24, 0.28])
    assert gap_column.columns(held) == []
    assert gap_column.tallest_column(held, lambda a, b, scene: True).height == 0.0
    rising = _rising_necks([0.24])
    assert not gap_column.Scene(0.29, 0.10).touches(rising.points, rising.radii)[0]  # through the slot
    assert gap_column.Scene(0.20, 0.10).touches(rising.points, rising.radii)[0]  # the shelf across the neck


def test_a_slot_range_keeps_only_the_columns_whose_slot_lies_in_it():
    held = _rising_necks([0.20, 0.24, 0.28])  # a column at x 0.30
    inside = gap_column.tallest_column(held, lambda a, b, scene: True, slot_x=(0.2, 0.4))
    assert inside.height == pytest.approx(0.08) and 0.2 <= inside.scene.slot_x <= 0.4
    assert gap_column.threading(held, slot_x=(0.2, 0.4)).all()
    assert abs(gap_column.refine_targets(held, 2, (0.2, 0.4))[0, 0] - 0.30) < 1e-9
    assert gap_column.columns(held, slot_x=(-0.1, 0.1)) == []
    assert gap_column.tallest_column(held, lambda a, b, scene: True, slot_x=(-0.1, 0.1)) == gap_column.NO_COLUMN
    assert not gap_column.threading(held, slot_x=(-0.1, 0.1)).any()
    assert gap_column.refine_targets(held, 2, (-0.1, 0.1)) is None
    # Without a column the way in ramps into the highest level pose over the range, the slot under it.
    target = design_objectives.passage_target(gap_column.NO_COLUMN, held, (0.2, 0.35))
    assert target.poses == (2,) and target.scene.slot_x == pytest.approx(0.30) and target.height == 0.0
    assert design_objectives.passage_target(gap_column.NO_COLUMN, held, (-0.1, 0.1)) == gap_column.NO_COLUMN


def test_the_way_in_scores_the_height_reached_through_the_slot_and_the_column_when_it_gets_there():
    score = design_objectives.passage_score
    assert score({"highest_in_slot_m": -0.10, "clear": 0}, 0.08) == pytest.approx(-0.10)
    assert score({"highest_in_slot_m": 0.03, "clear": 1}, 0.08) == pytest.approx(0.11)
    never = score({"highest_in_slot_m": None, "clear": 0, "nearest_to_slot_m": 0.2}, 0.08)
    assert never == pytest.approx(design_objectives.PASSAGE_FLOOR - 0.2)
    assert never < score({"highest_in_slot_m": -0.5, "clear": 0}, 0.0)
    assert score({"highest_in_slot_m": None, "clear": 0, "nearest_to_slot_m": None}, 0.0) < never


def test_a_ramp_that_stays_still_is_clear_and_one_through_the_shelf_is_not():
    spec, layout = design_space.SPEC, layouts.build("ventral_slips")
    physics = scenes.frame_physics(spec, layout)
    base = np.array(physics.named.data.xpos["arm/c18"])[[0, 2]]

    def to_plane(point):
        return np.asarray(point)[[0, 2]] - base

    held = gap_column.hold_poses(physics, [np.zeros(9)], to_plane, 2.0)
    far = gap_column.Scene(held.points[0, :, 0].max() + 1.0, 0.9)  # far ahead and above: nothing near the arm
    assert gap_column.ramp_stays_clear(physics, held, 0, 0, far, to_plane, 2.0)
    x, z = held.points[0, len(held.radii) // 2]
    across = gap_column.Scene(x + 0.1, z - 0.01)  # the near shelf cuts the neck halfway along it
    assert across.touches(held.points, held.radii)[0]
    assert not gap_column.ramp_stays_clear(physics, held, 0, 0, across, to_plane, 2.0)


def test_the_way_into_a_column_is_clear_under_an_open_sky_and_blocked_by_a_shelf_across_the_neck():
    spec, layout = design_space.SPEC, layouts.build("ventral_slips")
    physics = scenes.frame_physics(spec, layout)
    base = np.array(physics.named.data.xpos["arm/c18"])[[0, 2]]
    stored = targets.level_head_poses()["control"][100]  # a level pose, head 0.37 m up
    held = gap_column.hold_poses(physics, [stored], lambda p: np.asarray(p)[[0, 2]] - base, 2.0)
    # A shelf 2 m up and far ahead: every pose at rest is under it, every ramp to the level pose is clear.
    sky = gap_column.Column(gap_column.Scene(5.0, 2.0), (0,), 0.0)
    open_sky = gap_passage.measure(spec, layout, sky, held, 2.0, samples=40, ramps=2)
    assert open_sky["under_poses"] >= 10 and open_sky["ramps"] == 2 * len(gap_passage.RAMP_TIMES)
    assert 2 * open_sky["clear"] >= open_sky["ramps"] and open_sky["highest_in_slot_m"] is None  # slot 5 m ahead
    # Its neck crosses the task's shelf, 13.3 cm above the base joint, away from the slot: no ramp from
    # under the shelf ends there clear.
    points = held.points[0]
    crossing = points[np.argmin(np.abs(points[:, 1] - gap_column.SHELF_Z)), 0]
    across = gap_column.Column(gap_column.Scene(crossing + 0.12, gap_column.SHELF_Z), (0,), 0.0)
    assert across.scene.touches(held.points, held.radii)[0]
    blocked = gap_passage.measure(spec, layout, across, held, 2.0, samples=150, ramps=2)
    assert blocked["under_poses"] > 0 and blocked["ramps"] > 0 and blocked["clear"] == 0
    assert blocked["highest_in_slot_m"] is None or blocked["highest_in_slot_m"] < 0.0  # never up through the slot


# --------------------------------------------------------------------------- the search

def test_a_tiny_search_keeps_the_papers_routing_and_drops_the_one_from_the_base(tmp_path, capsys):
    out = tmp_path / "out"
    summary = design.main(["--trials", "2", "--out", str(out), "--start-from", "ventral_from_base", "ventral_slips",
                           *TINY])
    rows = {row["trial"]: row for row in summary["front"]}
    # ventral_from_base (trial 0) fails the paper's rolling/lever test, ventral_slips (trial 1) passes it.
    assert summary["trials"]["complete"] == 2 and summary["trials"]["feasible"] == 1
    assert list(rows) == [1] and rows[1]["rolling_lever_ratio"] < design_study.RATIO_LIMIT
    written = json.loads((out / "design.json").read_text())
    assert written["benchmark"] == "design" and written["command"].startswith("robostrich-design --trials 2")
    assert (out / "front.png").stat().st_size > 0
    # The front's routing is a layout file that the layouts command and the tasks accept.
    path = rows[1]["layout_file"]
    name, layout = layouts.read_file(path)
    assert name == "design_trial_1" and layout == design_space.layout(design_space.parameters(layouts.build("ventral_slips")))
    assert [t.links for t in layout.tendons] == [t.links for t in layouts.build("ventral_slips").tendons]
    env = robostrich_suite.load("robostrich", "lesson1", task_kwargs={"tendon_layout": path})
    assert env.action_spec().shape == (9,)
    assert layout_compare.make_cases([], [path], [])[0].label == "design_trial_1"
    # design.json is what a results record keeps.
    record = results_page.make_record("design", str(out / "design.json"), "Routings searched", date="2026-12-04")
    assert record["kind"] == "design" and "layout_file" not in json.dumps(record)
    page = results_page.render_record(record)
    assert f"| 1 | {rows[1]['coverage']:.0%} |" in page and "2 routings (1 with rolling/lever" in page
    assert "front of 1" in capsys.readouterr().out


def test_a_search_scored_by_the_way_in_records_it_per_trial(tmp_path):
    out = tmp_path / "out"
    summary = design.main(["--trials", "1", "--out", str(out), "--start-from", "ventral_slips", "--slot-x", "0.2,0.5",
                           "--score-passage", *TINY])
    assert summary["gap_objective"] == "passage" and summary["slot_x"] == [0.2, 0.5]
    assert summary["objectives"] == ["coverage", "gap_passage_m"]
    (row,) = summary["front"]
    passage = row["passage"]
    assert passage["samples"] == design_objectives.PASSAGE_SAMPLES and passage["ramps"] > 0
    height = row["gap_column_m"] if passage["target"] == "column" else 0.0
    assert row["gap_passage_m"] == design_objectives.passage_score(passage, height)
    assert summary["best_feasible_passage_m"] == row["gap_passage_m"]
    gap = row["gap"]
    assert gap["slot_x_m"] is None or 0.2 <= gap["slot_x_m"] <= 0.5
    record = results_page.make_record("design", str(out / "design.json"), "Way in searched", date="2026-12-04")
    page = results_page.render_record(record)
    assert "scored by coverage and the way in" in page and "the slot 20 to 50 cm ahead" in page


def test_the_space_round_trips_a_routing_and_refuses_one_outside_it():
    for name in layouts.fig1b_candidates():
        layout = layouts.build(name)
        assert [t.links for t in design_space.layout(design_space.parameters(layout)).tendons] == \
            [t.links for t in layout.tendons]
    with pytest.raises(ValueError, match="1 dorsal and 8 ventral"):
        design_space.parameters(layouts.build("antagonist_pairs"))


def _skipping_slips(tmp_path, insertions=("c14", "c10", "c6", "c2")) -> str:
    """A layout file beyond the paper's family: its dorsal tendon and ventral slips 4 joints long,
    holed every other link."""
    names = design_space.SPEC.joint_names
    ventral = [arm.TendonSpec(f"ventral_{link}", "ventral",
                              design_space.holes(names.index(link), names.index(link) + 4, 2),
                              on_base=names.index(link) + 4 == len(names) - 1)
               for link in insertions]
    layout = arm.TendonLayout((layouts.build("ventral_slips").tendons[0], *ventral))
    path = tmp_path / "skipping_slips.json"
    path.write_text(json.dumps(layouts.to_dict(layout, "skipping_slips")))
    return str(path)


def test_a_search_beyond_the_family_writes_routings_of_the_asked_tendons_that_load_as_a_task(tmp_path, capsys):
    out = tmp_path / "out"
    beyond = ["--ventral-tendons", "4", "--max-hole-stride", "2"]
    summary = design.main(["--trials", "1", "--out", str(out), "--start-from", _skipping_slips(tmp_path), *beyond,
                           *TINY])
    (row,) = summary["front"]  # the slips pass the rolling/lever test
    assert summary["tendons"] == {"dorsal": 1, "ventral": 4, "max_hole_stride": 2}
    record = results_page.make_record("design", str(out / "design.json"), "Beyond", date="2026-12-05")
    assert "beyond the paper's family: 1 dorsal and 4 ventral tendons, holes up to 2 links apart" in \
        results_page.render_record(record)
    name, layout = layouts.read_file(row["layout_file"])
    assert [t.side for t in layout.tendons] == ["dorsal"] + ["ventral"] * 4
    assert layout.tendons[1].links == ("c18", "c16", "c14")  # holes every other link, origin to insertion
    env = robostrich_suite.load("robostrich", "lesson1", task_kwargs={"tendon_layout": row["layout_file"]})
    assert env.action_spec().shape == (5,)
    step = env.step(np.full(5, 0.01))
    assert np.isfinite(step.observation["head_position"]).all()
    assert layout_compare.make_cases([], [row["layout_file"]], [])[0].layout == layout
    # The study keeps its tendon counts: resuming with others is one line naming them.
    for other in (["--ventral-tendons", "12", "--max-hole-stride", "2"], ["--dorsal-tendons", "2", *beyond], []):
        capsys.readouterr()
        assert design.cli(["--trials", "0", "--out", str(out), *other, *TINY]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "was started with --pose-budget 6 --ventral-tendons 4 --max-hole-stride 2, not" in err
        if other:  # and the settings asked for, where they differ
            assert f"{other[0]} {other[1]}" in err.split(", not ", 1)[1], err


def test_the_space_beyond_the_family_round_trips_its_routings_and_counts_its_tendons(tmp_path):
    space = design_space.Space(dorsal=2, ventral=12, max_stride=3)
    names = space.tendon_names()
    assert names[:3] == ["dorsal", "dorsal_2", "ventral_1"] and len(names) == 14
    params = {f"{name}_{key}": value for k, name in enumerate(names)
              for key, value in (("insertion", k % 16), ("span", 1 + k % 9), ("offset", 0.01), ("stride", 1 + k % 3))}
    layout = design_space.layout(params)
    assert len(layout) == 14 and layout.names[:2] == ("dorsal", "dorsal_2")
    assert design_space.layout(design_space.parameters(layout, space=space)) == layout
    _, skipping = layouts.read_file(_skipping_slips(tmp_path))
    with pytest.raises(ValueError, match="skips links"):
        design_space.parameters(skipping, space=design_space.Space(ventral=4))


# --------------------------------------------------------------------------- the command

def _complete(db) -> int:
    if not db.exists():
        return 0
    with sqlite3.connect(db, timeout=30) as connection:
        try:
            return connection.execute("SELECT COUNT(*) FROM trials WHERE state = 'COMPLETE'").fetchone()[0]
        except sqlite3.OperationalError:  # the tables are being made
            return 0


def _trials(db) -> dict:
    import optuna
    study = optuna.load_study(study_name="robostrich-design", storage=f"sqlite:///{db}")
    return {t.number: (t.state.name, t.values, t.params) for t in study.get_trials()}


def _start(out, trials):
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    return subprocess.Popen([console_script("robostrich-design"), "--trials", str(trials), "--out", str(out), *TINY],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def _wait_for_a_complete_trial(process, db, timeout=300):
    start = time.monotonic()
    while _complete(db) < 1:
        assert process.poll() is None, process.communicate()
        assert time.monotonic() - start < timeout, "no trial finished"
        time.sleep(0.2)


def test_a_killed_search_resumes_with_its_finished_trials_intact(tmp_path):
    out = tmp_path / "out"
    db = out / "study.db"
    process = _start(out, 50)
    _wait_for_a_complete_trial(process, db)
    process.send_signal(signal.SIGKILL)
    process.communicate()
    before = {n: t for n, t in _trials(db).items() if t[0] == "COMPLETE"}
    assert before
    done = subprocess.run([console_script("robostrich-design"), "--trials", str(len(before) + 1), "--out", str(out),
                           *TINY], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    after = _trials(db)
    assert {n: after[n] for n in before} == before  # every finished trial kept as it was
    assert sum(state == "COMPLETE" for state, _, _ in after.values()) == len(before) + 1
    assert json.loads((out / "design.json").read_text())["trials"]["complete"] == len(before) + 1


@pytest.mark.parametrize("signum, status, word", [(signal.SIGINT, 130, "interrupted"),
                                                   (signal.SIGTERM, 143, "terminated")])
def test_a_stop_marks_the_running_trial_failed_keeps_the_finished_ones_and_says_one_line(tmp_path, signum,
                                                                                        status, word):
    out = tmp_path / "out"
    db = out / "study.db"
    process = _start(out, 50)
    _wait_for_a_complete_trial(process, db)
    process.send_signal(signum)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == status, stderr[-3000:]
    shown = [line for line in stderr.replace("\r", "\n").splitlines() if line.strip() and "routings:" not in line]
    assert shown == [f"robostrich-design: {word}"], stderr[-3000:]  # no Optuna warning, no traceback
    states = [state for state, _, _ in _trials(db).values()]
    assert "RUNNING" not in states and states.count("COMPLETE") >= 1


@pytest.mark.parametrize("argv, message", [
    (["--trials", "-1"], "--trials: must be from 0"),
    (["--pose-budget", "2"], "--pose-budget: must be from 6"),
    (["--confirm", "x"], "--confirm: invalid whole number"),
    (["--storage", "nosuchdialect://x"], "--storage nosuchdialect://x:"),
    (["--start-from", "antagonist_pairs"], "--start-from antagonist_pairs: the search's routings have 1 dorsal"),
    (["--start-from", "nosuchlayout"], "unknown layout 'nosuchlayout'"),
    (["--slot-x", "0.5,0.2"], "--slot-x: MIN must be below MAX"),
    (["--slot-x", "0.3"], "--slot-x: must be two numbers MIN,MAX"),
    (["--slot-x", "0.1,nan"], "--slot-x: must be two numbers MIN,MAX"),
    (["--slot-x=-2,0.1"], "--slot-x: must lie within -1 to 1 m"),
    (["--ventral-tendons", "17"], "--ventral-tendons: must be from 2 to 16"),
    (["--dorsal-tendons", "0"], "--dorsal-tendons: must be from 1 to 4"),
    (["--max-hole-stride", "x"], "--max-hole-stride: invalid whole number"),
    (["--ventral-tendons", "4", "--start-from", "ventral_slips"], "1 dorsal and 4 ventral tendons, this one 1 and 8"),
])
def test_bad_input_is_one_line_and_exit_status_2(argv, message, tmp_path, capsys):
    assert _status([*argv, "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("robostrich-design: error: ") and message in err


def _status(argv) -> int:
    """The command's exit status, in this process (a usage error exits from the parser)."""
    try:
        return design.cli(argv)
    except SystemExit as stop:
        return stop.code


def test_a_study_resumed_with_another_pose_budget_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert design.cli(["--trials", "0", "--out", str(out), *TINY]) == 0
    assert design.cli(["--trials", "0", "--out", str(out), "--pose-budget", "7", "--quiet"]) == 2
    assert "was started with --pose-budget 6" in capsys.readouterr().err


def test_a_study_resumed_with_another_slot_range_or_scoring_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert design.cli(["--trials", "0", "--out", str(out), "--slot-x", "0.2,0.5", *TINY]) == 0
    assert design.cli(["--trials", "0", "--out", str(out), "--slot-x", "0.2,0.5", *TINY]) == 0
    for other in (["--slot-x=-0.1,0.1"], [], ["--slot-x", "0.2,0.5", "--score-passage"]):
        capsys.readouterr()
        assert design.cli(["--trials", "0", "--out", str(out), *other, *TINY]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "was started with --pose-budget 6 --slot-x 0.2,0.5, not --pose-budget 6" in err
