"""Hindsight relabelling on the real arm: recomputed rewards are exact, relabelled goals
come from later in the same episode, and a resumed run with HER is bit-exact."""
import dataclasses

import numpy as np
import pytest

from agents.curriculum import LessonSettings
from agents.replay import ReplayBuffer
from agents.robostrich.domain_run import DomainRun
from agents.robostrich.run_spec import RunSpec, parse_plan
from agents.sac.config import SACConfig

HER = SACConfig(batch_size=32, hidden_sizes=(32, 32), min_replay_size=100, max_replay_size=5000,
                updates_per_call=2, env_steps_per_call=2, action_repeat=5, her_ratio=0.5,
                relabel_rewards=True, critic_layer_norm=True)


def filled_run(tmp_path, plan="robostrich/lesson2:1500", config=HER, seed=0):
    run = DomainRun(RunSpec(parse_plan(plan), config, seed), str(tmp_path), checkpoint_every=10_000)
    run.run()
    return run


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    return filled_run(tmp_path_factory.mktemp("her"))


def test_recomputed_rewards_equal_the_rewards_the_task_gave(run):
    """For the real target, summing the task's goal reward over the stored control steps gives
    back the summed reward eq. 10 produced during the episode (action repeat 5)."""
    replay, relabeler = run.loop.replay, run.loop.relabeler
    n = len(replay)
    assert n == 1500 // 5 and replay.goal_width == 3
    goals = replay.obs[:n, relabeler.goal]
    recomputed = relabeler.rewards(replay.substep_goals[:n], replay.substeps[:n], goals)
    np.testing.assert_allclose(recomputed, replay.reward[:n], rtol=1e-5, atol=1e-4)
    assert np.all(replay.substeps[:n] == 5)
    assert np.min(replay.reward[:n]) < -5  # real misses, not a vacuous comparison


def test_the_inputs_change_charge_survives_recomputed_and_hindsight_rewards(tmp_path):
    """With ``weights.action_change`` the replay keeps each reward's part no goal changes: recomputed
    for its own goal the reward is the one the task gave (the charge included), and a hindsight
    reward carries the same charge; lesson 1 (eq. 9, no charge) keeps none."""
    run = DomainRun(RunSpec(parse_plan("robostrich/lesson1:300,robostrich/lesson2:600"), HER, 1,
                            task_kwargs={"weights": {"action_change": 50.0}}),
                    str(tmp_path), checkpoint_every=10_000)
    run.run()
    replay, relabeler = run.loop.replay, run.loop.relabeler
    assert relabeler.keeps_goal_free and replay.goal_free is not None
    n, lesson1 = len(replay), 300 // 5
    charge = replay.goal_free[:n]
    assert np.all(charge[:lesson1] == 0) and np.all(charge[lesson1:] < 0)  # every lesson-2 step moved its inputs
    goals = replay.obs[:n, relabeler.goal]
    recomputed = relabeler.rewards(replay.substep_goals[:n], replay.substeps[:n], goals) + charge
    np.testing.assert_allclose(recomputed[lesson1:], replay.reward[lesson1:n], rtol=1e-5, atol=1e-4)
    plain = relabeler.rewards(replay.substep_goals[:n], replay.substeps[:n], goals)
    assert np.max(plain[lesson1:] - replay.reward[lesson1:n]) > 0.1  # without the kept part it would be lost
    drawn = replay.rng.bit_generator.state
    batch = replay.sample_stack(1, 256, relabeler, her_ratio=1.0, relabel_rewards=True)
    replay.rng.bit_generator.state = drawn
    idx = replay.rng.integers(0, n, size=(1, 256))  # the rows that batch drew
    new_goal = batch.obs[..., relabeler.goal]
    assert np.mean(np.any(new_goal != replay.obs[idx][..., relabeler.goal], axis=-1)) > 0.5  # relabelled
    plain = relabeler.rewards(replay.substep_goals[idx], replay.substeps[idx], new_goal)
    np.testing.assert_allclose(batch.reward - plain, charge[idx], atol=1e-4)
    state = replay.state_dict()
    restored = ReplayBuffer(state["obs_size"], state["action_size"], state["capacity"], goal_width=state["goal_width"],
                            repeat=state["repeat"])
    restored.load_state_dict(state)  # a checkpoint keeps the charges
    np.testing.assert_array_equal(restored.goal_free[:n], charge)


