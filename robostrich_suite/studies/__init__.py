"""Studies: the research code behind the console scripts, apart from the runtime path.

* :mod:`workspace` (``robostrich-workspace``): the kinematic and actuated workspace (Fig. 6);
* :mod:`movement` (``robostrich-movement``): the rolling and lever patterns (Figs. 3-5);
* :mod:`walk` (``robostrich-walk``): the quadruped walking with the arm on it;
* :mod:`targets` (``robostrich-targets``) and :mod:`target_generation`: the level-head target files;
* :mod:`gait` (``robostrich-gait``): the gait file of the open-loop trot;
* :mod:`layout_compare` (``robostrich-layouts``) with :mod:`coverage`, :mod:`pose_seek`
  and :mod:`layout_figure`: tendon layouts compared.

Nothing in the runtime path (``model``, ``physics``, ``tasks``, the domain modules and
``agents``) imports this package.
"""
