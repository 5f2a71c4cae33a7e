"""Checkpoints, resumption and the curriculum, on dm_control's point_mass (real MuJoCo, tiny networks)."""
import contextlib
import dataclasses
import json
import os

import jax
import numpy as np
import pytest

from agents import checkpoint
from agents.robostrich.train import main_job
from agents.robostrich.train import command as training
from agents.robostrich.train import progress as training_progress
from agents.curriculum import LessonSettings, format_plan
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import DEFAULT_LESSONS, RunSpec, parse_plan
from agents.sac.config import SACConfig

# The main job's agent (its flags' defaults), small.
TINY = dataclasses.replace(main_job.MAIN_JOB_SAC, batch_size=32, hidden_sizes=(32, 32), min_replay_size=200,
                           max_replay_size=5000, updates_per_call=4, env_steps_per_call=8)
TINY_ARGS = ["--domain", "point_mass", "--hidden-sizes", "32,32", "--batch-size", "32", "--min-replay-size", "200",
             "--max-replay-size", "5000", "--updates-per-call", "4", "--env-steps-per-call", "8",
             "--num-eval-targets", "1", "--no-figures", "--no-rerun", "--quiet", "--no-baseline"]


def leaves(tree):
    """The arrays of a parameter tree; never none, so comparing two trees leaf by leaf cannot pass vacuously."""
    arrays = [np.asarray(x) for x in jax.tree_util.tree_leaves(tree)]
    assert arrays, "an empty tree"
    return arrays


def assert_same_run(a: DomainRun, b: DomainRun):
    for x, y in zip(leaves(a.loop.learner.state), leaves(b.loop.learner.state), strict=True):
        np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(np.asarray(a.loop.actor.key), np.asarray(b.loop.actor.key))
    assert a.loop.env_steps == b.loop.env_steps and a.loop.episodes == b.loop.episodes
    assert (a.lesson_index, a.lesson_steps) == (b.lesson_index, b.lesson_steps)
    assert len(a.loop.replay) == len(b.loop.replay)
    n = len(a.loop.replay)
    np.testing.assert_array_equal(a.loop.replay.obs[:n], b.loop.replay.obs[:n])
    np.testing.assert_array_equal(a.loop.env.physics.get_state(), b.loop.env.physics.get_state())


class Killed(Exception):
    """The process died: nothing is checkpointed on the way out."""


@contextlib.contextmanager
def killed_after(step: int):
    """robostrich-train (one process) dies once a run has reached ``step`` control steps: the
    progress bar, told after every chunk of steps, raises (chunks end at checkpoints and evaluations)."""
    original = training_progress.Progress.update

    def update(self, n, run):
        original(self, n, run)
        if run.loop.env_steps >= step:
            raise Killed(f"at step {run.loop.env_steps}")
    training_progress.Progress.update = update
    try:
        yield
    finally:
        training_progress.Progress.update = original


def test_checkpoint_round_trips_bit_exactly_and_continues_identically(tmp_path):
    plan = parse_plan("point_mass/easy:700")
    a = DomainRun(RunSpec(plan, TINY, 1), str(tmp_path / "a"), checkpoint_every=10_000)
    a.run(until_step=450)  # mid-episode, after learning started
    assert a.loop.learner.num_updates > 0
    path = str(tmp_path / "run.ckpt")
    a.save_checkpoint(path)
    b = DomainRun(RunSpec(plan, TINY, 1), str(tmp_path / "b"), checkpoint_every=10_000)
    b.restore(path)
    assert_same_run(a, b)
    a.run()
    b.run()
    assert_same_run(a, b)