def test_hindsight_goals_are_reached_later_in_the_same_episode(run):
    replay, relabeler = run.loop.replay, run.loop.relabeler
    n = len(replay)
    shadow = np.random.default_rng()
    shadow.bit_generator.state = replay.rng.bit_generator.state
    rows = shadow.integers(0, n, size=(1, 400))[0]  # the rows sample_stack is about to draw
    batch = replay.sample_stack(1, 400, relabeler, her_ratio=1.0)
    goals = batch.obs[0][:, relabeler.goal]
    head = batch.obs[0][:, relabeler.achieved]
    np.testing.assert_allclose(batch.obs[0][:, relabeler.delta], goals - head, atol=1e-6)
    np.testing.assert_array_equal(batch.next_obs[0][:, relabeler.goal], goals)
    reached = replay.substep_goals[:n, -1, :2]  # the head at the end of each transition
    episode = replay.abs_index[:n] // 50  # 2 s episodes = 50 decisions of 5 control steps
    for row, goal in zip(rows, goals):
        later = np.flatnonzero((episode == episode[row]) & (replay.abs_index[:n] >= replay.abs_index[row]))
        assert np.any(np.all(reached[later] == goal, axis=1)), (row, goal)
    # Relabelled goals lie nearer the head than the real targets do.
    real = np.linalg.norm(replay.obs[:n, relabeler.goal] - replay.obs[:n, relabeler.achieved], axis=1)
    assert np.mean(np.linalg.norm(goals - head, axis=1)) < 0.8 * np.mean(real)
    assert len(np.unique(episode)) == 6


def test_resumed_her_run_is_bit_exact(tmp_path):
    plan = parse_plan("robostrich/lesson1:600,robostrich/lesson2:600")
    a = DomainRun(RunSpec(plan, HER, 3), str(tmp_path / "a"), checkpoint_every=10_000)
    a.run(until_step=740)  # mid-episode in lesson 2, after learning started
    path = str(tmp_path / "run.ckpt")
    a.save_checkpoint(path)
    b = DomainRun(RunSpec(plan, HER, 3), str(tmp_path / "b"), checkpoint_every=10_000)
    b.restore(path)
    a.run()
    b.run()
    n = len(a.loop.replay)
    for field in a.loop.replay.fields:
        np.testing.assert_array_equal(getattr(a.loop.replay, field)[:n], getattr(b.loop.replay, field)[:n])
    for x, y in zip(*(np.asarray(v) for v in (a.loop.learner.get_state().q_params["critic_head"]["w"],
                                              b.loop.learner.get_state().q_params["critic_head"]["w"]))):
        np.testing.assert_array_equal(x, y)


def test_task_kwargs_reach_every_lesson_and_the_checkpoint_fingerprint(tmp_path):
    """--task-kwargs (eq. 10's weights here) go to each lesson's task; a checkpoint made with
    other weights is refused on resume."""
    plan = parse_plan("robostrich/lesson1:100,robostrich/lesson2:100")
    weights = {"weights": {"position_error": 10.0}}
    run = DomainRun(RunSpec(plan, HER, 0, task_kwargs=weights), str(tmp_path / "a"))
    assert run.loop.env.task.weights.position_error == 10.0
    run.run()
    assert run.done
    path = str(tmp_path / "run.ckpt")
    run.save_checkpoint(path)
    plain = DomainRun(RunSpec(plan, HER, 0), str(tmp_path / "b"))
    assert plain.loop.env.task.weights.position_error == 2.0
    with pytest.raises(ValueError, match="task_kwargs"):
        plain.restore(path)


