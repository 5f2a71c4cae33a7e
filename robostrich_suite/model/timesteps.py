"""The simulation's timesteps (paper Sec. 4.2): facts of the model that the layers above read."""

CONTROL_TIMESTEP = 0.008  # s (paper Sec. 4.2)
PHYSICS_TIMESTEP = 0.002  # s; 4 substeps per control step
