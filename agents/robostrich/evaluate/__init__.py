"""robostrich-evaluate: held-out and track evaluations of a policy, and a run's policy exported."""
