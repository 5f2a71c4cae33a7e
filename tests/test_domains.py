"""The domain adapter (agents/robostrich/domains.py): each arm domain and tendon layout trains and is judged on its own
targets, with its own lookup table; dm_control domains keep working; bad names are errors that name them."""
import dataclasses

import numpy as np
import pytest

from agents import checkpoint
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, parse_plan
from agents.robostrich.domains import Domain
from agents.robostrich.train.main_job import MAIN_JOB_SAC
from robostrich_suite import targets
from robostrich_suite.model import layouts
from robostrich_suite.tasks import quadruped_tasks
from robostrich_suite.tasks.track import default_track_targets

LAYOUT = "antagonist_pairs"
TINY = dataclasses.replace(MAIN_JOB_SAC, hidden_sizes=(16, 16), batch_size=16, min_replay_size=20,
                           updates_per_call=2, env_steps_per_call=2)  # the main job's agent, small


def test_quadruped_domain_reads_the_frame_arms_targets_and_lookup_in_its_trunk_frame():
    domain = Domain("robostrich_a1")
    np.testing.assert_allclose(domain.heldout_targets(), quadruped_tasks.frame_to_trunk(targets.heldout_targets()))
    table, frame_table = domain.lookup_table(), Domain("robostrich").lookup_table()
    np.testing.assert_array_equal(table["control"], frame_table["control"])
    np.testing.assert_allclose(table["head_position"], quadruped_tasks.frame_to_trunk(frame_table["head_position"]))
    assert domain.heldout_task("lesson4") == "lesson2" and domain.has_moving_starts
    assert domain.track_task("track") is None  # the quadruped has no `track`; the frame arm has
    assert Domain("robostrich").track_task("track") == "track"
    starts, controls = domain.moving_starts()
    assert starts.shape == (3, 2) and controls.shape == (3, 9)
    # the starts lie among the quadruped's own training targets (trunk frame), not the frame's
    pool = quadruped_tasks.default_target_pool()
    assert np.min(np.linalg.norm(pool[None] - starts[:, None], axis=2), axis=1).max() < 1e-12


def test_a_layout_trains_and_is_judged_on_its_own_targets():
    domain = Domain("robostrich", LAYOUT)
    path = layouts.target_file(LAYOUT)
    heldout = domain.heldout_targets()
    np.testing.assert_array_equal(heldout, targets.heldout_targets(path))
    assert not np.array_equal(heldout[:len(targets.heldout_targets())], targets.heldout_targets())
    env = domain.make_environment("lesson2", 0)
    np.testing.assert_array_equal(env.task.target_pool, targets.training_targets(path))
    track = domain.make_environment("track", 0)
    np.testing.assert_array_equal(track.task.targets, default_track_targets(heldout))
    table = domain.lookup_table()
    assert np.linalg.norm(table["head_position"][:, None] - heldout[None], axis=2).min() >= 0.01  # no held-out pose

    # The table's inputs are this layout's: held from the fixed start they bring the head to the stored pose.
    env.task.target_pool = table["head_position"][:1]
    timestep = env.reset()
    while not timestep.last():
        timestep = env.step(table["control"][0])
    assert env.task.position_error(env.physics) < 0.01
    assert abs(env.task.attitude_error(env.physics)) < 5.0


def test_bad_domain_layout_and_task_names_are_errors_that_name_them():
    with pytest.raises(ValueError, match="unknown layout 'tangled'.*antagonist_pairs"):
        Domain("robostrich", "tangled")
    with pytest.raises(ValueError, match="arm domains.*'reacher'"):
        Domain("reacher", "ventral_slips")
    with pytest.raises(ValueError, match="no task 'lesson9'.*lesson1"):
        Domain("robostrich").check_task("lesson9")
    with pytest.raises(ValueError, match="unknown domain 'robostrch'.*robostrich"):
        Domain("robostrch").check_task("lesson1")
    with pytest.raises(ValueError, match="observe_sent_actions applies to the arm domains.*'reacher'"):
        Domain("reacher", sent_actions=3)
    with pytest.raises(ValueError, match="observe_sent_actions must be a whole number.*from 0 to 8"):
        Domain("robostrich", sent_actions=9)
    Domain("robostrich_a1").check_task("lesson4")
    Domain("reacher").check_task("easy")
    assert Domain("reacher").heldout_targets() is None and Domain("reacher").lookup_table() is None


