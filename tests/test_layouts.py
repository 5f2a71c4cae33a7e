"""Tendon-layout comparison: layout files, the coverage metric, robostrich-layouts."""
import csv
import json
import os
import subprocess

import numpy as np
import pytest

from robostrich_suite.model import arm, layouts
from robostrich_suite import fingerprint as fingerprint_lib
from robostrich_suite.studies import coverage, layout_compare, workspace

import results_page
from conftest import console_script


def xml(layout, spec=None):
    return arm.build_arm(spec, layout).to_xml_string()


@pytest.mark.parametrize("name", list(layouts.BUILT_IN))
def test_builtin_layouts_fit_the_paper_budget_and_round_trip_through_a_file(name, tmp_path):
    layout = layouts.build(name)
    layout.validate(arm.ArmSpec.from_table1())
    assert len(layout) <= layouts.MAX_TENDONS
    path = tmp_path / f"{name}.json"
    path.write_text(json.dumps(layouts.to_dict(layout, name)))
    read_name, read = layouts.read_file(path)
    assert read_name == name and read == layout
    assert xml(read) == xml(layout)


def test_toml_file_with_spans_gives_the_same_mjcf_as_the_equivalent_layout(tmp_path):
    spec = arm.ArmSpec.from_table1()
    path = tmp_path / "mine.toml"
    path.write_text('[[tendons]]\nname = "dorsal"\nside = "dorsal"\nfrom = "c18"\nto = "atlas"\n\n'
                    '[[tendons]]\nname = "slip"\nside = "ventral"\nfrom = "c12"\nto = "c6"\n\n'
                    '[[tendons]]\nname = "skip"\nside = "ventral"\nlinks = ["c18", "c12", "c6", "c3"]\n')
    equivalent = arm.TendonLayout((
        arm.TendonSpec.spanning("dorsal", "dorsal", "atlas", spec),
        arm.TendonSpec.spanning("slip", "ventral", "c6", spec, origin="c12"),
        arm.TendonSpec("skip", "ventral", ("c18", "c12", "c6", "c3")),
    ))
    name, layout = layouts.read_file(path, spec)
    assert name == "mine" and layout == equivalent
    assert xml(layout, spec) == xml(equivalent, spec)


def tendon(**fields):
    return {"name": "t", "side": "ventral", "links": ["c18", "c10"], **fields}


MALFORMED = {  # file content -> words the error must contain
    "not_json": ("{tendons: [", "not valid JSON"),
    "a_list": ([tendon()], "expected a table/object"),
    "no_tendons": ({"name": "x"}, "'tendons' must be a non-empty list"),
    "empty_tendons": ({"tendons": []}, "'tendons' must be a non-empty list"),
    "unknown_file_key": ({"tendons": [tendon()], "colour": "red"}, "unknown key(s) ['colour']"),
    "tendon_not_table": ({"tendons": ["dorsal"]}, "tendon 1: expected a table/object"),
    "unknown_tendon_key": ({"tendons": [tendon(width=2)]}, "tendon 1 ('t'): unknown key(s) ['width']"),
    "no_name": ({"tendons": [{"side": "dorsal", "links": ["c18", "c2"]}]}, "'name' must be a string"),
    "no_side": ({"tendons": [{"name": "t", "links": ["c18", "c2"]}]}, "'side' must be a string"),
    "neither_links_nor_span": ({"tendons": [{"name": "t", "side": "dorsal"}]}, "either 'links'"),
    "links_and_span": ({"tendons": [tendon(**{"from": "c18", "to": "c2"})]}, "either 'links'"),
    "links_not_names": ({"tendons": [tendon(links=["c18", 3])]}, "'links' must be a list of link names"),
    "on_base_not_bool": ({"tendons": [tendon(on_base="yes")]}, "'on_base' must be true or false"),
    "span_with_on_base": ({"tendons": [{"name": "t", "side": "dorsal", "from": "c18", "to": "c2",
                                        "on_base": False}]}, "'on_base' goes with 'links'"),
    "span_unknown_link": ({"tendons": [{"name": "t", "side": "dorsal", "from": "c18", "to": "c1"}]},
                          "unknown link 'c1'"),
    "span_backwards": ({"tendons": [{"name": "t", "side": "dorsal", "from": "c2", "to": "c18"}]},
                       "is caudal of origin"),
    # TendonLayout.validate's own errors, named the same way
    "unknown_side": ({"tendons": [tendon(side="lateral")]}, "unknown side 'lateral'"),
    "unknown_link": ({"tendons": [tendon(links=["c18", "c19"])]}, "unknown link 'c19'"),
    "one_hole": ({"tendons": [tendon(links=["c18"])]}, "a tendon needs at least two"),
    "cranial_first": ({"tendons": [tendon(links=["c10", "c18"])]}, "from caudal to cranial"),
    "duplicate_names": ({"tendons": [tendon(), tendon()]}, "duplicate tendon name 't'"),
    "bad_name": ({"tendons": [tendon(name="a\tb")]}, "must be a non-empty printable string"),
}


