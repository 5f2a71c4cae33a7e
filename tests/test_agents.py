"""Unit tests of the SAC pieces: real JAX, tiny networks."""
import jax
import numpy as np
import pytest
from dm_env import specs

from agents.actors import ActionAdapter, Actor
from agents.replay import ObservationFlattener, ReplayBuffer
from agents.sac.config import SACConfig
from agents.sac.learning import SACLearner, TrainingState, Transitions
from agents.sac.networks import make_networks, tanh_gaussian_log_prob

OBS, ACT = 6, 3
# A small agent with this project's additions on (the values of the arm's main job), which these
# tests were measured with.
TINY = SACConfig(batch_size=32, hidden_sizes=(32, 32), min_replay_size=1, max_replay_size=1000,
                 updates_per_call=4, env_steps_per_call=4, learning_rate=1e-3, target_entropy_per_action=-2.0,
                 init_temperature=0.01, critic_layer_norm=True, her_ratio=0.5, relabel_rewards=True,
                 pre_tanh_penalty=0.1, policy_average=1e-4)


def random_batch(num_updates, batch, seed=0):
    rng = np.random.default_rng(seed)
    return Transitions(rng.normal(size=(num_updates, batch, OBS)).astype(np.float32),
                       rng.uniform(-1, 1, size=(num_updates, batch, ACT)).astype(np.float32),
                       rng.normal(size=(num_updates, batch)).astype(np.float32),
                       np.ones((num_updates, batch), np.float32),
                       rng.normal(size=(num_updates, batch, OBS)).astype(np.float32))


def make_learner(seed=0, config=TINY):
    return SACLearner(make_networks(OBS, ACT, config.hidden_sizes), config, jax.random.PRNGKey(seed))


def leaves(tree):
    """The arrays of a parameter tree; never none, so comparing two trees leaf by leaf cannot pass vacuously."""
    arrays = [np.asarray(x) for x in jax.tree_util.tree_leaves(tree)]
    assert arrays, "an empty tree"
    return arrays


def test_critic_loss_falls_on_a_fixed_batch():
    learner = make_learner()
    # discount 0: the Bellman target is the reward itself, so the critics face a fixed regression.
    fixed = random_batch(1, 32)._replace(discount=np.zeros((1, 32), np.float32))
    stack = Transitions(*(np.repeat(x, 4, axis=0) for x in fixed))
    losses = [float(learner.step(stack)["critic_loss"]) for _ in range(50)]
    assert all(np.isfinite(losses)) and losses[-1] < 0.4 * losses[0], losses


def test_update_is_deterministic_for_a_seed_and_differs_across_seeds():
    batches = random_batch(4, 32, seed=1)
    a, b, c = make_learner(seed=3), make_learner(seed=3), make_learner(seed=4)
    ma, mb = a.step(batches), b.step(batches)
    c.step(batches)
    for x, y in zip(leaves(a.state), leaves(b.state), strict=True):
        np.testing.assert_array_equal(x, y)
    assert float(ma["critic_loss"]) == float(mb["critic_loss"])
    assert any(not np.array_equal(x, y) for x, y in zip(leaves(a.state.policy_params), leaves(c.state.policy_params)))
    assert a.num_updates == 4


def test_scan_of_k_updates_equals_k_single_updates():
    batches = random_batch(4, 32, seed=2)
    a, b = make_learner(seed=5), make_learner(seed=5)
    a.step(batches)
    for i in range(4):
        b.step(Transitions(*(x[i:i + 1] for x in batches)))
    for x, y in zip(leaves(a.state), leaves(b.state), strict=True):
        np.testing.assert_allclose(x, y, rtol=1e-5, atol=1e-6)