def test_her_lessons_relabel_only_the_named_lessons_also_after_a_resume(tmp_path):
    """her_lessons=("lesson1",): lesson 1's batches get hindsight goals, lesson 2's keep the real
    targets, and a run resumed in lesson 2 keeps HER off."""
    plan = parse_plan("robostrich/lesson1:600,robostrich/lesson2:600")
    config, lessons = HER, LessonSettings(her_lessons=("lesson1",))
    run = DomainRun(RunSpec(plan, config, 1, lessons=lessons), str(tmp_path / "a"), checkpoint_every=10_000)
    assert run.loop.her_ratio == 0.5
    run.run(until_step=800)
    assert run.lesson_index == 1 and run.loop.her_ratio == 0.0
    replay, relabeler = run.loop.replay, run.loop.relabeler
    real_targets = {tuple(g) for g in replay.obs[:len(replay), relabeler.goal]}

    def relabelled_share(her_ratio):
        goals = replay.sample_stack(1, 400, relabeler, her_ratio=her_ratio).obs[0][:, relabeler.goal]
        return np.mean([tuple(g) not in real_targets for g in goals])

    assert relabelled_share(run.loop.her_ratio) == 0.0
    assert relabelled_share(lessons.her_ratio("lesson1", config)) > 0.3  # what lesson 1 sampled
    path = str(tmp_path / "run.ckpt")
    run.save_checkpoint(path)
    resumed = DomainRun(RunSpec(plan, config, 1, lessons=lessons), str(tmp_path / "b"), checkpoint_every=10_000)
    assert resumed.loop.her_ratio == 0.5  # lesson 1 until the checkpoint says otherwise
    resumed.restore(path)
    assert resumed.loop.her_ratio == 0.0
    with pytest.raises(ValueError, match="her_lessons"):
        LessonSettings(her_lessons="lesson1")  # a string, not a tuple of names
    misspelt = LessonSettings(her_lessons=("lesson_1",))
    off = DomainRun(RunSpec(plan, dataclasses.replace(HER, her_ratio=0.0), 1, lessons=misspelt),
                    str(tmp_path / "off"))  # --her-ratio 0 turns HER off whatever the lessons say
    assert off.loop.her_ratio == 0.0
    with pytest.raises(ValueError, match=r"her_lessons names \['lesson_1'\]"):
        DomainRun(RunSpec(plan, HER, 1, lessons=misspelt), str(tmp_path / "c"))


def test_level_goals_only_relabel_with_poses_the_lesson_could_set(run):
    """The reaching tasks' option hindsight_level_goals: a row gets a later pose as its goal only if
    that pose's head was within the attitude tolerance (a target lesson 2 could set); the others
    keep their own target. Lesson 1 (eq. 9 ignores the attitude), and every lesson without the
    option, may relabel with every reached position."""
    import robostrich_suite
    replay, relabeler, task = run.loop.replay, run.loop.relabeler, run.loop.env.task
    n = len(replay)
    reached = replay.substep_goals[:n, -1]
    assert relabeler.settable(reached) is None  # the option is off by default
    level = {"hindsight_level_goals": True}
    assert robostrich_suite.load("robostrich", "lesson1", task_kwargs=level).task.settable_goals(reached) is None
    assert robostrich_suite.load("robostrich", "lesson2", task_kwargs=level).task.attitude_tolerance == 5.0
    attitude = np.abs(reached[:, 2])
    # The random policy rarely holds the head level: judge against the median attitude error
    # instead, so that about half the reached poses count as settable goals.
    saved = task.attitude_tolerance
    task.hindsight_level_goals, task.attitude_tolerance = True, float(np.median(attitude))
    try:
        batch = replay.sample_stack(1, 400, relabeler, her_ratio=1.0)
    finally:
        task.hindsight_level_goals, task.attitude_tolerance = False, saved
    goals = batch.obs[0][:, relabeler.goal]
    kept = relabelled = 0
    for goal in goals:
        match = np.flatnonzero(np.all(reached[:, :2] == goal, axis=1))
        if match.size:  # a reached position: it must have been a settable one
            assert np.any(attitude[match] <= np.median(attitude))
            relabelled += 1
        else:
            assert np.any(np.all(replay.obs[:n, relabeler.goal] == goal, axis=1))  # its own target
            kept += 1
    assert relabelled > 100 and kept > 100


