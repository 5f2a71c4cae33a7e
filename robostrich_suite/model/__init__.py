"""The models: Table 1, the arm generator, the A1-like quadruped and its legs, the tendon layout
library, an arm described in a file (:mod:`arm_file`) and the time steps.  Generation only: the
scenes they are composed into (the immobile frame, the A1 composition, the narrow-gap wall) are
:mod:`robostrich_suite.scenes`, reading a compiled model :mod:`robostrich_suite.physics`' job, its
fingerprint :mod:`robostrich_suite.fingerprint`'s."""