def test_policy_average_leaves_training_alone_and_evaluates_the_moving_average():
    import dataclasses
    plain_config = dataclasses.replace(TINY, policy_average=0.0)  # the paper's: judge the last policy
    averaged_config = dataclasses.replace(TINY, policy_average=0.25, policy_average_fraction=0.0)
    plain, averaged = make_learner(seed=6, config=plain_config), make_learner(seed=6, config=averaged_config)
    start = leaves(averaged.policy_params)
    one = random_batch(1, 32, seed=3)
    plain.step(one)
    averaged.step(one)
    # the agent explores and learns with its current policy: bit for bit the plain learner's state
    for x, y in zip(leaves(plain.state[:9]), leaves(averaged.state[:9]), strict=True):
        np.testing.assert_array_equal(x, y)
    assert plain.evaluation_params is plain.policy_params and plain.state.average_policy_params is None
    # after one update the average is 3/4 of where the policy started and 1/4 of where it went
    for avg, p0, p1 in zip(leaves(averaged.evaluation_params), start, leaves(averaged.policy_params), strict=True):
        np.testing.assert_allclose(avg, 0.75 * p0 + 0.25 * p1, rtol=1e-6, atol=1e-7)
    assert any(not np.array_equal(a, p) for a, p in zip(leaves(averaged.evaluation_params),
                                                      leaves(averaged.policy_params)))
    with pytest.raises(ValueError, match="lacks a policy average"):
        averaged.set_state(plain.get_state())  # e.g. a checkpoint of a run without one
    # a checkpoint pickled before the field existed unpickles through the 9 values it has
    old = TrainingState(*plain.get_state()[:9])
    assert old.average_policy_params is None
    plain.set_state(old)
    with pytest.raises(ValueError, match="policy_average must be a rate"):
        SACConfig(policy_average=1.0)


def test_early_on_the_policy_average_spans_a_fraction_of_the_updates_so_far():
    """With policy_average_fraction f the rate after n updates is max(policy_average, 1/(1 + f n)):
    a short run's average is of its recent policies, not mostly of its random initial one."""
    import dataclasses
    config = dataclasses.replace(TINY, policy_average=0.25, policy_average_fraction=0.5)
    learner = make_learner(seed=6, config=config)
    policies = [leaves(learner.policy_params)]
    for seed in (3, 4, 5):
        learner.step(random_batch(1, 32, seed=seed))
        policies.append(leaves(learner.policy_params))
    # rates 1/1.5, 1/2, 1/2.5: all still above the floor policy_average = 0.25
    expected = policies[0]
    for rate, policy in zip((1 / 1.5, 1 / 2.0, 1 / 2.5), policies[1:]):
        expected = [(1 - rate) * e + rate * p for e, p in zip(expected, policy)]
    for avg, e in zip(leaves(learner.evaluation_params), expected, strict=True):
        np.testing.assert_allclose(avg, e, rtol=1e-5, atol=1e-6)
    # a long run ends on policy_average itself: 1 / (1 + 0.1 * 1e6) < 1e-4
    from agents.sac.learning import average_rate
    averaged = SACConfig(policy_average=1e-4)
    assert float(average_rate(averaged, 1_000_000)) == pytest.approx(1e-4)
    assert float(average_rate(averaged, 15_000)) == pytest.approx(1 / 1501)
    assert average_rate(dataclasses.replace(averaged, policy_average_fraction=0.0), 10) == 1e-4
    with pytest.raises(ValueError, match="policy_average_fraction must be in"):
        SACConfig(policy_average_fraction=-0.1)


def test_pre_tanh_penalty_pulls_the_policy_mean_out_of_saturation():
    """A policy whose pre-tanh mean sits deep in the tanh's flat part (here pushed there by a
    large output bias) gets almost no gradient from the critic; the penalty brings it back."""
    import dataclasses
    networks = make_networks(OBS, ACT, TINY.hidden_sizes)
    batches = random_batch(8, 32, seed=4)
    obs = batches.obs[0]

    def mean_magnitude(config):
        learner = SACLearner(networks, config, jax.random.PRNGKey(7))
        params = jax.tree_util.tree_map(np.array, learner.policy_params)
        params["mean"]["b"][:] = 3.0  # pre-tanh means near 3: tanh' = 0.01
        learner.set_state(learner.get_state()._replace(policy_params=params))
        for _ in range(5):
            learner.step(batches)
        mean, _ = networks.policy_apply(learner.policy_params, obs)
        return float(np.mean(np.abs(mean)))

    plain = mean_magnitude(dataclasses.replace(TINY, policy_average=0.0, pre_tanh_penalty=0.0))
    penalised = mean_magnitude(dataclasses.replace(TINY, policy_average=0.0, pre_tanh_penalty=1.0))
    assert plain > 2.0 and penalised < plain - 0.2, (penalised, plain)  # measured: 2.51 and 2.14
    with pytest.raises(ValueError, match="pre_tanh_penalty must be"):
        SACConfig(pre_tanh_penalty=-1.0)


