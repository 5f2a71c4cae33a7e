"""Wires networks, learner, replay, actor and loop for one environment's specs."""
import jax

from agents.actors import ActionAdapter, Actor, ResidualAdapter
from agents.goals import GoalRelabeler
from agents.loop import EnvironmentLoop
from agents.replay import ObservationFlattener, ReplayBuffer
from agents.sac.config import SACConfig
from agents.sac.learning import SACLearner
from agents.sac.networks import make_networks


class SACBuilder:
    """Everything an agent needs, built from an environment's specs and a seed.

    The same builder output is reused across lessons: only the environment
    changes, so parameters, optimiser states, temperature and replay carry over.
    """

    def __init__(self, config: SACConfig):
        self.config = config

    def make_adapter(self, env, flattener, residual=None) -> ActionAdapter:
        """Policy box [-1, 1]^|A| <-> the environment's actions; with ``residual`` = (base policy
        factory, scale) the policy's output is a correction of ``base(flattener)``'s action, within
        ``scale`` of each action's half-range (agents/actors.ResidualAdapter)."""
        action_spec = env.action_spec()
        if len(action_spec.shape) != 1:
            raise ValueError(f"expected a flat action spec, got shape {action_spec.shape}")
        if residual is not None:
            base_policy, scale = residual
            if not 0.0 < scale <= 2.0:
                raise ValueError(f"a residual's scale must be in (0, 2], got {scale}")
            if self.config.her_ratio > 0:
                raise ValueError("a residual policy and her_ratio do not mix: a relabelled goal changes the base "
                                 "policy's action, so the stored residual would no longer mean what it did "
                                 "(her_ratio=0, --her-ratio 0)")
            return ResidualAdapter(action_spec, base_policy(flattener), scale)
        return ActionAdapter(action_spec)

    def make_networks(self, flattener: ObservationFlattener, action_size: int, residual: bool = False):
        """The networks for ``flattener``'s observations; a residual policy's mean starts at zero (the base's action)."""
        cfg = self.config
        return make_networks(flattener.size, action_size, cfg.hidden_sizes, cfg.log_std_min, cfg.log_std_max,
                             cfg.critic_layer_norm, zero_policy_mean=residual, fine_input_gain=cfg.fine_input_gain,
                             fine_input_entries=cfg.fine_input_entries(flattener.keys, flattener.sizes))

    def make_learner(self, networks, key) -> SACLearner:
        return SACLearner(networks, self.config, key)

    def make_replay(self, env, flattener, action_size: int, seed: int):
        """The replay, and the goal relabeler when it keeps achieved goals (HER, reward recomputation)."""
        cfg = self.config
        relabeler = GoalRelabeler.for_environment(env, flattener) if cfg.uses_goals else None
        goal_width = relabeler.reached_size if relabeler is not None else 0
        return ReplayBuffer(flattener.size, action_size, cfg.max_replay_size, seed=seed, goal_width=goal_width,
                            repeat=cfg.action_repeat)

    def make_actor(self, networks, adapter, params, key=None, deterministic: bool = False) -> Actor:
        return Actor(networks, adapter, params, key=key, deterministic=deterministic)

    def make_components(self, env, seed: int, residual=None, episode_probe=None) -> EnvironmentLoop:
        """All of the above for `env`, wired into the loop that owns them (what a lesson plan runs);
        ``residual``: see make_adapter; ``episode_probe(env)``: metrics an episode's record gets from its last state."""
        flattener = ObservationFlattener(env.observation_spec())
        adapter = self.make_adapter(env, flattener, residual)
        networks = self.make_networks(flattener, adapter.size, residual is not None)
        learner_key, actor_key = jax.random.split(jax.random.PRNGKey(seed))
        learner = self.make_learner(networks, learner_key)
        replay = self.make_replay(env, flattener, adapter.size, seed)
        actor = self.make_actor(networks, adapter, learner.policy_params, key=actor_key)
        return EnvironmentLoop(env, actor, replay, learner, self.config, flattener, seed=seed,
                               episode_probe=episode_probe)

    @staticmethod
    def make_eval_actor(loop: EnvironmentLoop) -> Actor:
        """The deterministic policy a trained agent is judged by (its average, if it keeps one)."""
        return Actor(loop.learner.networks, loop.actor.adapter, loop.learner.evaluation_params,
                     deterministic=True)
