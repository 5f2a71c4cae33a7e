"""robostrich-robustness: success as the robot differs from its model, and its figure."""
