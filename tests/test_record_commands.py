"""Every learning record in docs/results/ stays reproducible by its command: the flags it names still
exist and pass robostrich-train's own checks, and a record of an earlier main job resolves to the
settings of its day, not to today's defaults."""
import dataclasses
import json
import pathlib
import shlex
import sys

import pytest

from agents.robostrich.sweep import command as sweep
from agents.robostrich.train import command as training
from agents.robostrich.train import main_job

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))

import benchmark_peers  # noqa: E402

RECORDS = {path.stem: json.loads(path.read_text()) for path in sorted((ROOT / "docs" / "results").glob("*.json"))}
SEED_RECORDS = [name for name, r in RECORDS.items() if r["command"].startswith("python tools/benchmark_seeds.py")]
PEER_RECORDS = [name for name, r in RECORDS.items() if r["command"].startswith("python tools/benchmark_peers.py")]


def _arguments(name: str) -> list:
    return shlex.split(RECORDS[name]["command"])[2:]


def _resolved(train_argv: list):
    """(SACConfig, lesson plan) that robostrich-train resolves from ``train_argv``."""
    args = training.build_parser().parse_args(train_argv)
    return main_job.config_from_args(args, train_argv), main_job.plan_from_args(args)


def test_the_records_name_the_main_job_and_the_peers():
    assert {"main_job", "main_job_list_targets", "main_job_600k", "main_job_plain_inputs",
            "quadruped_main_job"} <= set(SEED_RECORDS)
    assert {"peers", "peers_100k"} <= set(PEER_RECORDS)


@pytest.mark.parametrize("name", SEED_RECORDS)
def test_every_seed_record_command_passes_the_sweeps_checks(name):
    args, passthrough = sweep.build_parser().parse_known_args(_arguments(name))
    groups, runs = sweep.plan(args, passthrough)  # robostrich-train's parser and input checks, per group
    assert len(groups) == 1 and len(runs) == len(RECORDS[name]["data"]["seeds"])


@pytest.mark.parametrize("name", PEER_RECORDS)
def test_every_peer_record_command_passes_its_checks(name, tmp_path):
    args = benchmark_peers.build_parser().parse_args([*_arguments(name), "--out", str(tmp_path)])
    settings = benchmark_peers.settings_from(args)  # the tool's own checks, --ours-args by robostrich-train's
    assert settings.steps == RECORDS[name]["data"]["steps"]


def test_the_earlier_main_jobs_resolve_to_their_own_settings_not_todays():
    """Each record's flags give the budget and the settings it trained with."""
    today, today_plan = _resolved([])
    assert sum(lesson.steps for lesson in today_plan) == main_job.MAIN_JOB_STEPS["robostrich"]
    for name, fine in (("main_job_600k", {"fine_input_gain": 100.0}), ("main_job_plain_inputs", {})):
        _, passthrough = sweep.build_parser().parse_known_args(_arguments(name))
        config, plan = _resolved(passthrough)
        assert sum(lesson.steps for lesson in plan) == 600_000, name
        assert config == dataclasses.replace(main_job.MAIN_JOB_SAC, **fine), name
        assert config != today


LIST_TARGET_RECORDS = ("antagonist_pairs", "main_job_list_targets", "main_job_600k", "main_job_plain_inputs")  # before 2026-12-07


def test_records_made_before_targets_between_the_stored_poses_train_on_the_list(tmp_path):
    """The main job trains on targets between the stored poses since 2026-12-07; the records made
    before keep their list of targets by their commands' flag, for ours and the peers alike."""
    from agents.robostrich.domains import Domain
    assert main_job.resolve_task_kwargs({}, Domain("robostrich"))["target_between"] == 4
    _, passthrough = sweep.build_parser().parse_known_args(_arguments("main_job"))  # today's main job
    args = training.build_parser().parse_args(passthrough)
    assert main_job.resolve_task_kwargs(args.task_kwargs, Domain("robostrich"))["target_between"] == 4
    assert "target_between" not in main_job.resolve_task_kwargs({}, Domain("robostrich_a1"))
    for name in LIST_TARGET_RECORDS:
        _, passthrough = sweep.build_parser().parse_known_args(_arguments(name))
        args = training.build_parser().parse_args(passthrough)
        assert main_job.resolve_task_kwargs(args.task_kwargs, Domain("robostrich"))["target_between"] == 0, name
    for name in PEER_RECORDS:
        args = benchmark_peers.build_parser().parse_args([*_arguments(name), "--out", str(tmp_path)])
        settings = benchmark_peers.settings_from(args)
        assert settings.task_kwargs == {"target_between": 0}, name
