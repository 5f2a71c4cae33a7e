"""Domain randomisation draws new arm parameters per episode, around the nominal model."""
import numpy as np
import pytest

import robostrich_suite
from robostrich_suite.tasks.randomization import DomainRandomization


def _masses(env):
    return np.array(env.physics.named.model.body_mass[[f"arm/{n}" for n in ("atlas", "c9")]])


def test_each_episode_draws_new_parameters_within_bounds():
    nominal = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(random=0))
    nominal.reset()
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(
        random=0, randomization=dict(mass_scale=(0.5, 1.5))))
    draws = []
    for _ in range(4):
        env.reset()
        draws.append(_masses(env))
        ratio = _masses(env) / _masses(nominal)
        assert np.all((ratio >= 0.5) & (ratio <= 1.5))  # relative to nominal, not cumulative
    assert len({tuple(d) for d in draws}) == 4
    model = env.physics.model  # gain scaling keeps each servo's rest length (bias0 / -gain0)
    assert not np.allclose(model.actuator_gainprm[:, 0], nominal.physics.model.actuator_gainprm[:, 0])
    np.testing.assert_allclose(model.actuator_biasprm[:, 0] / -model.actuator_gainprm[:, 0],
                               nominal.physics.tendon_rest_lengths(), rtol=1e-12)
    floor = env.physics.named.model.body_mass["world"]
    assert floor == nominal.physics.named.model.body_mass["world"]


def test_randomized_dynamics_change_where_the_arm_settles():
    action = np.full(9, 0.02)
    finals = []
    for randomization in (None, DomainRandomization(stiffness_scale=(0.3, 0.3),
                                                    mass_scale=(1, 1), damping_scale=(1, 1),
                                                    tendon_gain_scale=(1, 1))):
        env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(
            random=0, randomization=randomization, time_limit=0.8))
        ts = env.reset()
        while not ts.last():
            ts = env.step(action)
        finals.append(ts.observation["head_position"])
    assert np.linalg.norm(finals[0] - finals[1]) > 0.005


def test_joint_angle_noise_and_bad_ranges():
    env = robostrich_suite.load("robostrich", "lesson2", task_kwargs=dict(
        random=0, randomization=dict(joint_angle_noise=0.01)))
    ts = env.reset()
    noise = ts.observation["joint_angles"] - env.physics.joint_angles()
    assert 0.002 < noise.std() < 0.03
    with pytest.raises(ValueError, match="mass_scale"):
        DomainRandomization(mass_scale=(1.2, 0.8))
