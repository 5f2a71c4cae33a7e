"""The SAC learner: critics, actor, temperature and Polyak targets in one jitted function.

`SACLearner.step(batches)` runs `batches.reward.shape[0]` updates inside a
single `lax.scan`, so Python is entered once per call, not once per update.
"""
import dataclasses
import functools
from typing import NamedTuple, Optional

import jax
import jax.numpy as jnp
import numpy as np
import optax

from agents.sac.config import SACConfig
from agents.sac.networks import SACNetworks
from agents.types import Transitions  # noqa: F401  (re-exported: the learner consumes them)


class TrainingState(NamedTuple):
    policy_params: dict
    q_params: dict
    target_q_params: dict
    policy_opt_state: tuple
    q_opt_state: tuple
    log_alpha: jnp.ndarray
    alpha_opt_state: tuple
    key: jnp.ndarray
    steps: jnp.ndarray  # number of gradient updates done
    # Exponential moving average of policy_params (SACConfig.policy_average > 0), else None.
    average_policy_params: Optional[dict] = None


def make_optimizers(config: SACConfig):
    """One Adam per parameter group, as in Algorithm 1 (lambda_Q, lambda_pi, lambda_alpha); the
    networks' on one vector each (``optax.flatten``): one update of a few large arrays instead of
    many small ones."""
    return (optax.flatten(optax.adam(config.learning_rate)), optax.flatten(optax.adam(config.learning_rate)),
            optax.adam(config.learning_rate))


def init_state(networks: SACNetworks, config: SACConfig, key) -> TrainingState:
    policy_opt, q_opt, alpha_opt = make_optimizers(config)
    key, k_pi, k_q = jax.random.split(key, 3)
    policy_params = networks.policy_init(k_pi)
    q_params = networks.q_init(k_q)
    log_alpha = jnp.asarray(np.log(config.init_temperature), jnp.float32)
    return TrainingState(
        policy_params=policy_params,
        q_params=q_params,
        target_q_params=jax.tree_util.tree_map(jnp.copy, q_params),
        policy_opt_state=policy_opt.init(policy_params),
        q_opt_state=q_opt.init(q_params),
        log_alpha=log_alpha,
        alpha_opt_state=alpha_opt.init(log_alpha),
        key=key,
        steps=jnp.zeros((), jnp.int32),
        average_policy_params=(jax.tree_util.tree_map(jnp.copy, policy_params)
                               if config.policy_average > 0 else None),
    )


def average_rate(config: SACConfig, updates):
    """The policy average's rate after ``updates`` gradient steps (``SACConfig.policy_average``
    and ``policy_average_fraction``): at least ``policy_average``, and early on about
    1 / (fraction of the updates so far), so that a short run's average is of its recent
    policies, not of its random initial one."""
    if config.policy_average_fraction == 0.0:
        return config.policy_average
    return jnp.maximum(config.policy_average, 1.0 / (1.0 + config.policy_average_fraction * updates))


def make_loss_fns(networks: SACNetworks, config: SACConfig):
    """(critic_loss, actor_loss, alpha_loss): eqs. 6, 7 and 8 of SAC with this config's additions."""
    target_entropy = config.resolved_target_entropy(networks.action_size)

    def critic_loss(q_params, target_q_params, policy_params, alpha, batch, key):
        next_action, next_log_prob = networks.sample(policy_params, batch.next_obs, key)
        tq1, tq2 = networks.q_apply(target_q_params, batch.next_obs, next_action)
        next_v = jnp.minimum(tq1, tq2) - alpha * next_log_prob  # soft V (eq. 3)
        target = config.reward_scale * batch.reward + config.discount * batch.discount * next_v
        target = jax.lax.stop_gradient(target)
        q1, q2 = networks.q_apply(q_params, batch.obs, batch.action)
        loss = 0.5 * (jnp.mean((q1 - target) ** 2) + jnp.mean((q2 - target) ** 2))  # eq. 6
        return loss, jnp.mean(q1)

    def actor_loss(policy_params, q_params, alpha, obs, key):
        action, log_prob = networks.sample(policy_params, obs, key)
        q1, q2 = networks.q_apply(q_params, obs, action)
        loss = jnp.mean(alpha * log_prob - jnp.minimum(q1, q2))  # eq. 7
        if config.action_anchor > 0:
            # Pull the deterministic action toward 0 (a residual policy's base), scaled by the
            # critic's magnitude as TD3+BC does, so the anchor means the same at any return scale.
            q_scale = jax.lax.stop_gradient(jnp.mean(jnp.abs(jnp.minimum(q1, q2)))) + 1e-6
            anchor = jnp.mean(networks.mode(policy_params, obs) ** 2)
            loss = loss + config.action_anchor * q_scale * anchor
        if config.pre_tanh_penalty > 0:
            mean, _ = networks.policy_apply(policy_params, obs)
            loss = loss + config.pre_tanh_penalty * jnp.mean(mean ** 2)
        return loss, log_prob

    def alpha_loss(log_alpha, log_prob):
        # eq. 8: raise alpha when the entropy -log_prob falls below the target.
        return jnp.mean(-jnp.exp(log_alpha) * jax.lax.stop_gradient(log_prob + target_entropy))

    return critic_loss, actor_loss, alpha_loss


