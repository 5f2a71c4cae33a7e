"""Thin shim: `python tools/evaluate.py CHECKPOINT ...` == `robostrich-evaluate ...` (see agents/evaluation.py)."""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

from agents.evaluation import cli  # noqa: E402

if __name__ == "__main__":
    sys.exit(cli())
