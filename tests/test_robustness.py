"""The robot differing from its model (robostrich_suite/tasks/perturbations.py), trained with and
measured by robostrich-robustness: real MuJoCo, small sizes."""
import dataclasses
import json

import numpy as np
import pytest

import robostrich_suite
from robostrich_suite import policies
from agents import checkpoint
from agents.robostrich.train import command as training
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, parse_plan
from robostrich_suite.tasks import perturbations
from robostrich_suite.tasks.perturbations import Perturbation
from conftest import console_script, finish, start
from test_training import TINY, Killed, assert_same_run, killed_after

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


def test_the_observed_sent_actions_are_those_on_their_way_to_the_servos():
    """With ``vary`` each fresh episode draws 0-3 steps of latency; the observation holds the last 3
    actions sent (clipped, newest first), and the servos hold the one sent ``latency`` steps ago."""
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs={
        "random": 3, "observe_sent_actions": 3, "perturbation": {"latency": 0.5, "vary": True}})
    low, high = env.action_spec().minimum, env.action_spec().maximum
    drawn = set()
    for episode in range(16):
        timestep = env.reset()
        held = env.physics.arm_control().copy()
        np.testing.assert_array_equal(timestep.observation["sent_actions"], np.tile(held, 3))
        latency = env.task.randomizer._latency
        drawn.add(latency)
        sent = [np.random.RandomState(episode * 10 + i).uniform(low - 0.01, high) for i in range(5)]
        for action in sent:
            timestep = env.step(action)
        clipped = np.clip(sent, low, high)
        np.testing.assert_array_equal(timestep.observation["sent_actions"].reshape(3, 9), clipped[::-1][:3])
        np.testing.assert_array_equal(env.physics.arm_control(), clipped[-1 - latency])
    assert drawn == {0, 1, 2, 3}
    assert "sent_actions" not in _env().reset().observation  # the default observation is unchanged


def test_vary_draws_each_familys_scale_up_to_its_own():
    env = _env(Perturbation(mass=0.4, joint_noise=0.4, vary=True))
    scales = []
    for _ in range(30):
        env.reset()
        drawn = env.task.randomizer.apply(env.physics, env.task.random)
        scales.append([drawn["scale"]["mass"], drawn["scale"]["joint_noise"]])
        assert np.all(np.abs(drawn["mass"] - 1) <= drawn["scale"]["mass"])
    scales = np.array(scales)
    assert scales.min() >= 0 and scales.max() <= 0.4 and scales.std(axis=0).min() > 0.05
    assert abs(np.corrcoef(scales.T)[0, 1]) < 0.6  # each family from its own stream


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


def test_on_the_quadruped_the_gaits_timing_is_judged_while_it_walks():
    """Standing, the gait's clock changes nothing the arm feels; the walking evaluation (lesson 4,
    the quadruped trotting) is where gait_timing shows, so robostrich-robustness judges it there too."""
    from agents.robostrich.robustness import command as robustness
    evaluated = robustness.load_evaluated("robostrich_a1", "policy")
    nominal, late = (robustness.evaluate(evaluated, perturbation, num_targets=1)
                     for perturbation in (Perturbation(), Perturbation(gait_timing=0.5)))
    assert set(nominal) == {"heldout", "heldout_moving", "walking"} and nominal["walking"]["episodes"] == 1
    assert late["heldout"] == nominal["heldout"] and late["heldout_moving"] == nominal["heldout_moving"]
    assert late["walking"]["position_error_median"] != nominal["walking"]["position_error_median"]
    assert "walking" not in robustness.evaluate(robustness.load_evaluated("robostrich", "policy"), Perturbation(), 1)


def test_a_bad_scale_names_the_family():
    with pytest.raises(ValueError, match="mass"):
        _env({"mass": 1.5})
    with pytest.raises(TypeError, match="perturbation"):
        _env({"mas": 0.1})


def test_randomised_training_runs_and_resumes_bit_for_bit(tmp_path):
    """Every arm family at once, drawn per episode, a checkpoint mid-episode (delayed actions
    pending, the sent ones observed), restored."""
    task_kwargs = {"perturbation": {**{family: 0.3 for family in perturbations.ARM_FAMILIES}, "latency": 0.5,
                                    "vary": True}, "observe_sent_actions": 3}
    plan = parse_plan("robostrich/lesson3:320")
    config = dataclasses.replace(TINY, min_replay_size=100)
    a = DomainRun(RunSpec(plan, config, 2, task_kwargs=task_kwargs), str(tmp_path / "a"), checkpoint_every=10_000)
    a.run(until_step=270)  # early in the second episode
    assert a.loop.env.task.randomizer._pending  # actions in flight are part of the checkpoint
    path = str(tmp_path / "run.ckpt")
    a.save_checkpoint(path)
    b = DomainRun(RunSpec(plan, config, 2, task_kwargs=task_kwargs), str(tmp_path / "b"), checkpoint_every=10_000)
    b.restore(path)
    assert_same_run(a, b)
    a.run(until_step=310)
    b.run(until_step=310)
    assert_same_run(a, b)