def make_update_fn(networks: SACNetworks, config: SACConfig):
    """Returns update(state, batch) -> (state, metrics) for ONE gradient step (not jitted)."""
    policy_opt, q_opt, alpha_opt = make_optimizers(config)
    critic_loss, actor_loss, alpha_loss = make_loss_fns(networks, config)

    def update(state: TrainingState, batch: Transitions):
        key, k_critic, k_actor = jax.random.split(state.key, 3)
        alpha = jnp.exp(state.log_alpha)

        (c_loss, q_mean), q_grads = jax.value_and_grad(critic_loss, has_aux=True)(
            state.q_params, state.target_q_params, state.policy_params, alpha, batch, k_critic)
        q_updates, q_opt_state = q_opt.update(q_grads, state.q_opt_state, state.q_params)
        q_params = optax.apply_updates(state.q_params, q_updates)

        (a_loss, log_prob), pi_grads = jax.value_and_grad(actor_loss, has_aux=True)(
            state.policy_params, q_params, alpha, batch.obs, k_actor)
        pi_updates, policy_opt_state = policy_opt.update(pi_grads, state.policy_opt_state, state.policy_params)
        policy_params = optax.apply_updates(state.policy_params, pi_updates)

        t_loss, alpha_grad = jax.value_and_grad(alpha_loss)(state.log_alpha, log_prob)
        alpha_updates, alpha_opt_state = alpha_opt.update(alpha_grad, state.alpha_opt_state, state.log_alpha)
        log_alpha = optax.apply_updates(state.log_alpha, alpha_updates)

        target_q_params = optax.incremental_update(q_params, state.target_q_params, config.tau)
        average_policy_params = state.average_policy_params
        if average_policy_params is not None:
            average_policy_params = optax.incremental_update(
                policy_params, average_policy_params, average_rate(config, state.steps + 1))
        new_state = TrainingState(policy_params, q_params, target_q_params, policy_opt_state, q_opt_state,
                                  log_alpha, alpha_opt_state, key, state.steps + 1, average_policy_params)
        metrics = {"critic_loss": c_loss, "actor_loss": a_loss, "alpha_loss": t_loss,
                   "temperature": alpha, "entropy": -jnp.mean(log_prob), "q_mean": q_mean}
        return new_state, metrics

    return update


@functools.lru_cache(maxsize=None)
def _jitted_update_many(networks: SACNetworks, config: SACConfig):
    """One compiled function per (networks, config), shared by all learners that match."""
    update = make_update_fn(networks, config)

    def update_many(state, batches):
        state, metrics = jax.lax.scan(update, state, batches)
        return state, jax.tree_util.tree_map(jnp.mean, metrics)

    # The state's buffers are given to the update (donated): it writes the new state where the old
    # one was. An array a caller still views from numpy (an actor's parameters) is copied instead.
    return jax.jit(update_many, donate_argnums=0)


@functools.lru_cache(maxsize=None)
def _jitted_init_state(networks: SACNetworks, config: SACConfig):
    """init_state as one compiled function: run op by op, the networks' initialisers compile (or read
    from JAX's cache) about a hundred small programs; the values are the same bit for bit."""
    return jax.jit(functools.partial(init_state, networks, config))


class SACLearner:
    """Holds the training state; `step` runs a stack of updates in one jitted call."""

    def __init__(self, networks: SACNetworks, config: SACConfig, key):
        self.networks = networks
        self.config = config
        self._update_many = _jitted_update_many(networks, config)
        self.state = _jitted_init_state(networks, config)(key)

    def step(self, batches: Transitions) -> dict:
        """batches: arrays with a leading [num_updates, batch_size] shape. Returns mean metrics (floats)."""
        self.state, metrics = self._update_many(self.state, batches)
        return metrics

    def set_discount(self, discount: float) -> None:
        """Train on with another discount (a curriculum's per-lesson discount); the state carries over."""
        if discount != self.config.discount:
            self._retune(discount=float(discount))

    def set_target_entropy(self, target_entropy: float) -> None:
        """Train on toward another target entropy (a curriculum's per-lesson exploration)."""
        if target_entropy != self.config.resolved_target_entropy(self.networks.action_size):
            self._retune(target_entropy=float(target_entropy))

    def _retune(self, **fields) -> None:
        """Replace config fields the update is compiled with; the training state carries over."""
        self.config = dataclasses.replace(self.config, **fields)
        self._update_many = _jitted_update_many(self.networks, self.config)

    @property
    def policy_params(self):
        """What the agent explores with while it trains."""
        return self.state.policy_params

    @property
    def evaluation_params(self):
        """What a trained agent is evaluated and deployed with: the moving average of the policy
        (``SACConfig.policy_average``) where the config keeps one, else the policy itself."""
        average = self.state.average_policy_params
        return self.state.policy_params if average is None else average

    @property
    def num_updates(self) -> int:
        return int(self.state.steps)

    def get_state(self):
        """Numpy copy of the full state, for checkpoints."""
        return jax.tree_util.tree_map(np.asarray, self.state)

    def set_state(self, state):
        ref = jax.tree_util.tree_structure(self.state)
        if jax.tree_util.tree_structure(state) != ref:
            averaged = (self.state.average_policy_params is not None, state.average_policy_params is not None)
            if averaged[0] != averaged[1]:
                raise ValueError("learner state in checkpoint does not match this learner's structure: it "
                                 f"{'has' if averaged[1] else 'lacks'} a policy average (policy_average)")
            raise ValueError("learner state in checkpoint does not match this learner's structure")
        for a, b in zip(jax.tree_util.tree_leaves(self.state), jax.tree_util.tree_leaves(state)):
            if np.shape(a) != np.shape(b):
                raise ValueError(f"learner state shape mismatch: {np.shape(b)} in checkpoint, {np.shape(a)} expected")
        self.state = jax.tree_util.tree_map(jnp.asarray, state)
