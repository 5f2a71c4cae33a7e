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

    def make_adapter(self, env, flattener, lookup_table=None) -> ActionAdapter:
        """Policy box [-1, 1]^|A| <-> the environment's actions; a residual on the lookup if configured.
        `lookup_table`: the residual's base (agents/lookup.py; default: the paper layout's poses)."""
        action_spec = env.action_spec()
        if len(action_spec.shape) != 1:
            raise ValueError(f"expected a flat action spec, got shape {action_spec.shape}")
        if self.config.residual_scale > 0:
            from agents.lookup import LookupPolicy
            return ResidualAdapter(action_spec, LookupPolicy(flattener, lookup_table), self.config.residual_scale)
        return ActionAdapter(action_spec)

    def make_networks(self, observation_size: int, action_size: int):
        cfg = self.config
        return make_networks(observation_size, action_size, cfg.hidden_sizes, cfg.log_std_min, cfg.log_std_max,
                             cfg.critic_layer_norm, zero_policy_mean=cfg.residual_scale > 0)

    def make_learner(self, networks, key) -> SACLearner:
        return SACLearner(networks, self.config, key)

    def make_replay(self, env, flattener, action_size: int, seed: int):
        """The replay, and the goal relabeler when it keeps achieved goals (HER, reward recomputation)."""
        cfg = self.config
        relabeler = GoalRelabeler.for_environment(env, flattener) if cfg.uses_goals else None
        goal_width = relabeler.goal_size + 1 if relabeler is not None else 0  # + attitude error
        return ReplayBuffer(flattener.size, action_size, cfg.max_replay_size, seed=seed, goal_width=goal_width,
                            repeat=cfg.action_repeat)

    def make_actor(self, networks, adapter, params, key=None, deterministic: bool = False) -> Actor:
        return Actor(networks, adapter, params, key=key, deterministic=deterministic)

    def make_components(self, env, seed: int, lookup_table=None) -> EnvironmentLoop:
        """All of the above for `env`, wired into the loop that owns them (what a lesson plan runs)."""
        flattener = ObservationFlattener(env.observation_spec())
        adapter = self.make_adapter(env, flattener, lookup_table)
        networks = self.make_networks(flattener.size, adapter.size)
        learner_key, actor_key = jax.random.split(jax.random.PRNGKey(seed))
        learner = self.make_learner(networks, learner_key)
        replay = self.make_replay(env, flattener, adapter.size, seed)
        actor = self.make_actor(networks, adapter, learner.policy_params, key=actor_key)
        return EnvironmentLoop(env, actor, replay, learner, self.config, flattener, seed=seed)

    @staticmethod
    def make_eval_actor(loop: EnvironmentLoop) -> Actor:
        """The deterministic policy a trained agent is judged by (its average, if it keeps one)."""
        return Actor(loop.learner.networks, loop.actor.adapter, loop.learner.evaluation_params,
                     deterministic=True)
