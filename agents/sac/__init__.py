"""Soft Actor-Critic in JAX (haiku + optax), one concern per module as in Acme."""
from agents.sac.builder import SACBuilder
from agents.sac.config import SACConfig
from agents.sac.learning import SACLearner, TrainingState
from agents.sac.networks import SACNetworks, make_networks
from agents.types import Transitions

__all__ = ["SACConfig", "SACNetworks", "make_networks", "SACLearner", "TrainingState", "Transitions", "SACBuilder"]