def test_robostrich_train_randomizes_and_its_policy_carries_what_it_observes(tmp_path):
    """--randomize puts the per-episode robot (and, with latency, the sent actions observed) into
    every lesson's task and the checkpoint's fingerprint (and so through robostrich-sweep, which
    passes training flags on); evaluation, the policy file and the robustness tool rebuild the
    observation from it; bad scales and families are refused first."""
    from agents.robostrich.evaluate import evaluation
    from agents.robostrich.robustness import command as robustness
    from agents.robostrich.evaluate.policy_export import export_policy
    args = ["--plan", "robostrich/lesson2:300", "--hidden-sizes", "32,32", "--batch-size", "32",
            "--min-replay-size", "100", "--updates-per-call", "4", "--env-steps-per-call", "8",
            "--checkpoint-every", "100", "--no-figures", "--no-rerun", "--quiet", "--no-baseline"]
    with pytest.raises(Killed), killed_after(120):
        training.main(args + ["--randomize", "all=0.2,latency=0.5", "--out", str(tmp_path / "run")])
    path = str(tmp_path / "run" / "curriculum" / "checkpoint.ckpt")
    fingerprint = checkpoint.read_fingerprint(path)
    assert fingerprint["task_kwargs"]["perturbation"] == {
        **{family: 0.2 for family in perturbations.ARM_FAMILIES}, "latency": 0.5, "vary": True}
    assert fingerprint["task_kwargs"]["observe_sent_actions"] == perturbations.MAX_LATENCY_STEPS
    assert evaluation.checkpoint_domain(fingerprint).sent_actions == 3
    policy = export_policy(path, str(tmp_path / "policy.npz"))
    assert policy.task_kwargs() == {"observe_sent_actions": 3}
    with pytest.raises(policies.PolicyMismatch, match="observe_sent_actions"):
        policy.check(robostrich_suite.load("robostrich", "track"))
    evaluated = robustness.load_evaluated(str(tmp_path / "policy.npz"), "robust")
    row = robustness.evaluate(evaluated, Perturbation(latency=0.1), num_targets=1)
    assert row["heldout"]["episodes"] == 1 and row["heldout_moving"]["episodes"] == 3
    for flags, message in ((["--randomize", "trunk_height=0.1"], "trunk_height do not apply"),
                           (["--task-kwargs", '{"perturbation": {"mass": 2}}'], "mass"),
                           (["--randomize", "mass=0.1", "--task-kwargs", '{"perturbation": {"mass": 0.1}}'],
                            "give one")):
        with pytest.raises(ValueError, match=message):
            training.main(args + flags + ["--out", str(tmp_path / "bad")])
    for text, message in (("mass=2", "mass must be a scale from 0 to 1"), ("mas=0.1", "'mas=0.1'"),
                          ("latency", "FAMILY=SCALE"), ("mass=x", "mass: expected a scale")):
        with pytest.raises(ValueError, match=message):
            perturbations.parse_scales(text)


def test_the_command_writes_its_figure_json_and_a_results_record(tmp_path):
    script = console_script("robostrich-robustness")
    out = tmp_path / "out"
    # the policy trained with latency observes its sent actions, the nominal one and the lookup do not:
    # each meets the same robots with its own observation
    process = start(script, "robostrich_robust", "--compare", "robostrich", "--num-targets", "2", "--scales", "0,0.3",
                    "--out", str(out))
    result = finish(process)
    assert result.returncode == 0, result.stderr
    report = json.loads((out / "robustness.json").read_text())
    assert (out / "robustness.png").stat().st_size > 10_000
    assert report["labels"] == ["policy", "compare", "lookup"] and report["num_targets"] == 2
    assert "robustness: 100%" in result.stderr  # the progress bar
    assert set(report["results"]["policy"]) == set(perturbations.ARM_FAMILIES) | {"all"}
    for rows in report["results"]["policy"].values():
        assert [r["scale"] for r in rows] == [0.0, 0.3]
        assert rows[0] == report["results"]["policy"]["mass"][0]  # scale 0: the one nominal robot
        assert rows[1]["heldout"]["episodes"] == 2 and rows[1]["heldout_moving"]["episodes"] == 6
    # what it prints agrees with its JSON for every policy, family and start: a fall below 90 % anywhere is said
    printed = result.stdout.splitlines()
    for label, families in report["results"].items():
        block = printed[printed.index(next(l for l in printed if l.startswith(f"{label}: "))):]
        for family, rows in families.items():
            line = next(l for l in block if l.split()[:1] == [family])
            for kind, words in (("heldout", "fixed start: "), ("heldout_moving", "moving starts: ")):
                below = [r["scale"] for r in rows if r[kind]["success_rate"] < 0.9]
                said = line.split(words, 1)[1].split(";")[0]
                assert said.startswith(f"below 90 % at s = {below[0]}") if below else said.startswith("above 90 %"), \
                    (label, family, kind, line)
    record = results_page.make_record("robustness_test", str(out / "robustness.json"), "Robustness")
    assert record["kind"] == "robustness" and record["command"].startswith("robostrich-robustness robostrich_robust")
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
    from agents.robostrich.robustness import command as robustness
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
