"""Table 1 of the paper: the Robostrich arm's joints and links, in one place.

Every other module (the MJCF generator, the tasks, the workspace tools and the
tests) reads the arm's numbers from here.  Columns run from the cranial end
(the atlas, i.e. the head joint) to the caudal end (C18, which joins the frame).

Units are as printed in the paper (degrees, millimetres, grams); the generator
converts them to SI.
"""
from __future__ import annotations

import dataclasses

# Joint (and link) names, cranial to caudal.  Joint ``Cn`` sits at the caudal end
# of link ``Cn``; the ``atlas`` joint joins the head to link C2, and joint C18
# joins link C18 to the frame.
JOINT_NAMES = ("atlas",) + tuple(f"c{n}" for n in range(2, 19))

# Range of motion from the straight pose, in degrees (both positive numbers).
DORSAL_LIMIT_DEG = (1, 12, 18, 20, 28, 31, 33, 35, 28, 29, 30, 27, 24, 22, 19, 18, 18, 18)
VENTRAL_LIMIT_DEG = (1, 12, 16, 18, 25, 30, 32, 30, 26, 25, 18, 15, 12, 8, 6, 6, 6, 6)

# Distance between the link's two joint axes, in millimetres.  The head (atlas)
# has no length in Table 1: its shape is a generator parameter.
LENGTH_MM = (None, 7.1, 17.6, 22.1, 26.5, 30.9, 35.3, 39.7, 39.7, 44.1, 44.1, 44.1,
                 44.1, 44.1, 44.1, 44.1, 44.1, 39.7)

# Mass of each bone part, in grams (the atlas mass includes the beak).
MASS_G = (83, 5, 7, 8, 10, 11, 12, 13, 13, 14, 14, 14, 14, 14, 14, 14, 14, 13)


@dataclasses.dataclass(frozen=True)
class JointRow:
    """One column of Table 1."""
    name: str
    dorsal_limit_deg: float
    ventral_limit_deg: float
    length_mm: float | None
    mass_g: float


def rows() -> tuple[JointRow, ...]:
    """Table 1 as rows, cranial (atlas) to caudal (C18)."""
    return tuple(
          JointRow(n, d, v, length, m)
          for n, d, v, length, m in zip(
              JOINT_NAMES, DORSAL_LIMIT_DEG, VENTRAL_LIMIT_DEG, LENGTH_MM, MASS_G))


TOTAL_MASS_G = sum(MASS_G)  # 287 g
TOTAL_LENGTH_MM = sum(length for length in LENGTH_MM if length is not None)  # 611.4 mm
