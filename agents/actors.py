"""A generic actor: flattened observation in, environment action out.

The policy network works in [-1, 1]^|A|; `ActionAdapter` maps that box onto
the BoundedArray spec (e.g. actuator inputs in their own units) and back.
"""
import jax
import numpy as np


class ActionAdapter:
    """Affine map between the policy's [-1, 1] box and the environment's bounds."""

    def __init__(self, action_spec):
        shape = action_spec.shape
        if not hasattr(action_spec, "minimum") or not hasattr(action_spec, "maximum"):
            raise ValueError("the action spec must be a BoundedArray with minimum and maximum")
        self.low = np.broadcast_to(np.asarray(action_spec.minimum, np.float64), shape).copy()
        self.high = np.broadcast_to(np.asarray(action_spec.maximum, np.float64), shape).copy()
        if not (np.all(np.isfinite(self.low)) and np.all(np.isfinite(self.high)) and np.all(self.high > self.low)):
            raise ValueError(f"action bounds must be finite with maximum > minimum, got {self.low} .. {self.high}")
        self.dtype = action_spec.dtype
        self.size = int(np.prod(shape))
        self._half_range = 0.5 * (self.high - self.low)
        self._mid = 0.5 * (self.high + self.low)

    def to_env(self, policy_action, flat_obs=None) -> np.ndarray:
        """The environment action for ``policy_action``; ``flat_obs`` is unused here (see
        `ResidualAdapter`, whose map depends on the observation)."""
        return (self._mid + self._half_range * np.asarray(policy_action, np.float64)).astype(self.dtype)

    def to_policy(self, env_action) -> np.ndarray:
        return ((np.asarray(env_action, np.float64) - self._mid) / self._half_range).astype(np.float32)


class ResidualAdapter(ActionAdapter):
    """The policy corrects a base controller: env action = base(obs) + scale x half-range x a, clipped.

    Residual RL (Johannink et al. 2019, Silver et al. 2018): the base is a controller that gets
    near the goal without feedback (a table of stored actions, say). The policy only learns the
    correction, within ``scale`` (a fraction of each action dimension's half-range) of the base;
    a zero policy output is the base itself. Hindsight goal relabelling does not mix with it (a new goal changes the base
    action, so the stored residual no longer means what it did).
    """

    def __init__(self, action_spec, base, scale: float):
        super().__init__(action_spec)
        if not (np.isfinite(scale) and 0.0 < scale <= 2.0):
            raise ValueError(f"residual scale must be in (0, 2] (a fraction of the action half-range), got {scale}")
        self.base = base
        self.scale = float(scale)

    def to_env(self, policy_action, flat_obs=None) -> np.ndarray:
        if flat_obs is None:
            raise ValueError("a residual policy needs the observation to compute its base action")
        base = np.asarray(self.base.select_action(flat_obs), np.float64)
        action = base + self.scale * self._half_range * np.asarray(policy_action, np.float64)
        return np.clip(action, self.low, self.high).astype(self.dtype)

    def to_policy(self, env_action) -> np.ndarray:
        raise NotImplementedError("a residual action depends on the observation; there is no fixed inverse")


class Actor:
    """Runs the policy for one observation per call, on the host in numpy.

    Stochastic (`deterministic=False`) samples a ~ pi(.|s) for training;
    deterministic returns tanh(mean) for evaluation. One observation at a time,
    numpy does the small network's arithmetic in less time than a jitted call
    takes to dispatch, so acting never waits on JAX (only `update` converts the
    learner's new parameters).
    """

    def __init__(self, networks, adapter: ActionAdapter, params, key=None, deterministic=False):
        """`networks`: anything with `host_policy_apply(numpy params, obs) -> (mean, log_std)` for one
        observation (e.g. agents.sac.SACNetworks); ``key``: a JAX PRNG key that seeds the sampling."""
        self.adapter = adapter
        self.deterministic = deterministic
        self._apply = networks.host_policy_apply
        self.key = jax.random.PRNGKey(0) if key is None else key
        self.rng = self.rng_from_key(self.key)  # the sampling's own stream (a checkpoint keeps its state)
        # Exploration noise correlated over control steps: the Gaussian's standard normal draw
        # follows eps' = rho eps + sqrt(1 - rho^2) n (stationary, unit variance) instead of a
        # fresh n every step (rho = 0: plain SAC).
        self.noise_correlation = 0.0
        self.noise = None  # eps, (action size,); None until the first correlated step
        self.update(params)

    @staticmethod
    def rng_from_key(key) -> np.random.Generator:
        """The numpy generator a JAX key seeds (a checkpoint written before the actor kept one resumes with it)."""
        return np.random.default_rng(np.asarray(key, np.uint32).ravel().tolist())

    def update(self, params):
        self.params = params
        self._host_params = jax.tree_util.tree_map(np.asarray, params)

    def policy_action(self, flat_obs: np.ndarray) -> np.ndarray:
        """Action in [-1, 1]; raises if the network produced NaN/inf."""
        obs = np.asarray(flat_obs, np.float32)
        mean, log_std = self._apply(self._host_params, obs, not self.deterministic)
        if self.deterministic:
            action = np.tanh(mean)
        else:
            fresh = self.rng.standard_normal(mean.shape, np.float32)
            if self.noise_correlation > 0.0:
                if self.noise is None:  # start from the process' stationary distribution
                    self.noise = self.rng.standard_normal(mean.shape, np.float32)
                rho = np.float32(self.noise_correlation)
                self.noise = rho * self.noise + np.sqrt(np.float32(1.0) - rho * rho) * fresh
                fresh = self.noise
            action = np.tanh(mean + np.exp(log_std) * fresh)
        if not np.all(np.isfinite(action)):
            raise ValueError(f"policy produced a non-finite action {action}; observation was {flat_obs}")
        return action

    def select_action(self, flat_obs: np.ndarray) -> np.ndarray:
        return self.adapter.to_env(self.policy_action(flat_obs), flat_obs)
