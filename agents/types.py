"""Types shared by the generic agent modules (replay, loop) and the SAC learner, so neither imports the other."""
from typing import NamedTuple

import numpy as np


class Transitions(NamedTuple):
    """A batch of (s, a, r, discount, s'); `action` is in the policy's [-1, 1] space."""

    obs: np.ndarray
    action: np.ndarray
    reward: np.ndarray
    discount: np.ndarray
    next_obs: np.ndarray
