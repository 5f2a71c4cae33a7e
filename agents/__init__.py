"""The learner: an Acme-style JAX SAC agent, replay, loops and the curriculum (Algorithm 1)."""
