"""The models: Table 1, the arm generator, the A1-like quadruped and its legs, the tendon layout
library and the time steps.  Generation only: the scenes they are composed into (the immobile
frame, the A1 composition, the narrow-gap wall) are :mod:`robostrich_suite.scenes`, reading a
compiled model :mod:`robostrich_suite.physics`' job, its fingerprint
:mod:`robostrich_suite.fingerprint`'s."""
