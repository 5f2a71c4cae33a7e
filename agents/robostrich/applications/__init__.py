"""The applications on the walking quadruped (Sec. 5.2): robostrich-stabilize, robostrich-gap
(commands.py) and robostrich-play, their rollouts and figures."""
