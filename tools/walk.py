"""Walk the quadruped with the arm on it: python tools/walk.py [--tendons sine] [--out out/walk].

Writes a Rerun recording (OUT.rrd, open with `rerun OUT.rrd`) and a PNG of the
trunk's and head's height, speed and attitude over time.
"""
import os
import sys

os.environ.setdefault("MUJOCO_GL", "egl")

from robostrich_suite.studies.walk import cli  # noqa: E402

if __name__ == "__main__":
    sys.exit(cli())
