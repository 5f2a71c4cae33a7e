"""Thin shim: `python tools/train.py ...` == `robostrich-train ...` (see agents/training.py)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from agents.training import cli  # noqa: E402

if __name__ == "__main__":
    sys.exit(cli())
