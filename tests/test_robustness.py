"""The robot differing from its model (robostrich_suite/tasks/perturbations.py), trained with and
measured by robostrich-robustness: real MuJoCo, small sizes."""
import dataclasses
import json
import os

import numpy as np
import pytest

import robostrich_suite
from agents import checkpoint
from agents.curriculum import TrainingInterrupted
from agents.robostrich import training
from agents.robostrich.runs import DomainRun, parse_plan
from robostrich_suite.tasks import perturbations
from robostrich_suite.tasks.perturbations import Perturbation
from conftest import console_script, finish, start
from test_training import TINY, assert_same_run

import results_page  # noqa: E402

# Every model field any family writes.
WRITTEN = sorted({field for fields in perturbations.FIELDS.values() for field in fields})


def _fields(env) -> dict:
    return {name: np.array(getattr(env.physics.model, name)) for name in WRITTEN}


def _env(perturbation=None, domain="robostrich", task="lesson2"):
    kwargs = {} if perturbation is None else {"perturbation": perturbation}
    return robostrich_suite.load(domain, task, task_kwargs={"random": 5, **kwargs})


def _run(env, steps=30, action=None):
    """Observations and head positions over ``steps`` control steps of a constant action."""
    timestep = env.reset()
    action = np.full(9, 0.01) if action is None else action
    rows = []
    for _ in range(steps):
        timestep = env.step(action)
        rows.append(np.concatenate([timestep.observation["joint_angles"], env.physics.head_position()]))
    return np.array(rows)


def test_scale_zero_leaves_the_model_and_the_rollout_byte_identical():
    nominal, zero = _env(), _env(Perturbation())
    assert zero.task.randomizer is None
    a, b = _run(nominal), _run(zero)
    assert a.tobytes() == b.tobytes()
    assert nominal.physics.model.ptr is not zero.physics.model.ptr
    for name, value in _fields(nominal).items():
        assert value.tobytes() == getattr(zero.physics.model, name).tobytes(), name


@pytest.mark.parametrize("family", perturbations.ARM_FAMILIES)
def test_each_family_changes_exactly_its_fields_and_restores_them(family):
    env = _env()
    reference = {name: value.copy() for name, value in _fields(env).items()}
    env.reset()
    everything = {name: np.array(getattr(env.physics.model.ptr, name)) for name in dir(env.physics.model.ptr)
                  if isinstance(getattr(env.physics.model.ptr, name), np.ndarray)}
    perturber = perturbations.Perturber(Perturbation.of(family, 0.3))
    perturber.apply(env.physics, np.random.RandomState(0))
    changed = {name for name, value in everything.items()
               if np.array(getattr(env.physics.model.ptr, name)).tobytes() != value.tobytes()}
    assert changed == set(perturbations.FIELDS[family])
    perturber.restore(env.physics)
    for name, value in reference.items():
        assert value.tobytes() == getattr(env.physics.model, name).tobytes(), name


def test_joint_noise_changes_only_the_observed_angles():
    clean, noisy = _env(), _env(Perturbation(joint_noise=0.5))
    a, b = _run(clean, 5), _run(noisy, 5)
    np.testing.assert_array_equal(a[:, -3:], b[:, -3:])  # the head moves exactly as on the nominal robot
    spread = np.std(b[:, :-3] - a[:, :-3])
    assert 0.5 * perturbations.JOINT_NOISE_AT_1 * 0.5 < spread < 0.5 * perturbations.JOINT_NOISE_AT_1 * 2


@pytest.mark.parametrize("scale,steps", [(0.1, 1), (0.3, 2), (0.5, 3)])
def test_latency_delays_every_action_by_exactly_its_steps(scale, steps):
    assert perturbations.latency_steps(scale) == steps
    nominal, late = _env(), _env(Perturbation(latency=scale))
    actions = np.random.RandomState(1).uniform(-0.01, 0.004, size=(12, 9))
    for env in (nominal, late):
        env.reset()
    controls = {id(env): [] for env in (nominal, late)}
    for action in actions:
        for env in (nominal, late):
            env.step(action)
            controls[id(env)].append(env.physics.arm_control().copy())
    sent, arrived = np.array(controls[id(nominal)]), np.array(controls[id(late)])
    np.testing.assert_array_equal(arrived[steps:], sent[:-steps])
    np.testing.assert_array_equal(arrived[:steps], 0.0)  # the input held when the episode began


def test_the_quadruped_families_move_the_trunk_and_the_gait_clock():
    standing = _env(domain="robostrich_a1")
    higher = _env(Perturbation(trunk_height=0.5), domain="robostrich_a1")
    standing.reset(), higher.reset()
    offset = higher.task.randomizer.trunk_height_offset
    assert 0 < abs(offset) <= 0.5 * perturbations.TRUNK_HEIGHT_AT_1
    assert abs(higher.physics.trunk_height() - standing.physics.trunk_height() - offset) < 0.01
    walking = _env(Perturbation(gait_timing=0.5), domain="robostrich_a1", task="lesson4")
    walking.reset()
    assert walking.task.randomizer.gait_rate != 1.0 and walking.task.randomizer.gait_phase > 0


