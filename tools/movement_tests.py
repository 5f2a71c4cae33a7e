"""The paper's rolling and lever movement tests (Sec. 4.3, Figs. 4-5); see --help."""
import pathlib
import sys

try:
    from robostrich_suite.studies import movement
except ImportError:  # run from a checkout without `pip install -e .`
    sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
    from robostrich_suite.studies import movement

if __name__ == "__main__":
    sys.exit(movement.cli())