def test_a_domain_that_observes_its_sent_actions_gives_every_environment_that_observation():
    observing = Domain("robostrich", sent_actions=2)
    for task in ("lesson2", "lesson3", "track"):
        observation = observing.make_environment(task, 0).reset().observation
        assert observation["sent_actions"].shape == (18,), task
    assert "sent_actions" not in Domain("robostrich").make_environment("lesson2", 0).reset().observation
    assert observing.describe() == "robostrich (layout ventral_slips), observing 2 sent actions"
    assert observing.info() == {"domain": "robostrich", "layout": "ventral_slips", "observe_sent_actions": 2}


def test_curriculum_runs_every_lesson_on_the_quadruped_and_carries_the_learner(tmp_path):
    plan = parse_plan("lesson1:60,lesson2:60,lesson3:60,lesson4:60", default_domain="robostrich_a1")
    run = DomainRun(RunSpec(plan, TINY, 0), str(tmp_path / "a1"), checkpoint_every=10 ** 6)
    learner = run.loop.learner
    run.run()
    assert run.done and run.loop.env_steps == 240
    assert run.loop.learner is learner and learner.num_updates > 100
    assert len(run.loop.replay) == 240  # one replay through all four lessons
    assert run.loop.env.physics.trunk_height() > 0.1  # the last lesson's environment is the quadruped's
    assert run.loop.env.task.legs == "walk"  # lesson 4: the quadruped trots


@pytest.mark.long
def test_a_layout_is_part_of_the_checkpoint(tmp_path):
    plan = parse_plan("lesson1:40")
    run = DomainRun(RunSpec(plan, TINY, 0, layout=LAYOUT), str(tmp_path / "run"))
    assert run.fingerprint()["layout"] == LAYOUT
    run.run()
    other = DomainRun(RunSpec(plan, TINY, 0), str(tmp_path / "other"))  # the paper's layout
    with pytest.raises(checkpoint.CheckpointError, match="layout"):
        other.restore(run.checkpoint_path)
    with pytest.raises(ValueError, match="arm domains"):
        DomainRun(RunSpec(parse_plan("reacher/easy:10"), TINY, 0, layout=LAYOUT), str(tmp_path / "r"))


def test_periodic_evaluation_targets_spread_over_the_held_out_set():
    """The periodic evaluation's 20 targets reach the upper workspace: the first 20 of `antagonist_pairs`'
    44 (generation order) hold none of its upper third, where a policy can fail unseen."""
    full = Domain("robostrich", LAYOUT).heldout_targets()
    subset = Domain("robostrich", LAYOUT).heldout_targets(20)
    assert len(subset) == 20 and len(np.unique(subset, axis=0)) == 20
    np.testing.assert_array_equal(subset[[0, -1]], full[[0, -1]])
    upper = np.percentile(full[:, 1], 67)
    assert (subset[:, 1] > upper).sum() >= 5
    np.testing.assert_array_equal(Domain("robostrich").heldout_targets(100), Domain("robostrich").heldout_targets())


def test_default_lessons_are_the_domains_curriculum():
    """Without --lessons/--plan, robostrich-train runs Algorithm 1 of the chosen domain: lessons 1-3
    on the frame, 1-4 (lesson 4 trotting) on the quadruped; a dm_control domain must name its tasks."""
    from agents.curriculum import LessonSettings
    from agents.robostrich.train import main_job
    from agents.robostrich.train import command as training
    parse = training.build_parser().parse_args
    frame = main_job.plan_from_args(parse(["--steps", "300"]))
    assert [(l.domain, l.task, l.steps) for l in frame] == [
        ("robostrich", "lesson1", 80), ("robostrich", "lesson2", 80), ("robostrich", "lesson3", 140)]  # 4:4:7
    quadruped = main_job.plan_from_args(parse(["--domain", "robostrich_a1", "--steps", "1000"]))
    assert [l.task for l in quadruped] == ["lesson1", "lesson2", "lesson3", "lesson4"]
    assert sum(l.steps for l in quadruped) == 1000
    with pytest.raises(ValueError, match="has no curriculum"):
        main_job.plan_from_args(parse(["--domain", "cartpole"]))


