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

    def make_components(self, env, seed: int, lookup_table=None):
        """`lookup_table`: the residual policy's base (agents/lookup.py; default: the paper layout's poses)."""
        cfg = self.config
        action_spec = env.action_spec()
        if len(action_spec.shape) != 1:
            raise ValueError(f"expected a flat action spec, got shape {action_spec.shape}")
        flattener = ObservationFlattener(env.observation_spec())
        if cfg.residual_scale > 0:
            from agents.lookup import LookupPolicy
            adapter = ResidualAdapter(action_spec, LookupPolicy(flattener, lookup_table), cfg.residual_scale)
        else:
            adapter = ActionAdapter(action_spec)
        networks = make_networks(flattener.size, adapter.size, cfg.hidden_sizes, cfg.log_std_min, cfg.log_std_max,
                                 cfg.critic_layer_norm, zero_policy_mean=cfg.residual_scale > 0)
        key = jax.random.PRNGKey(seed)
        learner_key, actor_key = jax.random.split(key)
        learner = SACLearner(networks, cfg, learner_key)
        relabeler = GoalRelabeler.for_environment(env, flattener) if cfg.uses_goals else None
        goal_width = relabeler.goal_size + 1 if relabeler is not None else 0  # + attitude error
        replay = ReplayBuffer(flattener.size, adapter.size, cfg.max_replay_size, seed=seed,
                              goal_width=goal_width, repeat=cfg.action_repeat)
        actor = Actor(networks, adapter, learner.policy_params, key=actor_key, deterministic=False)
        loop = EnvironmentLoop(env, actor, replay, learner, cfg, flattener, seed=seed)
        return loop

    @staticmethod
    def make_eval_actor(loop: EnvironmentLoop) -> Actor:
        return Actor(loop.learner.networks, loop.actor.adapter, loop.learner.policy_params, deterministic=True)