def test_a_bad_scale_names_the_family():
    with pytest.raises(ValueError, match="mass"):
        _env({"mass": 1.5})
    with pytest.raises(TypeError, match="perturbation"):
        _env({"mas": 0.1})


def test_randomised_training_runs_and_resumes_bit_for_bit(tmp_path):
    """Every arm family at once, a checkpoint mid-episode (delayed actions pending), restored."""
    task_kwargs = {"perturbation": {family: 0.3 for family in perturbations.ARM_FAMILIES}}
    plan = parse_plan("robostrich/lesson3:320")
    config = dataclasses.replace(TINY, min_replay_size=100)
    a = DomainRun(plan, config, seed=2, run_dir=str(tmp_path / "a"), checkpoint_every=10_000, task_kwargs=task_kwargs)
    with pytest.raises(TrainingInterrupted):
        a.run(stop_at_step=270)  # early in the second episode
    assert a.loop.env.task.randomizer._pending  # actions in flight are part of the checkpoint
    path = str(tmp_path / "run.ckpt")
    a.save_checkpoint(path)
    b = DomainRun(plan, config, seed=2, run_dir=str(tmp_path / "b"), checkpoint_every=10_000, task_kwargs=task_kwargs)
    b.restore(path)
    assert_same_run(a, b)
    with pytest.raises(TrainingInterrupted):
        a.run(stop_at_step=310)
    with pytest.raises(TrainingInterrupted):
        b.run(stop_at_step=310)
    assert_same_run(a, b)


def test_robostrich_train_takes_the_perturbation_as_a_task_option(tmp_path):
    """--task-kwargs carries it into every lesson's task and the checkpoint's fingerprint (and so
    through robostrich-sweep, which passes training flags on); a bad scale is refused first."""
    perturbation = {"latency": 0.2, "mass": 0.2}
    args = ["--plan", "robostrich/lesson2:300", "--hidden-sizes", "32,32", "--batch-size", "32",
            "--min-replay-size", "100", "--updates-per-call", "4", "--env-steps-per-call", "8",
            "--checkpoint-every", "100", "--no-figures", "--no-rerun", "--quiet", "--no-baseline"]
    with pytest.raises(TrainingInterrupted):
        training.main(args + ["--task-kwargs", json.dumps({"perturbation": perturbation}),
                              "--out", str(tmp_path / "run"), "--stop-at-step", "120"])
    fingerprint = checkpoint.read_fingerprint(str(tmp_path / "run" / "curriculum" / "checkpoint.ckpt"))
    assert fingerprint["task_kwargs"]["perturbation"] == perturbation
    with pytest.raises(ValueError, match="mass"):
        training.main(args + ["--task-kwargs", '{"perturbation": {"mass": 2}}', "--out", str(tmp_path / "bad")])


def test_the_command_writes_its_figure_json_and_a_results_record(tmp_path):
    script = console_script("robostrich-robustness")
    out = tmp_path / "out"
    process = start(script, "robostrich", "--num-targets", "2", "--scales", "0,0.3", "--out", str(out),
                    "--no-lookup")
    result = finish(process)
    assert result.returncode == 0, result.stderr
    report = json.loads((out / "robustness.json").read_text())
    assert (out / "robustness.png").stat().st_size > 10_000
    assert report["labels"] == ["policy"] and report["num_targets"] == 2
    assert "robustness: 100%" in result.stderr  # the progress bar
    assert set(report["results"]["policy"]) == set(perturbations.ARM_FAMILIES) | {"all"}
    for rows in report["results"]["policy"].values():
        assert [r["scale"] for r in rows] == [0.0, 0.3]
        assert rows[0] == report["results"]["policy"]["mass"][0]  # scale 0: the one nominal robot
        assert rows[1]["heldout"]["episodes"] == 2 and rows[1]["heldout_moving"]["episodes"] == 6
    record = results_page.make_record("robustness_test", str(out / "robustness.json"), "Robustness")
    assert record["kind"] == "robustness" and record["command"].startswith("robostrich-robustness robostrich")
    section = results_page.render_record(record)
    assert "| latency |" in section and "policy: family" in section and "s = 0.3" in section


@pytest.mark.parametrize("argv,message", [
    (["robostrich", "--scales", "0,2"], "--scales"),
    (["robostrich", "--scales", "a"], "--scales"),
    (["nosuch"], "unknown policy"),
    (["missing/checkpoint.ckpt"], "no checkpoint"),
    (["robostrich", "--num-targets", "0"], "--num-targets"),
])
def test_bad_input_is_one_line_and_exit_status_2(argv, message, tmp_path, capsys):
    from agents.robostrich import robustness
    try:
        status = robustness.cli(argv + ["--out", str(tmp_path / "out")])
    except SystemExit as stop:  # argparse's own exit, as the console script ends
        status = stop.code
    assert status == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("robostrich-robustness: error:") and message in err
    assert not (tmp_path / "out").exists()


def test_a_robustness_file_without_results_is_refused_naming_it(tmp_path):
    path = tmp_path / "robustness.json"
    path.write_text(json.dumps({"benchmark": "robustness", "scales": [0.0]}))
    with pytest.raises(ValueError, match=str(path)):
        results_page.make_record("robustness_bad", str(path), "Robustness")