def test_temperature_rises_when_entropy_is_below_target():
    config = SACConfig(**{**TINY.to_dict(), "target_entropy": 100.0, "hidden_sizes": (32, 32)})
    learner = make_learner(config=config)
    before = float(np.exp(learner.state.log_alpha))
    for i in range(5):
        learner.step(random_batch(4, 32, seed=i))
    assert float(np.exp(learner.state.log_alpha)) > before


def test_tanh_gaussian_log_prob_matches_change_of_variables():
    u = np.array([[-3.0, 0.1, 8.0]], np.float32)
    mean, log_std = np.zeros_like(u), np.full_like(u, -0.5)
    sigma = np.exp(-0.5)
    gauss = -0.5 * (u / sigma) ** 2 - np.log(sigma) - 0.5 * np.log(2 * np.pi)
    expected = np.sum(gauss - np.log(1 - np.tanh(u.astype(np.float64)) ** 2 + 1e-30), axis=-1)
    np.testing.assert_allclose(np.asarray(tanh_gaussian_log_prob(u, mean, log_std)), expected, rtol=1e-4)


def test_action_adapter_maps_policy_box_onto_asymmetric_bounds():
    spec = specs.BoundedArray((3,), np.float64, minimum=[-0.1, -0.02, 0.0], maximum=[0.08, 0.05, 0.3])
    adapter = ActionAdapter(spec)
    np.testing.assert_allclose(adapter.to_env([-1, -1, -1]), spec.minimum)
    np.testing.assert_allclose(adapter.to_env([1, 1, 1]), spec.maximum)
    x = np.array([0.3, -0.7, 0.9])
    np.testing.assert_allclose(adapter.to_policy(adapter.to_env(x)), x, atol=1e-6)
    with pytest.raises(ValueError, match="BoundedArray"):
        ActionAdapter(specs.Array((3,), np.float64))


def test_actor_stays_in_bounds_and_rejects_nan():
    spec = specs.BoundedArray((ACT,), np.float64, minimum=-0.1, maximum=0.08)
    learner = make_learner()
    actor = Actor(learner.networks, ActionAdapter(spec), learner.policy_params, key=jax.random.PRNGKey(1))
    acts = np.array([actor.select_action(np.random.default_rng(i).normal(size=OBS).astype(np.float32) * 10)
                     for i in range(50)])
    assert acts.min() >= -0.1 and acts.max() <= 0.08 and acts.std() > 0
    det = Actor(learner.networks, ActionAdapter(spec), learner.policy_params, deterministic=True)
    obs = np.ones(OBS, np.float32)
    np.testing.assert_array_equal(det.select_action(obs), det.select_action(obs))
    with pytest.raises(ValueError, match="non-finite"):
        actor.select_action(np.full(OBS, np.nan, np.float32))


def test_correlated_exploration_noise_follows_an_ar1_process_with_the_policys_spread():
    """noise_correlation rho: the standardised exploration noise (pre-tanh sample minus mean, over
    the std) of successive steps correlates at about rho and keeps unit variance; 0 is plain SAC's
    white noise (lag-1 correlation near 0). The same observation every step, so only noise moves."""
    learner = make_learner()
    obs = np.full(OBS, 0.2, np.float32)
    mean, log_std = (np.asarray(x[0]) for x in learner.networks.policy_apply(learner.policy_params, obs[None]))
    lag1, spread = {}, {}
    for rho in (0.0, 0.95):
        actor = Actor(learner.networks, ActionAdapter(specs.BoundedArray((ACT,), np.float64, -1.0, 1.0)),
                      learner.policy_params, key=jax.random.PRNGKey(3))
        actor.noise_correlation = rho
        u = np.arctanh(np.clip([actor.policy_action(obs) for _ in range(3000)], -0.999999, 0.999999))
        eps = (u - mean) / np.exp(log_std)
        lag1[rho] = float(np.mean([np.corrcoef(eps[:-1, i], eps[1:, i])[0, 1] for i in range(ACT)]))
        spread[rho] = float(eps.std())
    assert abs(lag1[0.0]) < 0.1 and 0.9 < lag1[0.95] < 0.99, lag1
    assert 0.8 < spread[0.0] < 1.2 and 0.6 < spread[0.95] < 1.4, spread
    from agents.curriculum import LessonSettings
    with pytest.raises(ValueError, match="exploration_noise_correlation must be in"):
        LessonSettings(exploration_noise_correlation=1.0)


