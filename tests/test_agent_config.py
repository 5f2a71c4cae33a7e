"""The agent's settings: SACConfig() is plain SAC as Acme has it, and robostrich-train's main job
keeps its measured values in one place. (Checkpoints written with earlier settings fields:
tests/test_run_spec.py.)"""
import dataclasses

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
