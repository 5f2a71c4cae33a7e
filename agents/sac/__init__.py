"""Soft Actor-Critic in JAX (haiku + optax), one concern per module as in Acme."""
from agents.sac.config import SACConfig
from agents.sac.learning import SACLearner, TrainingState, Transitions
from agents.sac.networks import SACNetworks, make_networks

__all__ = ["SACConfig", "SACNetworks", "make_networks", "SACLearner", "TrainingState", "Transitions", "SACBuilder"]


def __getattr__(name):  # the builder imports actors/loop, which import this package: load it lazily
    if name == "SACBuilder":
        from agents.sac.builder import SACBuilder
        return SACBuilder
    raise AttributeError(name)
