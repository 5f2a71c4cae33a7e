"""Results live in one place: docs/results.md and the README's table are what the records give."""
import json
import pathlib
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))

import benchmark_seeds  # noqa: E402
import results_page  # noqa: E402


def _summary(success: float) -> dict:
    report = {"success_rate": success, "precise_success_rate": success / 2, "position_error_median": 0.01,
              "attitude_error_median": 1.0}
    return {"runs": {"curriculum": {"heldout": report, "track": {**report, "success_rate": 2 / 3}},
                     "lookup": {"heldout": {**report, "success_rate": 0.9}}},
            "env_steps": {"curriculum": 600_000, "lookup": 0}}


def test_readme_and_results_page_match_the_records():
    done = subprocess.run([sys.executable, str(ROOT / "tools" / "results_page.py"), "--check"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_every_number_of_the_readme_table_comes_from_the_main_job_record():
    record = {r["name"]: r for r in results_page.read_records()}[results_page.README_RECORD]
    readme = (ROOT / "README.md").read_text()
    begin = readme.index(results_page.BLOCK_BEGIN.format(name=results_page.README_RECORD))
    block = readme[begin:readme.index(results_page.BLOCK_END, begin)]
    curriculum = record["data"]["results"]["curriculum"]["heldout"]["success_rate"]["mean"]
    assert f"| curriculum SAC | {curriculum * 100:.1f} %" in block
    assert block.count("\n| ") == 1 + len(record["data"]["results"])  # header and one row per run


def test_a_changed_number_makes_the_committed_text_stale(tmp_path):
    records = results_page.read_records()
    changed = json.loads(json.dumps(records))
    main = next(r for r in changed if r["name"] == results_page.README_RECORD)
    stats = main["data"]["results"]["curriculum"]["heldout"]["success_rate"]
    stats["mean"] = stats["min"] = stats["max"] = 0.123
    readme = (ROOT / "README.md").read_text()
    expected = results_page.expected_files(changed, {results_page.README: readme})
    assert expected[results_page.README] != readme
    assert expected[results_page.PAGE] != results_page.PAGE.read_text()
    assert "12.3 %" in expected[results_page.PAGE]


def test_a_record_shows_spread_per_seed_track_targets_and_the_command(tmp_path):
    seeds_json = tmp_path / "seeds.json"
    agg = benchmark_seeds.aggregate([_summary(1.0), _summary(0.9)], seeds=[4, 5], minutes=[10.0, None])
    seeds_json.write_text(json.dumps(agg))
    record = results_page.make_record("x", str(seeds_json), "A title", "python tools/benchmark_seeds.py --seeds 4,5",
                                      date="2026-12-02")
    text = results_page.render_record(record)
    assert "95.0 % [90.0, 100.0]" in text  # mean [min, max] over the seeds
    assert "| lookup (no learning) | held-out, fixed start | 90.0 % |" in text  # one value: no spread shown
    assert "seed 4: 100.0 % / - / 2 of 3 track targets / 10.0 min" in text
    assert "seed 5: 90.0 % / - / 2 of 3 track targets / time unknown" in text
    assert "`python tools/benchmark_seeds.py --seeds 4,5` (2026-12-02," in text


def test_a_file_that_is_not_a_benchmark_is_refused(tmp_path):
    bad = tmp_path / "summary.json"
    bad.write_text(json.dumps({"runs": {}}))
    with pytest.raises(ValueError, match="not a tools/benchmark_seeds.py seeds.json"):
        results_page.make_record("x", str(bad), "t", "c")


def test_a_record_with_lesson_end_evaluations_gets_its_own_readme_block(tmp_path):
    summary = _summary(0.95)
    summary["lesson_ends"] = {"curriculum": {"heldout_after_lesson3": {
        "success_rate": 1.0, "precise_success_rate": 0.5, "position_error_median": 0.005, "attitude_error_median": 0.4}}}
    seeds_json = tmp_path / "seeds.json"
    seeds_json.write_text(json.dumps(benchmark_seeds.aggregate([summary], seeds=[0], minutes=[20.0])))
    record = results_page.make_record("quadruped", str(seeds_json), "On the quadruped", "cmd")
    text = results_page.render_record(record)
    assert "| curriculum SAC | held-out, fixed start, after lesson3 | 100.0 % |" in text
    assert "(held-out fixed / moving / `track` / after lesson3 / wall-clock of the whole job): " \
           "seed 0: 95.0 % / - / 2 of 3 track targets / 100.0 % / 20.0 min" in text
    records = results_page.read_records() + [record]
    readme = (ROOT / "README.md").read_text() + "\n" + results_page.BLOCK_BEGIN.format(name="quadruped") + \
        "\nold\n" + results_page.BLOCK_END + "\n"
    rendered = results_page.expected_files(records, {results_page.README: readme})[results_page.README]
    assert "old" not in rendered.split(results_page.BLOCK_BEGIN.format(name="quadruped"))[1]
    block = rendered.split(results_page.BLOCK_BEGIN.format(name="quadruped"))[1]
    assert "| run | held-out, fixed start | `track` | after lesson3 | within 1 cm and 2 deg | median error |" in block
    assert "| curriculum SAC | 95.0 % | 66.7 % | 100.0 % | 47.5 % | 1.00 cm, 1.00 deg |" in block
    assert "| lookup (no learning) | 90.0 % | - | - | 47.5 % | 1.00 cm, 1.00 deg |" in block
    with pytest.raises(ValueError, match="no record 'missing'"):
        results_page.expected_files(records, {results_page.README: readme + results_page.BLOCK_BEGIN.format(name="missing")})


def test_a_changed_number_of_a_record_makes_the_page_that_shows_it_stale():
    """docs/layouts.md shows the routings' record: a coverage changed in the record is a stale page."""
    records = json.loads(json.dumps(results_page.read_records()))
    texts = {path: path.read_text() for path in results_page.block_pages()}
    layouts_page = ROOT / "docs" / "layouts.md"
    assert "layouts_comparison" in results_page.blocks(texts[layouts_page])
    assert results_page.expected_files(records, texts)[layouts_page] == texts[layouts_page]
    record = next(r for r in records if r["name"] == "layouts_comparison")
    row = next(r for r in record["data"]["rows"] if r["layout"] == "antagonist_pairs")
    row["coverage"] = 0.123
    expected = results_page.expected_files(records, texts)
    assert expected[layouts_page] != texts[layouts_page] and "| 12% |" in expected[layouts_page]
    assert "| 12% |" in expected[results_page.PAGE]


def _damaged_records(tmp_path) -> dict:
    """{case: folder of records}: the committed records with one of them damaged as ``case`` says."""
    good = (results_page.RECORDS / f"{results_page.README_RECORD}.json").read_text()
    record = json.loads(good)
    damaged = {
        "list": "[1, 2]",
        "no_name": json.dumps({k: v for k, v in record.items() if k != "name"}),
        "no_data": json.dumps({k: v for k, v in record.items() if k != "data"}),
        "data_of_another_kind": json.dumps({**record, "data": {"rows": []}}),
        "deep": "[" * 100_000 + "]" * 100_000,
        "deep_data": json.dumps({**record, "data": {}})[:-2] + '"x": ' + "[" * 100 + "]" * 100 + "}}",
        "truncated": good[:len(good) // 2],
        "empty": "",
        "latin1": good.replace('"note": "', '"note": "caf\u00e9 ', 1),
    }
    folders = {}
    for case, text in damaged.items():
        folder = tmp_path / case
        folder.mkdir()
        for path in results_page.RECORDS.glob("*.json"):
            (folder / path.name).write_text(path.read_text())
        target = folder / f"{results_page.README_RECORD}.json"
        target.write_bytes(text.encode("latin-1" if case == "latin1" else "utf-8"))
        folders[case] = folder
    return folders


def test_a_damaged_record_is_one_line_naming_it_and_exit_status_2(tmp_path, capsys):
    """A damaged record is bad input (2), never a stale page (1): CI must not take one for the other."""
    for case, folder in _damaged_records(tmp_path).items():
        status = results_page.cli(["--check", "--records", str(folder)])
        err = capsys.readouterr().err.strip().splitlines()
        assert status == results_page.BAD_INPUT and len(err) == 1, (case, status, err)
        assert err[0].startswith("results_page: error: ") and f"{results_page.README_RECORD}.json" in err[0], (case, err)
    done = subprocess.run([sys.executable, str(ROOT / "tools" / "results_page.py"), "--check", "--records",
                           str(tmp_path / "deep")], capture_output=True, text=True)
    assert done.returncode == 2 and len(done.stderr.strip().splitlines()) == 1, done.stderr[-2000:]
    assert "nested too deeply" in done.stderr


def test_a_changed_record_is_a_stale_page_exit_status_1(tmp_path, capsys):
    for path in results_page.RECORDS.glob("*.json"):
        (tmp_path / path.name).write_text(path.read_text())
    record = json.loads((tmp_path / f"{results_page.README_RECORD}.json").read_text())
    record["date"] = "1999-01-01"
    (tmp_path / f"{results_page.README_RECORD}.json").write_text(json.dumps(record))
    assert results_page.cli(["--check", "--records", str(tmp_path)]) == results_page.STALE
    assert "differs from docs/results" in capsys.readouterr().err
    assert results_page.cli(["--check", "--records", str(results_page.RECORDS)]) == 0


def test_a_file_to_add_that_is_damaged_is_named(tmp_path):
    for text in ("[1]", "{", "{" * 100_000, '{"results": 3, "seeds": [0]}'):
        bad = tmp_path / "written.json"
        bad.write_text(text)
        with pytest.raises(ValueError, match="written.json"):
            results_page.make_record("x", str(bad), "t", "c")