@pytest.mark.parametrize("case", list(MALFORMED))
def test_every_malformed_file_gets_a_named_error(case, tmp_path):
    content, words = MALFORMED[case]
    path = tmp_path / f"{case}.json"
    path.write_text(content if isinstance(content, str) else json.dumps(content))
    with pytest.raises(layouts.LayoutFileError) as error:
        layouts.read_file(path)
    assert str(path) in str(error.value) and words in str(error.value), str(error.value)


def test_malformed_toml_and_unknown_file_types_are_named(tmp_path):
    bad_toml = tmp_path / "bad.toml"
    bad_toml.write_text("[[tendons]\nname = ")
    with pytest.raises(layouts.LayoutFileError, match="bad.toml: not valid TOML"):
        layouts.read_file(bad_toml)
    yaml = tmp_path / "layout.yaml"
    yaml.write_text("tendons: []")
    with pytest.raises(layouts.LayoutFileError, match="unknown layout file type '.yaml'"):
        layouts.read_file(yaml)
    with pytest.raises(OSError):
        layouts.read_file(tmp_path / "missing.json")
    os.mkfifo(tmp_path / "fifo.toml")  # refused at once: reading it would wait for a writer
    with pytest.raises(layouts.LayoutFileError, match="fifo.toml: a FIFO, not a layout file"):
        layouts.read_file(tmp_path / "fifo.toml")
    with pytest.raises(ValueError, match="unknown layout 'best'"):
        layouts.build("best")


def constructed_region():
    """Three blue-region cells far apart (two samples each) plus a sample that is not level."""
    positions = np.array([[0.101, 0.501], [0.109, 0.509], [0.201, 0.501], [0.205, 0.505],
                          [0.301, 0.401], [0.309, 0.405], [0.0, 0.3]])
    attitudes = np.array([90, 92, 88, 90, 95, 85, 120.0])
    samples = workspace.KinematicSamples(np.zeros((7, 18)), positions, attitudes, np.ones(7, bool))
    return coverage.BlueRegion.from_samples(samples)


def test_coverage_is_one_for_an_arm_that_holds_everything_and_one_cell_for_a_single_pose():
    region = constructed_region()
    assert region.num_cells == 3 and len(region.head_position) == 6
    everything = region.head_position
    held = workspace.ActuatedSamples(everything, np.full(6, 90.0), np.zeros((6, 9)), np.ones(6, bool))
    assert region.coverage(coverage.held_level_positions(held)) == 1.0
    assert region.coverage(region.head_position[:1]) == pytest.approx(1 / 3)
    assert region.coverage(np.empty((0, 2))) == 0.0
    # held within HOLD_DISTANCE of a cell's sample counts, farther does not
    near = region.head_position[2] + [coverage.HOLD_DISTANCE - 1e-4, 0]
    far = region.head_position[3] + [0, coverage.HOLD_DISTANCE + 0.005]
    assert region.covered(near[None]).tolist() == [False, True, False]
    assert region.covered(far[None]).tolist() == [False, False, False]
    # a pose held with the head not level, or not at rest, holds nothing
    tilted = workspace.ActuatedSamples(everything, np.full(6, 100.0), np.zeros((6, 9)), np.ones(6, bool))
    moving = workspace.ActuatedSamples(everything, np.full(6, 90.0), np.zeros((6, 9)), np.zeros(6, bool))
    assert region.coverage(coverage.held_level_positions(tilted)) == 0.0
    assert region.coverage(coverage.held_level_positions(moving)) == 0.0


def test_movement_tests_find_any_layouts_dorsal_and_ventral_tendons():
    spec = arm.ArmSpec.from_table1()
    renamed = layout_compare.movement_layout(layouts.build("antagonist_pairs"), spec)
    assert renamed.names[0] == "dorsal" and renamed.tendons[0].insertion == "atlas"
    ventral = [t for t in renamed.tendons if t.side == "ventral"]
    assert [t.name for t in ventral] == [f"ventral_{i}" for i in range(4)]
    assert [t.insertion for t in ventral] == ["c13", "c9", "c5", "atlas"]  # caudal to cranial
    assert all("ventral" not in t.name and not t.name.endswith("dorsal")
               for t in renamed.tendons if t.side == "dorsal" and t.name != "dorsal")
    only_dorsal = arm.TendonLayout((arm.TendonSpec.spanning("d", "dorsal", "atlas", spec),))
    assert layout_compare.movement_layout(only_dorsal, spec) is None


