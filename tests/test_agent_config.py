"""The agent's settings: SACConfig() is plain SAC as Acme has it, robostrich-train's main job keeps
its measured values in one place, and checkpoints written while SACConfig held the arm's
her_level_goals still resume and evaluate."""
import dataclasses

import pytest

from agents import checkpoint
from agents.curriculum import LessonSettings
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, migrate, parse_plan
from agents.robostrich.evaluate import evaluation
from agents.robostrich.train import command, main_job
from agents.sac.config import SACConfig

# The main job's agent as measured (docs/training.md#the-main-job); SACConfig's defaults until
# 2026-12-05. A change here is a change of the main job, to be measured and logged.
MAIN_JOB_VALUES = {
    "batch_size": 64, "learning_rate": 1e-3, "discount": 0.99, "tau": 0.005, "target_entropy": None,
    "target_entropy_per_action": -2.0, "init_temperature": 0.01, "hidden_sizes": [64, 64],
    "min_replay_size": 1_000, "max_replay_size": 1_000_000, "updates_per_call": 4, "env_steps_per_call": 4,
    "action_repeat": 1, "reward_scale": 1.0, "log_std_min": -5.0, "log_std_max": 2.0, "critic_layer_norm": True,
    "her_ratio": 0.5, "relabel_rewards": True, "action_anchor": 0.0, "pre_tanh_penalty": 0.1,
    "policy_average": 1e-4, "policy_average_fraction": 0.1, "fine_input_gain": 0.0, "fine_inputs": []}


def test_the_main_job_keeps_its_measured_settings_whatever_sacconfig_defaults_to():
    assert main_job.MAIN_JOB_SAC.to_dict() == MAIN_JOB_VALUES
    for domain in ("robostrich_a1", "reacher"):  # robostrich-train's flags default to them
        args = command.build_parser().parse_args(["--domain", domain])
        assert main_job.config_from_args(args, ["--domain", domain]) == main_job.MAIN_JOB_SAC
    # on the frame arm, with fine inputs of its two errors; `none` turns them off
    arm = main_job.config_from_args(command.build_parser().parse_args([]), [])
    assert arm == dataclasses.replace(main_job.MAIN_JOB_SAC, learning_rate=2e-3,
                                      fine_inputs=("to_target=100", "attitude_error=30"))
    flags = ["--fine-inputs", "none", "--learning-rate", "1e-3"]
    assert main_job.config_from_args(command.build_parser().parse_args(flags), flags) == main_job.MAIN_JOB_SAC


def test_sacconfig_defaults_to_acmes_sac_with_every_addition_off():
    config = SACConfig()
    assert (config.batch_size, config.learning_rate, config.discount, config.tau) == (256, 3e-4, 0.99, 0.005)
    assert config.hidden_sizes == (256, 256) and config.init_temperature == 1.0
    assert (config.min_replay_size, config.max_replay_size) == (10_000, 1_000_000)
    assert config.resolved_target_entropy(9) == -9.0 and config.update_to_data_ratio == 1.0
    assert not (config.critic_layer_norm or config.her_ratio or config.relabel_rewards or config.action_anchor
                or config.pre_tanh_penalty or config.policy_average or config.uses_goals)
    assert SACConfig.paper_sac() == dataclasses.replace(config, updates_per_call=8, env_steps_per_call=8)
    assert "her_level_goals" not in SACConfig.HELP  # the task says which goals hindsight may use


def _rewritten(path, tmp_path, name, **config):
    """A copy of the checkpoint at ``path`` whose fingerprint's config holds ``config`` besides."""
    record = checkpoint.read_fingerprint(path)
    out = str(tmp_path / name)
    checkpoint.save(out, checkpoint.load(path, None), {**record, "config": {**record["config"], **config}})
    return out


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    tiny = dataclasses.replace(main_job.MAIN_JOB_SAC, hidden_sizes=(16, 16), batch_size=16)  # 80 steps: no update
    plan = parse_plan("robostrich/lesson1:40,robostrich/lesson2:40")
    run = DomainRun(RunSpec(plan, tiny, 0), str(tmp_path_factory.mktemp("run")), checkpoint_every=10 ** 6)
    run.run()
    run.save_checkpoint()
    return plan, tiny, run


def test_checkpoints_written_before_a_field_was_added_resume_and_evaluate(trained, tmp_path):
    """A stored config without fine_input_gain computed what 0 computes: it resumes as that."""
    plan, tiny, run = trained
    record = checkpoint.read_fingerprint(run.checkpoint_path)
    older = str(tmp_path / "older.ckpt")
    config = {k: v for k, v in record["config"].items() if k not in SACConfig.ADDED_FIELDS}
    checkpoint.save(older, checkpoint.load(run.checkpoint_path, None), {**record, "config": config})
    fresh = DomainRun(RunSpec(plan, tiny, 0), str(tmp_path / "a"))
    fresh.restore(older)
    assert fresh.loop.env_steps == 80 and evaluation.load_run_from_checkpoint(older).loop.env_steps == 80
    for changed in ({"fine_input_gain": 30.0}, {"fine_inputs": ("to_target=30",)}):
        with pytest.raises(checkpoint.CheckpointError):
            DomainRun(RunSpec(plan, dataclasses.replace(tiny, **changed), 0), str(tmp_path / "b")).restore(older)


def test_checkpoints_holding_her_level_goals_resume_and_evaluate(trained, tmp_path):
    """Off, the field is dropped; on, it reads as the reaching tasks' option it became, so the run
    that set the option resumes from it and one without the option is refused."""
    plan, tiny, run = trained
    off = _rewritten(run.checkpoint_path, tmp_path, "off.ckpt", her_level_goals=False)
    fresh = DomainRun(RunSpec(plan, tiny, 0), str(tmp_path / "a"))
    fresh.restore(off)
    assert fresh.loop.env_steps == 80
    assert evaluation.load_run_from_checkpoint(off).loop.env_steps == 80
    on = _rewritten(run.checkpoint_path, tmp_path, "on.ckpt", her_level_goals=True)
    assert migrate(checkpoint.read_fingerprint(on))["task_kwargs"] == {"hindsight_level_goals": True}
    with pytest.raises(checkpoint.CheckpointError, match="hindsight_level_goals"):
        DomainRun(RunSpec(plan, tiny, 0), str(tmp_path / "b")).restore(on)
    level = DomainRun(RunSpec(plan, tiny, 0, task_kwargs={"hindsight_level_goals": True}), str(tmp_path / "c"))
    level.restore(on)
    assert level.loop.env.task.hindsight_level_goals and evaluation.load_run_from_checkpoint(on).loop.env_steps == 80
    with pytest.raises(ValueError, match="her_level_goals"):
        SACConfig.from_dict({**tiny.to_dict(), "her_level_goals": True})
    assert LessonSettings.from_dict(checkpoint.read_fingerprint(on)["lessons"]) == run.lessons
