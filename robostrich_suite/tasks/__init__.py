"""The tasks: reaching and tracking (:mod:`reach`), the quadruped's tasks and its gait
controller, rewards, domain randomisation, the conventions they share and the one lesson
factory the domain modules (``robostrich_suite.robostrich``, ``robostrich_suite.robostrich_a1``)
are built with."""