def test_action_anchor_keeps_the_deterministic_action_near_zero():
    """A residual policy's anchor: on the same batches, a weighted penalty on the squared
    deterministic action keeps it far closer to 0 (the base controller) than plain SAC's actor."""
    import dataclasses
    obs = random_batch(1, 256, seed=9).obs[0]
    magnitude = {}
    for weight in (0.0, 5.0):
        learner = make_learner(config=dataclasses.replace(TINY, action_anchor=weight))
        for i in range(40):
            learner.step(random_batch(4, 32, seed=i))
        magnitude[weight] = float(np.mean(np.abs(learner.networks.mode(learner.policy_params, obs))))
    assert magnitude[5.0] < 0.5 * magnitude[0.0], magnitude
    with pytest.raises(ValueError, match="action_anchor"):
        SACConfig(action_anchor=-1.0)


def test_replay_flattens_dict_observations_and_wraps():
    obs_spec = {"b": specs.Array((2,), np.float64), "a": specs.Array((), np.float64)}
    flatten = ObservationFlattener(obs_spec)
    np.testing.assert_array_equal(flatten({"a": 3.0, "b": np.array([1.0, 2.0])}), [1, 2, 3])  # spec order
    replay = ReplayBuffer(3, 1, capacity=4, seed=0)
    for i in range(6):
        replay.add(np.full(3, i), [0.5], float(i), 1.0, np.full(3, i + 1))
    assert len(replay) == 4 and replay.insert_index == 2
    assert sorted(replay.reward.tolist()) == [2, 3, 4, 5]
    batch = replay.sample_stack(2, 5)
    assert batch.obs.shape == (2, 5, 3) and set(batch.reward.ravel()) <= {2, 3, 4, 5}
    np.testing.assert_array_equal(batch.next_obs[..., 0], batch.obs[..., 0] + 1)


@pytest.mark.parametrize("hidden, zero_mean, gain", [((16, 16), False, 0.0), ((8, 8, 8), True, 0.0),
                                                     ((16, 16), False, 100.0)])
def test_the_actors_numpy_forward_pass_is_the_networks(hidden, zero_mean, gain):
    """The actor acts with numpy on the host; its mean and spread must be the haiku network's, or
    training would explore with and evaluation judge another policy than the one learned (with fine
    inputs too)."""
    networks = make_networks(OBS, ACT, hidden, zero_policy_mean=zero_mean, fine_input_gain=gain)
    params = networks.policy_init(jax.random.PRNGKey(5))
    obs = np.random.default_rng(0).normal(size=(4, OBS)).astype(np.float32) * 3
    mean, log_std = (np.asarray(x) for x in networks.policy_apply(params, obs))
    host = jax.tree_util.tree_map(np.asarray, params)
    for row in range(4):
        host_mean, host_log_std = networks.host_policy_apply(host, obs[row])
        np.testing.assert_allclose(host_mean, mean[row], rtol=1e-5, atol=1e-6)
        np.testing.assert_allclose(host_log_std, log_std[row], rtol=1e-5, atol=1e-6)
    actor = Actor(networks, ActionAdapter(specs.BoundedArray((ACT,), np.float64, -1.0, 1.0)), params,
                  deterministic=True)
    np.testing.assert_allclose(actor.policy_action(obs[0]), np.tanh(mean[0]), rtol=1e-5, atol=1e-6)
    assert not zero_mean or np.all(actor.policy_action(obs[1]) == 0.0)


