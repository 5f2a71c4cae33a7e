"""The models: Table 1, the arm generator, the A1-like quadruped, the scenes they are
composed into (the immobile frame, the A1 composition, the narrow-gap wall), the tendon
layout library and the model fingerprint.  Generation only: reading a compiled model is
:mod:`robostrich_suite.physics`' job."""