def test_killed_and_resumed_run_matches_an_uninterrupted_one(tmp_path):
    args = TINY_ARGS + ["--plan", "point_mass/easy:600,point_mass/hard:600", "--checkpoint-every", "400",
                        "--seed", "3", "--action-repeat", "2"]
    whole, killed = str(tmp_path / "whole"), str(tmp_path / "killed")
    training.main(args + ["--out", whole])
    with pytest.raises(Killed), killed_after(1000):  # last checkpoint at 800
        training.main(args + ["--out", killed])
    with pytest.raises(ValueError, match="--resume"):
        training.main(args + ["--out", killed])  # never silently restarts over a checkpoint
    training.main(args + ["--out", killed, "--resume"])
    fp = checkpoint.read_fingerprint(os.path.join(whole, "curriculum", "checkpoint.ckpt"))
    a, b = (checkpoint.load(os.path.join(d, "curriculum", "checkpoint.ckpt"), fp) for d in (whole, killed))
    assert a["loop"]["env_steps"] == b["loop"]["env_steps"] == 1200
    assert a["loop"]["transitions"] == b["loop"]["transitions"] == 600  # action repeat 2
    assert (a["lesson_index"], a["lesson_steps"]) == (b["lesson_index"], b["lesson_steps"]) == (2, 0)
    assert int(a["learner"][".steps"]) == int(b["learner"][".steps"]) > 0
    for x, y in zip(leaves(a["learner"]), leaves(b["learner"]), strict=True):
        np.testing.assert_array_equal(x, y)
    for name in ("metrics.jsonl", "evals.jsonl"):  # no duplicated records after the resume
        ra, rb = (open(os.path.join(d, "curriculum", name)).read().splitlines() for d in (whole, killed))
        assert [json.loads(l)["env_steps"] for l in ra] == [json.loads(l)["env_steps"] for l in rb]


