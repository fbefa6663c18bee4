#!/usr/bin/env python3
"""Writes Mitsuba 3's built-in Cornell box (`mitsuba.cornell_box()`) as Mitsuba XML with
Mitsuba's own writer (`mitsuba.xml.dict_to_xml`), into scenes/import/cornell-box.xml: the
file `prism import` / `prism render` are checked on (tests/import_cli.rs renders it within
1 % per channel of Mitsuba's reference and of scenes/cornell-box.json).

Run: tools/mitsuba/setup.sh once, then
    tools/mitsuba/.venv/bin/python tools/mitsuba/export_cornell_xml.py
"""

import pathlib
import shutil
import sys
import tempfile

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from common import ROOT, import_mitsuba  # noqa: E402

OUT = ROOT / "scenes" / "import" / "cornell-box.xml"


def main():
    mi = import_mitsuba()
    mi.set_variant("scalar_spectral")
    from mitsuba.xml import dict_to_xml

    work = pathlib.Path(tempfile.mkdtemp(prefix="prism-cornell-xml-"))
    try:
        # The writer puts mesh files beside the XML (none for this scene): write aside.
        dict_to_xml(mi.cornell_box(), str(work / "cornell-box.xml"))
        body = (work / "cornell-box.xml").read_text()
    finally:
        shutil.rmtree(work, ignore_errors=True)
    header = (
        "<!-- Mitsuba 3's built-in Cornell box, written by Mitsuba "
        f"{mi.__version__}: mitsuba.xml.dict_to_xml(mitsuba.cornell_box(), ...) "
        "(tools/mitsuba/export_cornell_xml.py; do not edit by hand).\n"
        "     `prism render scenes/import/cornell-box.xml` or `prism import ... -o X.json`. -->\n"
    )
    tmp = OUT.with_suffix(".xml.tmp")
    tmp.write_text(header + body)
    tmp.replace(OUT)
    print(f"wrote {OUT.relative_to(ROOT)} (Mitsuba {mi.__version__})")


if __name__ == "__main__":
    main()
