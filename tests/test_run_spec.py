"""A run is described by one frozen RunSpec; a checkpoint's fingerprint of every earlier format reads
back, through the one migration, as the run that wrote it, in each of its readers: a resume, the
evaluation command and --init-from."""
import dataclasses
import pathlib

import pytest

from agents import checkpoint
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.evaluate import evaluation
from agents.robostrich.run_spec import RunSpec, migrate, parse_plan
from agents.robostrich.train import transfer
from agents.sac.config import SACConfig

DATA = pathlib.Path(__file__).parent / "data"
TINY = SACConfig(batch_size=16, hidden_sizes=(8, 8), min_replay_size=20, max_replay_size=200, her_ratio=0.5,
                 relabel_rewards=True)


@pytest.fixture(scope="module")
def written(tmp_path_factory):
    """A 60-step run's checkpoint, as this version writes it."""
    spec = RunSpec(parse_plan("lesson1:30,lesson2:30"), TINY, 4, task_kwargs={"fixed_stored_starts": 0.0})
    run = DomainRun(spec, str(tmp_path_factory.mktemp("run")))
    run.run()
    run.save_checkpoint()
    return spec, run.checkpoint_path


def _older(path, tmp_path, name, change) -> str:
    """A copy of the checkpoint at ``path`` whose fingerprint ``change(fingerprint)`` makes older."""
    out = str(tmp_path / name)
    checkpoint.save(out, checkpoint.load(path), change(checkpoint.read_fingerprint(path)))
    return out


OLDER_FORMATS = {  # name: how a fingerprint of that format differs from this version's
    "before fine inputs (2026-12-05)": lambda fp: {
        **fp, "config": {k: v for k, v in fp["config"].items() if k not in SACConfig.ADDED_FIELDS}},
    "with her_level_goals off (until 2026-12-05)": lambda fp: {
        **fp, "config": {**fp["config"], "her_level_goals": False}},
}


def test_the_spec_is_frozen_and_its_identity_is_what_the_checkpoint_holds(written):
    spec, path = written
    with pytest.raises(dataclasses.FrozenInstanceError):
        spec.seed = 5
    stored = checkpoint.read_fingerprint(path)
    assert {k: stored[k] for k in spec.identity()} == spec.identity()
    assert spec.identity()["layout"] == "ventral_slips"  # the arm's own routing, named
    assert RunSpec.from_fingerprint(stored) == spec


@pytest.mark.parametrize("name", OLDER_FORMATS)
def test_each_older_format_reads_as_the_run_that_wrote_it_in_every_reader(written, tmp_path, name):
    spec, path = written
    older = _older(path, tmp_path, "older.ckpt", OLDER_FORMATS[name])
    stored = checkpoint.read_fingerprint(older)
    assert stored != checkpoint.read_fingerprint(path)
    assert RunSpec.from_fingerprint(stored) == spec
    assert migrate(stored) == checkpoint.read_fingerprint(path)
    resumed = DomainRun(spec, str(tmp_path / "resumed"))
    resumed.restore(older)  # a resume
    assert resumed.loop.env_steps == 60
    assert evaluation.load_run_from_checkpoint(older).spec == spec  # robostrich-evaluate
    source = transfer.check_source(older, spec.plan, spec.config)  # --init-from
    assert source.fingerprint["config"] == spec.config.to_dict()


def test_a_config_written_before_fine_inputs_reads_as_none_and_no_other(written, tmp_path):
    """A stored config without fine_input_gain computed what 0 computes: a run with fine inputs is
    another run."""
    spec, path = written
    older = _older(path, tmp_path, "older.ckpt", OLDER_FORMATS["before fine inputs (2026-12-05)"])
    for changed in ({"fine_input_gain": 30.0}, {"fine_inputs": ("to_target=30",)}):
        other = dataclasses.replace(spec, config=dataclasses.replace(spec.config, **changed))
        with pytest.raises(checkpoint.CheckpointError):
            DomainRun(other, str(tmp_path / "other")).restore(older)


def test_her_level_goals_on_reads_as_the_task_option_it_became(written, tmp_path):
    spec, path = written
    on = _older(path, tmp_path, "on.ckpt", lambda fp: {**fp, "config": {**fp["config"], "her_level_goals": True}})
    became = RunSpec.from_fingerprint(checkpoint.read_fingerprint(on))
    assert became == dataclasses.replace(spec, task_kwargs={**spec.task_kwargs, "hindsight_level_goals": True})
    with pytest.raises(checkpoint.CheckpointError, match="hindsight_level_goals"):
        DomainRun(spec, str(tmp_path / "other")).restore(on)
    same = DomainRun(became, str(tmp_path / "same"))
    same.restore(on)
    assert same.loop.env.task.hindsight_level_goals and same.loop.env_steps == 60
    assert evaluation.load_run_from_checkpoint(on).spec == became
    with pytest.raises(ValueError, match="her_level_goals"):  # a config of today's has no such field
        SACConfig.from_dict({**spec.config.to_dict(), "her_level_goals": True})


@pytest.mark.parametrize("kind", ["mlp", "layer_norm"])
def test_checkpoints_of_the_earlier_learner_layout_read_as_runs(kind):
    """Written by the code before the learner's stacked critics (tests/data)."""
    spec = RunSpec.from_fingerprint(checkpoint.read_fingerprint(str(DATA / f"learner_layout_v1_{kind}.ckpt")))
    assert (spec.plan, spec.seed, spec.config.hidden_sizes) == (tuple(parse_plan("lesson1:120")), 5, (8, 8))
    assert spec.config.critic_layer_norm == (kind == "layer_norm")