def test_the_better_layout_ships_with_its_own_targets_loadable_through_task_kwargs():
    import robostrich_suite
    from robostrich_suite import targets
    path = layouts.target_file("antagonist_pairs")
    spec = arm.ArmSpec.from_table1()
    assert str(targets.level_head_poses(path)["fingerprint"]) == fingerprint_lib.model_fingerprint(
        spec, layouts.build("antagonist_pairs"))
    assert layouts.target_file("ventral_slips") == targets.DATA_PATH  # the tasks' default
    with pytest.raises(ValueError, match="'paper' is now called 'ventral_from_base'"):
        layouts.target_file("paper")
    from_base = layouts.target_file("ventral_from_base")
    assert str(targets.level_head_poses(from_base)["fingerprint"]) == fingerprint_lib.model_fingerprint(
        spec, layouts.build("ventral_from_base"))
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=layouts.task_kwargs("antagonist_pairs"))
    assert env.action_spec().shape == (9,)
    assert len(env.task.target_pool) == len(targets.training_targets(path)) > 0
    with pytest.raises(FileNotFoundError, match="no target file ships for layout 'cranial_every'"):
        layouts.target_file("cranial_every")


def test_the_fig1b_candidates_are_the_routings_with_the_papers_tendons():
    """One dorsal tendon to the head and eight ventral tendons at C16, C14, ..., C2, whatever
    their caudal ends: the default first; our own routings are not candidates."""
    candidates = layouts.fig1b_candidates()
    assert candidates[0] == layouts.DEFAULT == "ventral_slips"
    assert {"ventral_from_base", "ventral_slips_2", "ventral_slips_6"} <= set(candidates)
    assert not {"antagonist_pairs", "second_dorsal", "cranial_every"} & set(candidates)
    spans = {name: [len(t.links) for t in layouts.build(name).tendons[1:]] for name in candidates}
    assert spans["ventral_slips"][2:] == [5] * 6  # each slip runs through 5 holes: 4 joints
    assert len(set(map(tuple, spans.values()))) == len(candidates)  # each routed another way


@pytest.mark.long
def test_the_fidelity_check_prints_the_candidates_table(tmp_path):
    """`--candidates` measures every candidate of Fig. 1B, the rolling/lever test included."""
    out = tmp_path / "out"
    result = run_layouts("--out", out, "--candidates", "--kinematic-samples", 2000, "--random-samples", 1,
                         "--seek-time", 0.1, "--no-lookup", "--no-progress", "--workers", 2)
    assert result.returncode == 0, result.stderr[-3000:]
    rows = {row["layout"]: row for row in csv.DictReader(open(out / "layouts.csv"))}
    assert list(rows) == layouts.fig1b_candidates()
    # The paper's difference: rolling keeps the attitude at equal head travel on the default,
    # and does not on the routing with every ventral tendon from the base.
    assert float(rows["ventral_slips"]["rolling_lever_ratio"]) < 0.6
    assert float(rows["ventral_from_base"]["rolling_lever_ratio"]) > 1.0
    assert "head travel (mm)" in result.stdout and "| ventral_slips |" in result.stdout
    # layouts.json is what a results record keeps: the rows, the command, the blue region
    written = json.loads((out / "layouts.json").read_text())
    assert written["command"].startswith("robostrich-layouts --out ") and "--candidates" in written["command"]
    assert [row["layout"] for row in written["rows"]] == list(rows)
    assert written["blue_region"]["kinematic_samples"] == 2000
    record = results_page.make_record("fidelity", str(out / "layouts.json"), "Fidelity", date="2026-12-04")
    assert record["kind"] == "layouts" and record["command"] == written["command"]
    page = results_page.render_record(record)
    ratio = float(rows["ventral_slips"]["rolling_lever_ratio"])
    assert f"| ventral_slips | 1 | 9 |" in page and f"| {ratio:.2f} |" in page
    assert "target_file" not in json.dumps(record)  # where this run wrote is not a result


def run_layouts(*args):
    env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
    return subprocess.run([console_script("robostrich-layouts"), *map(str, args)], capture_output=True, text=True,
                          env=env, timeout=600)


