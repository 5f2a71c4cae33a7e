"""Soft Actor-Critic in JAX (haiku + optax), one concern per module as in Acme."""
from agents.sac.config import SACConfig
from agents.sac.networks import SACNetworks, make_networks
from agents.sac.learning import SACLearner, TrainingState
from agents.sac.builder import SACBuilder

__all__ = ["SACConfig", "SACNetworks", "make_networks", "SACLearner", "TrainingState", "SACBuilder"]