def test_quadruped_main_job_runs_all_four_lessons_and_resumes_mid_lesson4_exactly(tmp_path):
    """Algorithm 1 on the quadruped as robostrich-train runs it by default (lessons 1-3 standing with
    hindsight goals in lesson 1 and stored starts, then lesson 4 trotting from an empty replay, in its
    16:16:28:15 split),
    at a tiny budget: killed while the quadruped trots (its trunk height schedule under way), a run
    restored from its checkpoint continues exactly as the run that was never stopped."""
    from agents.curriculum import LessonSettings
    from agents.robostrich.train import main_job
    from agents.robostrich.train import command as training
    args = training.build_parser().parse_args(["--domain", "robostrich_a1", "--steps", "300"])
    plan = main_job.plan_from_args(args)
    assert [(l.task, l.steps) for l in plan] == [("lesson1", 64), ("lesson2", 64), ("lesson3", 112), ("lesson4", 60)]
    lessons = main_job.config_from_args(args, [], cls=LessonSettings)
    spec = RunSpec(plan, TINY, 0, lessons, main_job.resolve_task_kwargs({}, Domain("robostrich_a1")))

    def make_run(name):
        return DomainRun(spec, str(tmp_path / name), checkpoint_every=10 ** 6)

    whole = make_run("whole")
    whole.run()
    assert whole.done and whole.loop.relabeler is not None  # hindsight goals have the head's (forward, up)
    # lesson 4 started with an empty replay: it holds the trot's transitions only
    assert len(whole.loop.replay) == 60 // TINY.action_repeat < whole.loop.replay.total_added
    first = make_run("killed")
    first.run(until_step=270)  # 30 steps into lesson 4
    assert first.lesson.task == "lesson4" and first.loop.env.task.legs == "walk"
    first.save_checkpoint()
    resumed = make_run("killed")
    resumed.restore()
    resumed.run()
    assert resumed.loop.env_steps == whole.loop.env_steps == 300
    np.testing.assert_array_equal(resumed.loop.env.physics.get_state(), whole.loop.env.physics.get_state())
    for a, b in zip(jax_leaves(resumed.loop.learner.policy_params), jax_leaves(whole.loop.learner.policy_params),
                    strict=True):
        np.testing.assert_array_equal(a, b)


def jax_leaves(tree):
    import jax
    leaves = jax.tree_util.tree_leaves(tree)
    assert leaves
    return [np.asarray(leaf) for leaf in leaves]


def test_stored_starts_come_from_the_lookup_table_without_the_evaluations_moving_starts():
    """The agent layer fills lesson 3's start_inputs from the layout's lookup table (no held-out
    pose), leaving out the poses the moving-start evaluation starts from."""
    domain = Domain("robostrich", LAYOUT)
    table, (starts, start_controls) = domain.lookup_table(), domain.moving_starts()
    inputs = domain.stored_start_inputs()
    assert 0 < len(inputs) < len(table["control"])
    for control in start_controls:
        assert not np.any(np.all(inputs == control, axis=1))
    for task, option in (("lesson3", "stored_starts"), ("lesson1", "fixed_stored_starts")):
        env = domain.make_environment(task, 0, **{option: 0.5})
        np.testing.assert_array_equal(env.task.start_inputs, inputs)
    # The same poses on the standing quadruped (the arm holds them as on the frame).
    a1 = Domain("robostrich_a1", LAYOUT)
    np.testing.assert_array_equal(a1.make_environment("lesson3", 0, stored_starts=0.5).task.start_inputs, inputs)


def test_the_registry_names_each_domains_evaluation_tasks_and_mount():
    """The agent layer reads these facts from the suite's registry (tags), not from task names."""
    import robostrich_suite
    for name, mount in (("robostrich", "frame"), ("robostrich_a1", "quadruped")):
        domain = Domain(name)
        assert robostrich_suite.mount(name) == mount and domain.on_quadruped == (mount == "quadruped")
        assert domain.heldout_task("ignored") == "lesson2" and domain.moving_start_task == "lesson3"
        assert set(robostrich_suite.tasks_tagged(name, "draws_targets")) == set(domain.curriculum())
    assert robostrich_suite.tasks_tagged("robostrich", "track") == ("track",)
    assert robostrich_suite.tasks_tagged("robostrich_a1", "track") == ()
    frame = np.array([[0.1, 0.3]])
    np.testing.assert_array_equal(robostrich_suite.targets_from_frame("robostrich", frame), frame)
    assert not np.allclose(robostrich_suite.targets_from_frame("robostrich_a1", frame), frame)
    with pytest.raises(ValueError, match="unknown domain 'cartpole'"):
        robostrich_suite.tasks_tagged("cartpole", "heldout")
