"""Regenerate xml/ from the MJCF generators: python tools/export_xml.py [--out DIR]."""
from robostrich_suite.xml_export import main

if __name__ == "__main__":
    main()
