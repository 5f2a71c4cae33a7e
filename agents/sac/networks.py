"""Haiku networks of SAC: a tanh-Gaussian policy and twin Q critics.

The policy acts in [-1, 1]^|A|; mapping to the environment's bounds is the
actor's job (agents/actors.py), so the networks never see physical units.
"""
import dataclasses
import functools
from typing import Callable, Sequence

import haiku as hk
import jax
import jax.numpy as jnp
import numpy as np

_LOG_2 = float(np.log(2.0))
# The twin critics' module name: their parameters stacked, [2, ...] (``q_init``).
CRITIC = "critic"


@dataclasses.dataclass(frozen=True)
class SACNetworks:
    """Pure functions plus initialisers; parameters live in the learner's state."""

    policy_init: Callable
    policy_apply: Callable  # (params, obs) -> (mean, log_std)
    host_policy_apply: Callable  # (numpy params, one obs, with_log_std) -> the same in numpy, for acting
    q_init: Callable  # key -> the twin critics' parameters, each leaf stacked [2, ...]
    q_apply: Callable  # (params, obs, action) -> (q1, q2), each shape [B]
    obs_size: int
    action_size: int

    def sample(self, params, obs, key):
        """Reparameterised sample a = tanh(u) and its log-probability (eq. 7)."""
        mean, log_std = self.policy_apply(params, obs)
        u = mean + jnp.exp(log_std) * jax.random.normal(key, mean.shape, mean.dtype)
        return jnp.tanh(u), tanh_gaussian_log_prob(u, mean, log_std)

    def mode(self, params, obs):
        """Deterministic action used in evaluation."""
        mean, _ = self.policy_apply(params, obs)
        return jnp.tanh(mean)


def tanh_gaussian_log_prob(u, mean, log_std):
    """log pi(tanh(u)); the Jacobian term uses log(1 - tanh^2 u) = 2(log2 - u - softplus(-2u)), stable for large |u|."""
    z = (u - mean) * jnp.exp(-log_std)
    gaussian = -0.5 * z ** 2 - log_std - 0.5 * jnp.log(2.0 * jnp.pi)
    log_det = 2.0 * (_LOG_2 - u - jax.nn.softplus(-2.0 * u))
    return jnp.sum(gaussian - log_det, axis=-1)


def make_networks(obs_size: int, action_size: int, hidden_sizes: Sequence[int] = (256, 256),
                  log_std_min: float = -5.0, log_std_max: float = 2.0,
                  critic_layer_norm: bool = False, zero_policy_mean: bool = False,
                  fine_input_gain: float = 0.0, fine_input_entries: Sequence = ()) -> SACNetworks:
    """Cached: equal arguments give the same object, so learners and actors share compiled functions.

    ``critic_layer_norm`` normalises each hidden layer of the critics (before the ReLU):
    it keeps Q-values' gradients well scaled when returns are large and lets a critic
    learn fast at one update per step (Ball et al. 2023, "RLPD").
    ``zero_policy_mean`` starts the policy's mean head at zero weights, so the initial
    deterministic action is exactly 0: a residual policy then starts as its base controller.
    ``fine_input_gain`` and ``fine_input_entries`` ((index, gain), ...): fine inputs
    (``_fine_inputs``).
    """
    entries = tuple((int(i), float(g)) for i, g in fine_input_entries)
    return _make_networks(int(obs_size), int(action_size), tuple(int(h) for h in hidden_sizes),
                          float(log_std_min), float(log_std_max), bool(critic_layer_norm), bool(zero_policy_mean),
                          float(fine_input_gain), entries)


def _normalised_critic(x, hidden_sizes, name: str):
    """Linear -> LayerNorm -> ReLU per hidden layer, then a linear Q head."""
    for i, size in enumerate(hidden_sizes):
        x = hk.Linear(size, name=f"{name}_linear_{i}")(x)
        x = hk.LayerNorm(axis=-1, create_scale=True, create_offset=True, name=f"{name}_norm_{i}")(x)
        x = jax.nn.relu(x)
    return hk.Linear(1, name=f"{name}_head")(x)


def _squashed_log_std(raw, log_std_min, log_std_max, tanh):
    """log_std squashed smoothly into its range (as CleanRL) rather than clipped, which would lose its gradient."""
    return log_std_min + 0.5 * (log_std_max - log_std_min) * (tanh(raw) + 1.0)


