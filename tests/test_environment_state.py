"""An environment's open episode as data (agents/robostrich/environment_state.py): stored mid-episode
through a checkpoint file and restored into a freshly made environment of the same task, it goes
on bit for bit, across episode ends, on every task of this package and on dm_control's."""
import numpy as np
import pytest

from agents import checkpoint
from agents.robostrich import environment_state
from agents.robostrich.domains import Domain
from robostrich_suite.tasks.randomization import DomainRandomization

CASES = {  # (domain, task, task options, control steps before the checkpoint, steps after it)
    "point_mass": ("point_mass", "easy", {}, 130, 60),
    "reacher": ("reacher", "easy", {}, 1010, 60),  # the target is a model field each episode moves
    "lesson3": ("robostrich", "lesson3", {"time_limit": 0.2, "target_sampling": "failures",
                                          "release_starts": 0.5}, 60, 80),
    "randomised": ("robostrich", "lesson2", {"time_limit": 0.2, "randomization":
                                             DomainRandomization(joint_angle_noise=0.01)}, 60, 80),
    "track": ("robostrich", "track", {"steps_per_target": 10}, 15, 40),
    "lesson4": ("robostrich_a1", "lesson4", {"time_limit": 0.4}, 70, 60),
    "narrow_gap": ("robostrich_a1", "narrow_gap", {"steps_per_target": 5, "switch": "reached"}, 20, 20),
}


def make(case):
    domain, task, options, _, _ = CASES[case]
    env = Domain(domain).make_environment(task, 7, **options)
    return env, environment_state.model_reference(env)


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_restored_episode_goes_on_bit_for_bit(case, tmp_path):
    before, after = CASES[case][3:]
    env, reference = make(case)
    spec = env.action_spec()
    actions = np.random.default_rng(0).uniform(spec.minimum, spec.maximum, (before + after,) + spec.shape)
    timestep = env.reset()
    for action in actions[:before]:
        timestep = env.reset() if timestep.last() else timestep
        timestep = env.step(action)
    path = str(tmp_path / "episode.ckpt")
    checkpoint.save(path, {"episode": environment_state.capture(env, timestep, None, reference)}, {})
    stored = checkpoint.load(path)["episode"]
    fresh, fresh_reference = make(case)
    restored, _ = environment_state.restore(fresh, stored, fresh_reference)
    assert restored.step_type == timestep.step_type and restored.reward == timestep.reward
    changed_fields = stored["physics"]["model"]
    assert bool(changed_fields) == (case in ("reacher", "randomised")), sorted(changed_fields)
    for action in actions[before:]:
        if timestep.last():
            timestep, restored = env.reset(), fresh.reset()
        timestep, restored = env.step(action), fresh.step(action)
        assert timestep.reward == restored.reward and timestep.step_type == restored.step_type
        for key, value in timestep.observation.items():
            np.testing.assert_array_equal(restored.observation[key], value, err_msg=key)
    np.testing.assert_array_equal(fresh.physics.get_state(), env.physics.get_state())


def test_an_episode_of_another_task_or_a_task_holding_objects_is_refused():
    env, reference = make("track")
    stored = environment_state.capture(env, env.reset(), None, reference)
    other, other_reference = make("lesson3")
    with pytest.raises(ValueError, match="Track.*Reach"):
        environment_state.restore(other, stored, other_reference)
    suite_env, suite_reference = make("point_mass")
    suite_env.task.helper = object()  # a dm_control task's attributes are stored only when they are data
    with pytest.raises(checkpoint.NotData, match="helper"):
        environment_state.capture(suite_env, suite_env.reset(), None, suite_reference)
