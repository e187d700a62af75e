"""Make a legacy case: shot A's input with some cells changed, run through the original macro.

    python legacy_reference/make_case.py NAME '{"E2": 5e-6, "E34": 4e5}'

writes NAME_input.xlsx (``shot_a_appendix_5us_input.xlsx`` with the cells changed by openpyxl)
and NAME_legacy.xlsx (what ArtSim wrote into it, run by ``../shared/legacy/run-legacy-macro``
in LibreOffice Calc; about 45 ms a row). The entry for cases.json is printed; add the note.
"""
import json
import subprocess
import sys
from pathlib import Path

import openpyxl

HERE = Path(__file__).resolve().parent
RUNNER = HERE.parent.parent / "shared" / "legacy" / "run-legacy-macro"


def main(name, changes):
    wb = openpyxl.load_workbook(HERE / "shot_a_appendix_5us_input.xlsx")
    ws = wb.active
    for address, value in changes.items():
        ws[address] = value
    source = HERE / f"{name}_input.xlsx"
    wb.save(source)
    subprocess.run([str(RUNNER), str(source), str(HERE / f"{name}_legacy.xlsx")], check=True)
    print(json.dumps({name: {"changes_from_shot_a": changes, "note": "",
                             "input": source.name, "legacy_output": f"{name}_legacy.xlsx",
                             "made_by": "airgun-xl developers with shared/legacy/"
                                        "run-legacy-macro (LibreOffice Calc 7.4)"}}, indent=1))


if __name__ == "__main__":
    main(sys.argv[1], json.loads(sys.argv[2]))
