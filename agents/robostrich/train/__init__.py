"""robostrich-train: the main job's defaults, its input checks, the run directory, the runs' jobs and
workers, progress and transfer between domains (command.py is the command)."""