def _fine_inputs(obs, gain: float, index, gains, np_like):
    """The observation, followed by tanh(gain x observation) where ``gain`` is not 0, then by
    tanh(gains[j] x observation[index[j]]) where ``index`` is not None: an error in metres or radians
    reads a few thousandths near its goal, where a precise task is decided, and tanh(g x) spreads
    those thousandths over an input of order one (``np_like``: numpy on the host, jax.numpy in the
    networks)."""
    parts = [obs]
    if gain:
        parts.append(np_like.tanh(np_like.float32(gain) * obs))
    if index is not None:
        parts.append(np_like.tanh(obs[..., index] * gains))
    return parts[0] if len(parts) == 1 else np_like.concatenate(parts, axis=-1)


def _twin_critics(hidden_sizes, layer_norm: bool, with_fine_inputs, obs_size: int, action_size: int):
    """(q_init, q_apply) of the twin critics: one critic's parameters stacked on a leading axis of 2
    and applied by vmap, fewer and larger operations than two networks."""

    def critic_fn(x):
        if layer_norm:
            return _normalised_critic(x, hidden_sizes, CRITIC)[..., 0]
        return hk.nets.MLP(hidden_sizes + (1,), activation=jax.nn.relu, name=CRITIC)(x)[..., 0]

    critic = hk.without_apply_rng(hk.transform(critic_fn))

    def inputs(obs, action):
        return jnp.concatenate([with_fine_inputs(obs), action], axis=-1)

    def q_init(key):
        x = inputs(jnp.zeros((1, obs_size), jnp.float32), jnp.zeros((1, action_size), jnp.float32))
        return jax.vmap(lambda k: critic.init(k, x))(jax.random.split(key, 2))

    def q_apply(params, obs, action):
        q = jax.vmap(critic.apply, in_axes=(0, None))(params, inputs(obs, action))
        return q[0], q[1]

    return q_init, q_apply


@functools.lru_cache(maxsize=None)
def _make_networks(obs_size, action_size, hidden_sizes, log_std_min, log_std_max,
                   critic_layer_norm=False, zero_policy_mean=False, fine_input_gain=0.0,
                   fine_input_entries=()) -> SACNetworks:
    if any(not 0 <= i < obs_size for i, _ in fine_input_entries):
        raise ValueError(f"fine input entries {fine_input_entries} lie outside the observation's {obs_size} entries")

    # built once: the host policy reads them at every control step
    index = np.array([i for i, _ in fine_input_entries]) if fine_input_entries else None
    gains = np.array([g for _, g in fine_input_entries], np.float32)

    def with_fine_inputs(obs, np_like=jnp):
        return _fine_inputs(obs, fine_input_gain, index, gains, np_like)

    def policy_fn(obs):
        obs = with_fine_inputs(obs)
        h = hk.nets.MLP(hidden_sizes, activation=jax.nn.relu, activate_final=True, name="policy_torso")(obs)
        mean_init = hk.initializers.Constant(0.0) if zero_policy_mean else None
        mean = hk.Linear(action_size, w_init=mean_init, name="mean")(h)
        raw = hk.Linear(action_size, name="log_std")(h)
        return mean, _squashed_log_std(raw, log_std_min, log_std_max, jnp.tanh)

    def host_policy_apply(params, obs, with_log_std: bool = True):
        """policy_fn in numpy: acting on one observation at a time, a jitted call's dispatch costs
        several times the arithmetic of a small network (tools/benchmark_learner.py measures both)."""
        h = with_fine_inputs(obs, np)
        for i in range(len(hidden_sizes)):
            layer = params[f"policy_torso/~/linear_{i}"]
            h = np.maximum(h @ layer["w"] + layer["b"], 0.0)
        mean = h @ params["mean"]["w"] + params["mean"]["b"]
        if not with_log_std:
            return mean, None
        raw = h @ params["log_std"]["w"] + params["log_std"]["b"]
        return mean, _squashed_log_std(raw, log_std_min, log_std_max, np.tanh)

    policy = hk.without_apply_rng(hk.transform(policy_fn))
    dummy_obs = jnp.zeros((1, obs_size), jnp.float32)
    q_init, q_apply = _twin_critics(hidden_sizes, critic_layer_norm, with_fine_inputs, obs_size, action_size)
    return SACNetworks(
        policy_init=lambda key: policy.init(key, dummy_obs),
        policy_apply=policy.apply,
        host_policy_apply=host_policy_apply,
        q_init=q_init,
        q_apply=q_apply,
        obs_size=obs_size,
        action_size=action_size,
    )
