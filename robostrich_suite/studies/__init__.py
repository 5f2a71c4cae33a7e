"""Studies: the research code behind the console scripts, apart from the suite.

* :mod:`workspace` (``robostrich-workspace``): the kinematic and actuated workspace (Fig. 6);
* :mod:`movement` (``robostrich-movement``): the rolling and lever patterns (Figs. 3-5);
* :mod:`walk` (``robostrich-walk``): the quadruped walking with the arm on it;
* :mod:`targets` (``robostrich-targets``) and :mod:`target_generation`: the level-head target
  files; :mod:`new_targets`: level poses away from a file's, to judge a policy on;
* :mod:`gait` (``robostrich-gait``): the gait file of the open-loop trot;
* :mod:`layout_compare` with :mod:`coverage`, :mod:`pose_seek` and :mod:`layout_figure`: tendon
  layouts compared (``robostrich-layouts`` runs it, with training: agents/robostrich/layouts.py);
* :mod:`design` (``robostrich-design``) with the ``design_*`` modules: routings searched;
* :mod:`gap_bound`, :mod:`gap_column`, :mod:`gap_passage`: what the narrow gap asks of the arm.

The suite (``model``, ``physics``, ``tasks``, the domain modules) never imports this package
(tests/test_layers.py); the agent's glue does (new targets, the layout comparison).
"""