def test_mismatched_or_damaged_checkpoint_raises(tmp_path):
    plan = parse_plan("point_mass/easy:300")
    a = DomainRun(RunSpec(plan, TINY, 0), str(tmp_path / "a"), checkpoint_every=300)
    a.run()
    other = SACConfig(**{**TINY.to_dict(), "batch_size": 64, "hidden_sizes": (32, 32)})
    b = DomainRun(RunSpec(plan, other, 0), str(tmp_path / "b"))
    with pytest.raises(ValueError, match="batch_size: checkpoint has 32, this run has 64"):
        b.restore(a.checkpoint_path)
    c = DomainRun(RunSpec(plan, TINY, 5), str(tmp_path / "c"))
    with pytest.raises(ValueError, match="seed"):
        c.restore(a.checkpoint_path)
    data = bytearray(open(a.checkpoint_path, "rb").read())
    data[len(data) // 2] ^= 0xFF
    damaged = str(tmp_path / "damaged.ckpt")
    open(damaged, "wb").write(bytes(data))
    d = DomainRun(RunSpec(plan, TINY, 0), str(tmp_path / "d"))
    with pytest.raises(ValueError, match="damaged"):
        d.restore(damaged)
    open(damaged, "wb").write(bytes(data[:20]))
    with pytest.raises(ValueError, match="truncated"):
        d.restore(damaged)


def test_checkpoint_whose_fingerprint_lacks_a_field_is_refused_naming_it(tmp_path):
    """A fingerprint without a config field (written before the field existed) is refused naming
    the field, not filled in; the run's own checkpoint restores."""
    plan = parse_plan("point_mass/easy:300")
    run = DomainRun(RunSpec(plan, TINY, 0), str(tmp_path / "a"), checkpoint_every=300)
    run.run()
    payload = checkpoint.load(run.checkpoint_path)
    lacking = run.fingerprint()
    lacking["config"] = {k: v for k, v in lacking["config"].items() if k != "her_ratio"}
    checkpoint.save(str(tmp_path / "lacking.ckpt"), payload, lacking)
    with pytest.raises(ValueError, match=r"her_ratio: checkpoint has '<missing>'"):
        DomainRun(RunSpec(plan, TINY, 0), str(tmp_path / "c")).restore(str(tmp_path / "lacking.ckpt"))
    DomainRun(RunSpec(plan, TINY, 0), str(tmp_path / "d")).restore(run.checkpoint_path)  # its own: fine


def test_curriculum_carries_replay_and_parameters_across_lessons(tmp_path):
    plan = parse_plan("point_mass/easy:500,point_mass/hard:500")
    run = DomainRun(RunSpec(plan, TINY, 2), str(tmp_path), checkpoint_every=10_000)
    seen = {}

    def on_eval(r):  # called right after the switch to lesson 2
        seen["policy"] = leaves(r.loop.learner.state.policy_params)
        seen["updates"] = r.loop.learner.num_updates
        seen["replay"] = len(r.loop.replay)
        seen["env"] = r.loop.env
        seen["learner"] = r.loop.learner

    initial = leaves(run.loop.learner.state.policy_params)
    first_env = run.loop.env
    run.run(on_eval=on_eval, eval_at=[500])
    assert seen["env"] is not first_env and run.lesson_index == 2
    assert seen["replay"] == 500 and len(run.loop.replay) == 1000  # lesson-1 data stays in the replay
    assert seen["updates"] == 38 * 4  # calls at steps 200, 208, ..., 496
    assert run.loop.learner is seen["learner"] and run.loop.learner.num_updates > seen["updates"]
    # lesson 2 starts from lesson 1's trained parameters, not a fresh initialisation
    assert any(not np.array_equal(x, y) for x, y in zip(seen["policy"], initial))
    fresh = DomainRun(RunSpec(plan[1:], TINY, 2), str(tmp_path / "fresh"))
    assert any(not np.array_equal(x, y) for x, y in zip(seen["policy"], leaves(fresh.loop.learner.policy_params)))
    assert float(np.exp(run.loop.learner.state.log_alpha)) != TINY.init_temperature


def test_action_repeat_holds_actions_and_sums_rewards(tmp_path):
    config = SACConfig(**{**TINY.to_dict(), "action_repeat": 3, "hidden_sizes": (32, 32)})
    run = DomainRun(RunSpec(parse_plan("point_mass/easy:1000"), config, 0), str(tmp_path))
    episodes = []
    ran = run.loop.run(1000, on_episode=episodes.append)
    assert ran == 1000 and run.loop.env_steps == 1000  # the episode end cuts the last repeat short
    assert run.loop.transitions == len(run.loop.replay) == 334  # 333 full repeats + 1 step
    assert episodes[0]["length"] == 1000
    np.testing.assert_allclose(run.loop.replay.reward[:334].astype(np.float64).sum(), episodes[0]["return"],
                               rtol=1e-5, atol=1e-4)


@pytest.mark.long
def test_runs_trained_in_worker_processes_equal_runs_trained_in_turn(tmp_path):
    """--workers 2 trains the curriculum and the baseline at once, one process each: same
    checkpoints and reports as training them one after the other."""
    args = TINY_ARGS[:-1] + ["--plan", "point_mass/easy:500,point_mass/hard:500", "--checkpoint-every", "400"]
    summaries = {}
    for workers in ("1", "2"):
        out = str(tmp_path / workers)
        summaries[workers] = training.main(args + ["--out", out, "--workers", workers])
    assert summaries["1"]["runs"] == summaries["2"]["runs"]
    assert summaries["1"]["updates"] == summaries["2"]["updates"] and summaries["2"]["updates"]["baseline"] > 0
    for label in ("curriculum", "baseline"):
        a = checkpoint.load(str(tmp_path / "1" / label / "checkpoint.ckpt"), None)
        b = checkpoint.load(str(tmp_path / "2" / label / "checkpoint.ckpt"), None)
        for x, y in zip(leaves(a["learner"]), leaves(b["learner"]), strict=True):
            np.testing.assert_array_equal(x, y)


def test_paper_sac_flag_gives_acme_defaults_under_explicit_flags():
    args = training.build_parser().parse_args(["--paper-sac", "--batch-size", "32"])
    config = main_job.config_from_args(args, ["--paper-sac", "--batch-size", "32"])
    assert config == SACConfig.paper_sac(batch_size=32)
    assert not config.critic_layer_norm and config.her_ratio == 0 and config.init_temperature == 1.0
    default = main_job.config_from_args(training.build_parser().parse_args(["--domain", "reacher"]), [])
    assert default == main_job.MAIN_JOB_SAC  # the CLI's defaults are the main job's, on every domain
    arm = main_job.config_from_args(training.build_parser().parse_args([]), [], LessonSettings)
    per_lesson = {k: v for k, v in main_job.MAIN_JOB_BY_DOMAIN["robostrich"].items()
                  if k in {f.name for f in dataclasses.fields(LessonSettings)}}
    assert arm == dataclasses.replace(DEFAULT_LESSONS, **per_lesson)
    paper = main_job.config_from_args(args, ["--paper-sac", "--batch-size", "32"], LessonSettings)
    assert paper == LessonSettings()  # nothing per lesson
    argv = ["--her-ratio", "0.5", "--her-lessons", "lesson1,lesson2", "--hidden-sizes", "32,16"]
    args = training.build_parser().parse_args(argv)
    config, lessons = main_job.config_from_args(args, argv), main_job.config_from_args(args, argv, LessonSettings)
    assert lessons.her_lessons == ("lesson1", "lesson2") and config.hidden_sizes == (32, 16)
    assert (lessons.her_ratio("lesson2", config), lessons.her_ratio("lesson3", config)) == (0.5, 0.0)


def test_lesson_checkpoints_hold_the_policy_after_each_lesson(tmp_path):
    """--keep-lesson-checkpoints writes RUN/after_lessonK.ckpt at the end of every lesson but the
    last: a whole checkpoint of that moment, which robostrich-evaluate's loader restores."""
    from agents.robostrich.evaluate import evaluation
    args = TINY_ARGS[:-1] + ["--plan", "point_mass/easy:300,point_mass/hard:300", "--no-baseline",
                             "--checkpoint-every", "1000", "--keep-lesson-checkpoints",
                             "--out", str(tmp_path)]
    training.main(args)
    kept = tmp_path / "curriculum" / "after_lesson1.ckpt"
    assert sorted(p.name for p in (tmp_path / "curriculum").glob("after_lesson*.ckpt")) == [kept.name]
    state = checkpoint.load(str(kept), None)
    assert state["lesson_index"] == 1 and state["loop"]["env_steps"] == 300
    run = evaluation.load_run_from_checkpoint(str(kept))
    assert run.loop.env_steps == 300 and run.lesson.task == "hard"
    final = checkpoint.load(str(tmp_path / "curriculum" / "checkpoint.ckpt"), None)
    assert final["loop"]["env_steps"] == 600
    assert any(not np.array_equal(a, b) for a, b in zip(leaves(state["learner"]), leaves(final["learner"]),
                                                          strict=True))


def test_main_job_defaults_train_the_recipe_on_the_arm_and_plain_sac_settings_elsewhere():
    """The defaults are the measured recipe (docs/training.md#the-main-job) on the arm domains: antagonist_pairs,
    -2 entropy per tendon, HER in lesson 1, the precision term; dm_control plans get none of the
    arm's settings, and the paper's routing and eq. 10 stay one flag away."""
    from agents.robostrich.domains import Domain
    arm, dmc = Domain("robostrich"), Domain("reacher")
    config = main_job.MAIN_JOB_SAC
    assert config.resolved_target_entropy(9) == -18.0 and SACConfig.paper_sac().resolved_target_entropy(9) == -9.0
    assert SACConfig(target_entropy=-3.0).resolved_target_entropy(9) == -3.0  # an explicit value wins
    assert [DEFAULT_LESSONS.her_ratio(t, config) for t in ("lesson1", "lesson2", "lesson3", "lesson4")] == [
        0.5, 0.0, 0.0, 0.0]
    assert main_job.resolve_layout(None, arm) == "ventral_slips" == arm.layout  # the tasks' own, by name
    assert main_job.resolve_layout("antagonist_pairs", arm) == "antagonist_pairs"
    assert main_job.resolve_layout(None, dmc) is None and dmc.layout is None
    with pytest.raises(ValueError, match="'paper' is now called 'ventral_from_base'"):
        Domain("robostrich", "paper")
    recipe = {"weights": {"position_precision": 1.0, "attitude_precision": 0.5}, "target_sampling": "failures",
              "fixed_stored_starts": 0.25}
    assert main_job.resolve_task_kwargs({}, arm) == {**recipe, "target_between": 4}  # on the frame
    assert main_job.resolve_task_kwargs({"weights": {"position_error": 10}, "position_tolerance": 0.02}, arm) == {
        **recipe, "weights": {"position_precision": 1.0, "attitude_precision": 0.5, "position_error": 10},
        "position_tolerance": 0.02, "target_between": 4}
    paper = {"weights": {"position_precision": 0, "attitude_precision": 0}, "target_sampling": "uniform",
             "fixed_stored_starts": 0, "target_between": 0}
    assert main_job.resolve_task_kwargs(paper, arm) == paper
    # the standing quadruped's arm holds the frame's stored poses: the same recipe there, and a
    # quarter of lesson 4's episodes stand
    assert main_job.resolve_task_kwargs({}, Domain("robostrich_a1")) == {**recipe, "standing_share": 0.25}
    assert main_job.resolve_task_kwargs({"standing_share": 0}, Domain("robostrich_a1"))["standing_share"] == 0
    assert main_job.resolve_task_kwargs({}, dmc) == {}
    with pytest.raises(ValueError, match="target_entropy_per_action"):
        SACConfig(target_entropy_per_action=float("nan"))


def test_main_job_on_the_arm_gives_lesson_3_the_longest_share_and_narrower_noise():
    """On robostrich the main job's curriculum is 53k / 53k / 93k control steps with every lesson's
    target entropy at -3 per tendon; on robostrich_a1 lesson 3 alone is narrowed and lesson 4 follows
    from an empty replay; a flag given wins, --paper-sac and other domains keep theirs."""
    def made(*argv):
        args = training.build_parser().parse_args(list(argv))
        return (format_plan(main_job.plan_from_args(args)), main_job.config_from_args(args, list(argv)),
                main_job.config_from_args(args, list(argv), LessonSettings))

    plan, config, lessons = made()
    assert plan == "robostrich/lesson1:53333,robostrich/lesson2:53333,robostrich/lesson3:93334"
    assert [lessons.target_entropy(f"lesson{k}", config, 9) for k in (1, 2, 3)] == [-27.0] * 3
    _, config, lessons = made("--exploration-lessons", "lesson3")
    assert [lessons.target_entropy(f"lesson{k}", config, 9) for k in (1, 2, 3)] == [-18.0, -18.0, -27.0]
    assert made("--steps", "1500")[0] == "robostrich/lesson1:400,robostrich/lesson2:400,robostrich/lesson3:700"
    assert made("--lessons", "lesson1,lesson3", "--steps", "1000")[0] == "robostrich/lesson1:500,robostrich/lesson3:500"
    _, config, lessons = made("--exploration-target-entropy-per-action", "-2.5")
    assert lessons.target_entropy("lesson3", config, 9) == -22.5
    assert made("--exploration-lessons", "")[2].exploration_lessons == ()
    assert made("--paper-sac")[2].exploration_lessons == ()
    plan, config, lessons = made("--domain", "robostrich_a1")  # Algorithm 1: the same three, then lesson 4
    assert plan == ("robostrich_a1/lesson1:160000,robostrich_a1/lesson2:160000,robostrich_a1/lesson3:280000,"
                    "robostrich_a1/lesson4:150000")
    assert lessons.exploration_lessons == ("lesson3",) and lessons.fresh_replay_lessons == ("lesson4",)
    assert config.learning_rate == 1e-3 and config.fine_inputs == ()
    assert made("--domain", "cartpole", "--lessons", "balance")[2].exploration_lessons == ()


def test_long_horizon_lessons_train_with_their_own_discount_and_keep_it_on_resume(tmp_path):
    """long_horizon_lessons: the named lesson trains with long_horizon_discount, the others with
    discount; until that lesson starts the run is bit for bit the plain one, after it differs;
    a run resumed inside the lesson keeps its discount; a misspelt lesson is an error."""
    plan = parse_plan("point_mass/easy:400,point_mass/hard:400")
    long = LessonSettings(long_horizon_lessons=("hard",), long_horizon_discount=0.9)
    plain = DomainRun(RunSpec(plan, TINY, 0), str(tmp_path / "plain"), checkpoint_every=10_000)
    other = DomainRun(RunSpec(plan, TINY, 0, lessons=long), str(tmp_path / "long"), checkpoint_every=600)
    assert other.loop.learner.config.discount == 0.99
    for run in (plain, other):
        run.run(until_step=400)
    assert_same_run(plain, other)
    assert other.loop.learner.config.discount == 0.9 and plain.loop.learner.config.discount == 0.99
    plain.run()
    other.run(until_step=600)
    resumed = DomainRun(RunSpec(plan, TINY, 0, lessons=long), str(tmp_path / "long"))
    resumed.restore()
    assert resumed.loop.learner.config.discount == 0.9
    other.run()
    resumed.run()
    assert_same_run(resumed, other)
    differs = [not np.array_equal(a, b) for a, b in zip(leaves(plain.loop.learner.state.q_params),
                                                        leaves(other.loop.learner.state.q_params))]
    assert all(differs)
    with pytest.raises(ValueError, match=r"long_horizon_lessons names \['lesson3'\]"):
        DomainRun(RunSpec(plan, TINY, 0, lessons=LessonSettings(long_horizon_lessons=("lesson3",))),
                  str(tmp_path / "bad"))
    with pytest.raises(ValueError, match="long_horizon_discount must be in"):
        LessonSettings(long_horizon_discount=1.5)


def test_exploration_lessons_steer_to_their_own_target_entropy_and_keep_it_on_resume(tmp_path):
    """exploration_lessons: the named lesson's temperature steers to
    exploration_target_entropy_per_action x |A| (a higher entropy: the temperature rises above
    the plain run's) and explores with correlated noise; the run is the plain one bit for bit
    until that lesson, a resumed run keeps the lesson's target and its noise state (the same run
    to the end), and a misspelt lesson or a NaN target is an error."""
    plan = parse_plan("point_mass/easy:400,point_mass/hard:400")
    explore = LessonSettings(exploration_lessons=("hard",), exploration_target_entropy_per_action=1.0,
                             exploration_noise_correlation=0.9)
    plain = DomainRun(RunSpec(plan, TINY, 0), str(tmp_path / "plain"), checkpoint_every=10_000)
    other = DomainRun(RunSpec(plan, TINY, 0, lessons=explore), str(tmp_path / "explore"), checkpoint_every=600)
    actions = other.loop.learner.networks.action_size
    assert other.loop.learner.config.resolved_target_entropy(actions) == -2.0 * actions
    for run in (plain, other):
        run.run(until_step=400)
    assert_same_run(plain, other)
    at_switch = float(np.exp(other.loop.learner.state.log_alpha))
    assert other.loop.learner.config.resolved_target_entropy(actions) == 1.0 * actions
    plain.run()
    other.run(until_step=600)
    resumed = DomainRun(RunSpec(plan, TINY, 0, lessons=explore), str(tmp_path / "explore"))
    resumed.restore()
    assert resumed.loop.learner.config.resolved_target_entropy(actions) == 1.0 * actions
    assert resumed.loop.actor.noise_correlation == 0.9 and plain.loop.actor.noise_correlation == 0.0
    np.testing.assert_array_equal(resumed.loop.actor.noise, other.loop.actor.noise)  # the AR(1) state
    other.run()
    resumed.run()
    assert_same_run(resumed, other)
    np.testing.assert_array_equal(np.asarray(resumed.loop.actor.noise), np.asarray(other.loop.actor.noise))
    temperature = {name: float(np.exp(run.loop.learner.state.log_alpha)) for name, run in
                   (("plain", plain), ("explore", other))}
    # Over the second lesson the plain run's temperature keeps falling, the explorer's turns up.
    assert temperature["explore"] > at_switch > temperature["plain"], (at_switch, temperature)
    with pytest.raises(ValueError, match=r"exploration_lessons names \['lesson3'\]"):
        DomainRun(RunSpec(plan, TINY, 0, lessons=LessonSettings(exploration_lessons=("lesson3",))),
                  str(tmp_path / "bad"))
    with pytest.raises(ValueError, match="exploration_target_entropy_per_action must be finite"):
        LessonSettings(exploration_target_entropy_per_action=float("nan"))