def test_on_the_quadruped_hindsight_uses_the_heads_forward_and_up_components(tmp_path):
    """The quadruped's head position is 3-D (forward, left, up) and its goal 2-D: the relabeler
    compares the goal with (forward, up), and the rewards it recomputes are the task's."""
    run = filled_run(tmp_path, plan="robostrich_a1/lesson2:500")
    replay, relabeler = run.loop.replay, run.loop.relabeler
    assert relabeler is not None and list(relabeler.achieved) == [0, 2]
    n = len(replay)
    recomputed = relabeler.rewards(replay.substep_goals[:n], replay.substeps[:n], replay.obs[:n, relabeler.goal])
    np.testing.assert_allclose(recomputed, replay.reward[:n], rtol=1e-5, atol=1e-4)
    assert np.ptp(replay.reward[:n]) > 1  # rewards that differ, not a vacuous comparison


def test_a_goal_the_achieved_observation_cannot_be_compared_with_is_refused():
    from agents.goals import GoalRelabeler
    from agents.replay import ObservationFlattener
    import robostrich_suite
    env = robostrich_suite.load("robostrich_a1", "lesson1")
    flattener = ObservationFlattener(env.observation_spec())
    type(env.task).ACHIEVED_COMPONENTS, saved = None, type(env.task).ACHIEVED_COMPONENTS
    try:
        with pytest.raises(ValueError, match="achieved_components"):
            GoalRelabeler.for_environment(env, flattener)
    finally:
        type(env.task).ACHIEVED_COMPONENTS = saved


def test_after_a_fresh_replay_lesson_hindsight_goals_still_come_from_the_same_episode(tmp_path):
    """A lesson that starts with an empty replay refills it from row 0 while the stream's count
    goes on: hindsight goals must still be poses reached later in the transition's own episode
    (not rows the clear left behind, nor never-written zeros)."""
    plan = parse_plan("robostrich/lesson1:500,robostrich/lesson2:1000")
    run = DomainRun(RunSpec(plan, HER, 2, lessons=LessonSettings(fresh_replay_lessons=("lesson2",))),
                    str(tmp_path), checkpoint_every=10_000)
    run.run()
    replay, relabeler = run.loop.replay, run.loop.relabeler
    n = len(replay)
    assert n == 1000 // 5 and replay.abs_index[0] == 500 // 5  # refilled from row 0, the count went on
    shadow = np.random.default_rng()
    shadow.bit_generator.state = replay.rng.bit_generator.state
    rows = shadow.integers(0, n, size=(1, 300))[0]
    goals = replay.sample_stack(1, 300, relabeler, her_ratio=1.0).obs[0][:, relabeler.goal]
    reached = replay.substep_goals[:n, -1, :2]
    episode = replay.abs_index[:n] // 50
    for row, goal in zip(rows, goals):
        later = np.flatnonzero((episode == episode[row]) & (replay.abs_index[:n] >= replay.abs_index[row]))
        assert np.any(np.all(reached[later] == goal, axis=1)), (row, goal)
    restored = type(replay)(replay.obs_size, replay.action_size, replay.capacity, goal_width=replay.goal_width,
                            repeat=replay.repeat)
    restored.load_state_dict(replay.state_dict())
    assert restored.row_base == replay.row_base == 500 // 5
