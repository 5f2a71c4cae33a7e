"""robostrich-sweep given a damaged grid file, or a sweep directory whose record of its groups
(OUT/grid.json) is torn: one line naming the file, exit 2, no traceback, no run started."""
import json

import pytest

from agents.robostrich.sweep import grid as sweep_grid
from conftest import finish, start



def _one_line(result, *fragments) -> str:
    lines = result.stderr.strip().splitlines()
    assert result.returncode == 2 and len(lines) == 1, (result.returncode, result.stderr[-3000:])
    assert lines[0].startswith("robostrich-sweep: error: "), lines[0]
    for fragment in fragments:
        assert fragment in lines[0], (fragment, lines[0])
    return lines[0]


def test_a_damaged_grid_file_is_named_in_one_line(tmp_path):
    pytest.importorskip("ray")
    grids = {"deep.toml": ("seeds = " + "[" * 100_000 + "]" * 100_000 + "\n").encode(),
             "torn.toml": b"seeds = [0, 1\n[train]\n",
             "latin.toml": 'layouts = ["caf\u00e9"]\n'.encode("latin-1"),
             "deep_table.toml": ("[train]\ntask-kwargs = " + "{a = " * 100 + "1" + "}" * 100 + "\n").encode()}
    words = {"deep.toml": "nested too deeply", "torn.toml": "not valid TOML", "latin.toml": "UTF-8",
             "deep_table.toml": "nested too deeply"}
    processes = {}
    for name, content in grids.items():
        (tmp_path / name).write_bytes(content)
        processes[name] = start("robostrich-sweep", "--grid", tmp_path / name, "--out", tmp_path / f"out_{name}")
    for name, process in processes.items():
        _one_line(finish(process), str(tmp_path / name), words[name])
        assert not (tmp_path / f"out_{name}").exists()


def test_a_torn_record_of_the_groups_is_named_in_one_line(tmp_path):
    pytest.importorskip("ray")
    processes = {}
    for name, text in {"torn": '{"default": ["--steps"', "list": "[1, 2]", "flags": '{"default": [1]}'}.items():
        out = tmp_path / name
        out.mkdir()
        (out / "grid.json").write_text(text)
        processes[name] = start("robostrich-sweep", "--seeds", "0", "--out", out, "--steps", "600", "--quiet")
    for name, process in processes.items():
        _one_line(finish(process), str(tmp_path / name / "grid.json"))
        assert not (tmp_path / name / "runs").exists()


def test_the_record_of_the_groups_reads_back(tmp_path):
    path = tmp_path / "grid.json"
    assert sweep_grid.read_recorded_groups(str(path)) == {}
    path.write_text(json.dumps({"default": ["--steps", "600"]}))
    assert sweep_grid.read_recorded_groups(str(path)) == {"default": ["--steps", "600"]}


def test_a_damaged_summary_of_a_finished_run_is_named_in_one_line(tmp_path):
    """A run counts as finished by its summary.json; one that is torn is named, not a traceback."""
    pytest.importorskip("ray")
    processes = {}
    for name, text in {"torn": '{"runs": {', "deep": "[" * 100_000 + "]" * 100_000}.items():
        summary = tmp_path / name / "runs" / "default" / "seed_0" / "summary.json"
        summary.parent.mkdir(parents=True)
        summary.write_text(text)
        processes[name] = start("robostrich-sweep", "--seeds", "0", "--out", tmp_path / name, "--steps", "600",
                                "--quiet")
    for name, process in processes.items():
        _one_line(finish(process), str(tmp_path / name / "runs" / "default" / "seed_0" / "summary.json"))