def test_console_script_compares_a_file_layout_on_a_tiny_run(tmp_path):
    mine = tmp_path / "mine.json"
    mine.write_text(json.dumps(layouts.to_dict(layouts.build("ventral_slips"), "my_slips")))
    out = tmp_path / "out"
    result = run_layouts("--out", out, "--layouts", "antagonist_pairs", "--layout-file", mine,
                         "--kinematic-samples", 3000, "--random-samples", 1, "--seek-time", 0.2,
                         "--no-movement", "--no-progress")
    assert result.returncode == 0, result.stderr[-3000:]
    assert "Traceback" not in result.stderr
    for name in ("layouts.md", "layouts.csv", "layouts.png", "targets/antagonist_pairs.npz",
                 "targets/my_slips.npz"):
        assert (out / name).exists(), name
    table = (out / "layouts.md").read_text()
    assert "| antagonist_pairs |" in table and "| my_slips |" in table and "coverage" in table


def test_console_script_refuses_a_bad_file_with_one_line(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"tendons": [tendon(links=["c18", "c19"])]}))
    result = run_layouts("--out", tmp_path / "out", "--layouts", "--layout-file", bad, "--no-progress")
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("robostrich-layouts: error: "), result.stderr
    assert "bad.json" in lines[0] and "unknown link 'c19'" in lines[0]
    assert run_layouts("--help").returncode == 0


def test_a_layout_given_by_name_to_load_builds_that_layout_and_anything_else_is_named():
    import robostrich_suite
    from robostrich_suite import fingerprint as fp
    with pytest.warns(UserWarning, match="shipped targets were made with the default arm"):
        by_name = robostrich_suite.load("robostrich", "lesson2", task_kwargs={"tendon_layout": "antagonist_pairs"})
    built = robostrich_suite.load("robostrich", "lesson2", task_kwargs=layouts.task_kwargs("antagonist_pairs"))
    assert fp.compiled_fingerprint(by_name.physics.model) == fp.compiled_fingerprint(built.physics.model)
    assert fp.compiled_fingerprint(by_name.physics.model) != fp.compiled_fingerprint(
        robostrich_suite.load("robostrich", "lesson2").physics.model)
    with pytest.raises(ValueError, match="nope"):
        robostrich_suite.load("robostrich_a1", "lesson2", task_kwargs={"tendon_layout": "nope"})
    with pytest.raises(TypeError, match="tendon layout must be a TendonLayout, got int"):
        arm.build_arm(layout=3)


def test_a_tendons_own_hole_offset_moves_its_holes_and_round_trips_through_a_file(tmp_path):
    spec = arm.ArmSpec.from_table1()
    default = layouts.build("ventral_slips")
    tendons = list(default.tendons)
    tendons[1] = arm.TendonSpec(tendons[1].name, "ventral", tendons[1].links, tendons[1].on_base, hole_offset=0.025)
    mine = arm.TendonLayout(tuple(tendons))
    path = tmp_path / "mine.json"
    path.write_text(json.dumps(layouts.to_dict(mine, "mine")))
    assert layouts.read_file(path)[1] == mine
    from dm_control import mjcf
    physics = mjcf.Physics.from_mjcf_model(arm.build_arm(spec, mine))
    own = arm.hole_site_name("c17", "ventral", tendons[1].name)
    assert physics.named.model.site_pos[own][0] == pytest.approx(0.025)
    assert physics.named.model.site_pos[arm.hole_site_name("c17", "ventral")][0] == pytest.approx(spec.hole_offset)
    # A longer moment arm: the same joint bend shortens the tendon more, so its servo's range grows.
    ranges = physics.named.model.actuator_ctrlrange
    before = mjcf.Physics.from_mjcf_model(arm.build_arm(spec, default)).named.model.actuator_ctrlrange
    assert ranges[tendons[1].name][1] > before[tendons[1].name][1]
    assert xml(layouts.build("ventral_slips")) == xml(arm.TendonLayout(tuple(
        arm.TendonSpec(t.name, t.side, t.links, t.on_base, hole_offset=None) for t in default.tendons)))


@pytest.mark.parametrize("bad", [0.5, 0.001, "x", True, None, float("inf")])
def test_a_hole_offset_out_of_range_names_the_file_and_the_tendon(bad, tmp_path):
    data = layouts.to_dict(layouts.build("ventral_slips"), "mine")
    data["tendons"][2]["hole_offset"] = bad
    path = tmp_path / "mine.json"
    path.write_text(json.dumps(data))
    with pytest.raises(layouts.LayoutFileError, match=r"mine\.json: tendon 3 \('ventral_c14'\): 'hole_offset' must be"):
        layouts.read_file(path)
    with pytest.raises(ValueError, match="hole_offset"):
        arm.TendonLayout((arm.TendonSpec("d", "dorsal", ("c18", "atlas"), hole_offset=0.1),)).validate(
            arm.ArmSpec.from_table1())