def test_fine_inputs_resolve_small_errors_that_plain_inputs_leave_near_zero():
    """With fine_input_gain g the networks read tanh(g x) beside each input x: two observations 5 mm
    apart (in metres) differ by about 0.005 in the plain inputs and by tanh(0.5) - tanh(0) = 0.46 at
    g = 100 in the fine ones; the first layer widens to read both."""
    plain, fine = (make_networks(OBS, ACT, (16, 16), fine_input_gain=g) for g in (0.0, 100.0))
    assert plain.policy_init(jax.random.PRNGKey(0))["policy_torso/~/linear_0"]["w"].shape == (OBS, 16)
    params = fine.policy_init(jax.random.PRNGKey(0))
    assert params["policy_torso/~/linear_0"]["w"].shape == (2 * OBS, 16)
    assert fine.q_init(jax.random.PRNGKey(0))["critic/~/linear_0"]["w"].shape == (2, 2 * OBS + ACT, 16)
    first = jax.tree_util.tree_map(np.asarray, params)["policy_torso/~/linear_0"]
    near, off = np.zeros(OBS, np.float32), np.full(OBS, 0.005, np.float32)
    seen = [np.concatenate([x, np.tanh(100.0 * x)]) for x in (near, off)]
    assert np.abs(seen[1] - seen[0])[OBS:].min() == pytest.approx(np.tanh(0.5), rel=1e-5)
    moved = np.abs((seen[1] - seen[0]) @ first["w"]).sum()
    assert moved > 20 * np.abs((off - near) @ first["w"][:OBS]).sum()
    with pytest.raises(ValueError, match="fine_input_gain must be a number from 0"):
        SACConfig(fine_input_gain=-1.0)


def test_named_fine_inputs_read_only_the_entries_they_name_each_at_its_gain():
    """fine_inputs ("key=gain" items) resolve to flat entries of the robot's own observation: the error
    to the target at 100 and the attitude's at 30 add three inputs, each tanh(gain x entry), and leave
    the joint angles and tendon states as they are; a misnamed key or gain is refused, naming it."""
    import robostrich_suite
    flattener = ObservationFlattener(robostrich_suite.load("robostrich", "lesson3").observation_spec())
    config = SACConfig(fine_inputs=("to_target=100", "attitude_error=30"))
    start = sum(s for k, s in zip(flattener.keys, flattener.sizes) if k in flattener.keys[:4])
    entries = config.fine_input_entries(flattener.keys, flattener.sizes)
    assert SACConfig(fine_inputs="to_target=100, attitude_error=30") == config  # one text, as the flag takes it
    assert flattener.keys[4:6] == ("to_target", "attitude_error")
    assert entries == ((start, 100.0), (start + 1, 100.0), (start + 2, 30.0))
    networks = make_networks(flattener.size, 9, (16, 16), fine_input_entries=entries)
    params = jax.tree_util.tree_map(np.asarray, networks.policy_init(jax.random.PRNGKey(0)))
    assert params["policy_torso/~/linear_0"]["w"].shape == (flattener.size + 3, 16)
    obs = np.zeros(flattener.size, np.float32)
    obs[start:start + 3] = 0.005, -0.01, np.radians(2.0)  # 5 mm, -1 cm, 2 deg
    seen = np.concatenate([obs, np.tanh(obs[start:start + 3] * [100.0, 100.0, 30.0])]).astype(np.float32)
    assert seen[-3:] == pytest.approx([np.tanh(0.5), -np.tanh(1.0), np.tanh(30 * np.radians(2.0))], rel=1e-5)
    h = seen
    for i in range(2):
        h = np.maximum(h @ params[f"policy_torso/~/linear_{i}"]["w"] + params[f"policy_torso/~/linear_{i}"]["b"], 0)
    mean = h @ params["mean"]["w"] + params["mean"]["b"]
    np.testing.assert_allclose(networks.host_policy_apply(params, obs)[0], mean, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(np.asarray(networks.policy_apply(params, obs[None])[0])[0], mean, rtol=1e-5, atol=1e-6)
    for bad, words in ((("gaze=3",), r"names \['gaze'\], which the observation lacks \(it has \['head_position'"),
                       (("to_target",), "'to_target' is not key=gain"), (("to_target=-1",), "not key=gain"),
                       (("to_target=1", "to_target=2"), "names 'to_target' twice")):
        with pytest.raises(ValueError, match=words):
            SACConfig(fine_inputs=bad).fine_input_entries(flattener.keys, flattener.sizes)
