"""Tendon layouts side by side: blue-region coverage, targets, movement tests, lookup (issue 13); see --help."""
import pathlib
import sys

try:
    from robostrich_suite.studies import layout_compare
except ImportError:  # run from a checkout without `pip install -e .`
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
    from robostrich_suite.studies import layout_compare

if __name__ == "__main__":
    sys.exit(layout_compare.cli())
