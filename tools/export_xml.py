"""Regenerate xml/ from the MJCF generators: python tools/export_xml.py [--out DIR]."""
import sys

from robostrich_suite.xml_export import cli

if __name__ == "__main__":
    sys.exit(cli())
