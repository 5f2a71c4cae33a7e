"""The generated MJCF of the default models, as checked in under ``xml/``.

``xml/`` lets a user open the robots in plain MuJoCo (``simulate``,
``mujoco.MjModel.from_xml_path``) without this package.  A test fails when a
checked-in file differs from what the generators produce now; regenerate from the
repository's root with ``robostrich-export-xml --out xml``.
"""
from __future__ import annotations

import pathlib

from robostrich_suite import atomic_files
from robostrich_suite import cli as cli_lib
from robostrich_suite import outputs
from robostrich_suite import robostrich
from robostrich_suite import robostrich_a1


def _robostrich():
    return robostrich.get_model_and_assets()[0]


def _robostrich_a1():
    return robostrich_a1.get_model_and_assets()[0]


def generators() -> dict:
    """File name -> function returning that model's XML string."""
    return {"robostrich.xml": _robostrich, "robostrich_a1.xml": _robostrich_a1}


def export(directory: pathlib.Path) -> list[pathlib.Path]:
    """Write every default model's XML into ``directory``; returns the paths."""
    directory = pathlib.Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for name, generate in generators().items():
        path = directory / name
        atomic_files.write_text(path, generate())
        written.append(path)
    return written


def main(argv=None) -> None:
    parser = cli_lib.Parser(description="Write the generated MJCF of the default models.")
    parser.add_argument("--out", type=pathlib.Path, required=True,
                        help="directory to write into (the checked-in copies: the repository's xml/)")
    args = parser.parse_args(argv)
    outputs.check_directory(args.out)
    for path in export(args.out):
        print(f"wrote {path}")


def cli(argv=None) -> int:
    """Console script `robostrich-export-xml`: exit status 0, or 2 with a one-line error (robostrich_suite.cli)."""
    return cli_lib.run(main, "robostrich-export-xml", argv)


if __name__ == "__main__":
    import sys
    sys.exit(cli())
