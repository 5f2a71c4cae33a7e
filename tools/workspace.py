"""Kinematic and actuated workspace of the Robostrich arm (paper Fig. 6); see --help."""
import pathlib
import sys

try:
    from robostrich_suite.studies import workspace
except ImportError:  # run from a checkout without `pip install -e .`
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
    from robostrich_suite.studies import workspace

if __name__ == "__main__":
    sys.exit(workspace.cli())
