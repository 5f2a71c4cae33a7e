"""robostrich-sweep: grids of main jobs as Ray tasks and their table (command.py is the command)."""
