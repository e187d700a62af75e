"""Issue 63: the test a verdict is of, named on the report a client signs. The Specification
sheet's Test block (I:J) and accept's options (--client, --test-id, --item, --serial,
--operator, --lab) give it, an option over the sheet's value and said; every field is printed,
a blank line where none was given; text stays text; the archive's record keeps it."""
import json
import re
import shutil
import subprocess

import openpyxl
import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.identification import BLANK, FIELDS
from airgun_xl.readers.spec_sheet import TEST_FIRST_ROW

RECORDING = TEMPLATE.parent / "shot_a_recording.csv"


def _shot(path, **cells):
    """The template with its Test block's value cells (J) set: ``{field: value}``."""
    book = openpyxl.load_workbook(TEMPLATE)
    rows = {name: TEST_FIRST_ROW + k for k, (name, _label) in enumerate(FIELDS)}
    for name, value in cells.items():
        book["Specification"][f"J{rows[name]}"] = value
    book.save(path)
    return path


def test_the_template_holds_the_test_block():
    """Every field's label in column I, from row 2, its value cell blank."""
    sheet = openpyxl.load_workbook(TEMPLATE)["Specification"]
    assert sheet["I1"].value == "Test"
    for k, (_name, label) in enumerate(FIELDS):
        assert sheet[f"I{TEST_FIRST_ROW + k}"].value == label
        assert sheet[f"J{TEST_FIRST_ROW + k}"].value is None


def test_the_sheet_and_the_options_name_the_test_on_every_verdict(tmp_path):
    """The sheet gives a client, a test number (a number in its cell, shown whole), an item
    and a lot; --client replaces the sheet's (said), --operator adds one; the Verdict sheet
    lists every field (the serial, the lab, the date and the velocity as blank lines to
    fill), as text cells; the archive's record keeps the fields given."""
    shot = _shot(tmp_path / "shot.xlsx", client="Acme Aerospace", test_id=17,
                 item="Fuze S-12", lot="LOT-7")
    out = tmp_path / "v.xlsx"
    outcome = airgun_xl.accept(shot, RECORDING, sign=-1, peak="9kG:20%", output=out,
                               archive=tmp_path / "arch", client="=HYPERLINK(\"x\")",
                               operator="J. Smith")
    assert outcome.verdict.test == {"client": '=HYPERLINK("x")', "test_id": "17",
                                    "item": "Fuze S-12", "lot": "LOT-7",
                                    "operator": "J. Smith"}
    assert any(d.startswith("test: --client '=HYPERLINK(\"x\")' replaces the Specification "
                            "sheet's client, 'Acme Aerospace'")
               for d in outcome.verdict.definitions)
    sheet = openpyxl.load_workbook(out)["Verdict"]
    rows = {r[0].value: r[1] for r in sheet.iter_rows(min_row=1, max_row=len(FIELDS) + 1)}
    for name, label in FIELDS:
        cell = rows[label]
        assert cell.data_type == "s"  # text, never a live formula
        assert cell.value == outcome.verdict.test.get(name, BLANK)
    record = json.loads(outcome.archived.read_text())
    assert record["test"] == outcome.verdict.test


@pytest.mark.skipif(not shutil.which("pdftotext"), reason="needs poppler-utils (pdftotext)")
def test_the_pdf_names_the_test_on_its_first_page(tmp_path):
    """accept --pdf: each field on the first page, a blank line for those not given, and the
    gun's setting (the shot's A28)."""
    pytest.importorskip("matplotlib")
    shot = _shot(tmp_path / "shot.xlsx", test_id="T-0042", velocity=242.1)
    pdf = tmp_path / "r.pdf"
    assert main(["accept", str(shot), str(RECORDING), "--sign", "-1", "--peak", "9kG:20%",
                 "-o", str(tmp_path / "v.xlsx"), "--pdf", str(pdf), "--item", "Fuze S-12",
                 "--quiet"]) == 0
    first = subprocess.run(["pdftotext", "-layout", "-f", "1", "-l", "1", str(pdf), "-"],
                           capture_output=True, text=True, check=True).stdout
    # two fields a row: each label followed by its value or a blank line
    for label, value in (("Test number", "T-0042"), ("Test item", "Fuze S-12"),
                         ("Velocity measured", "242.1 m/s"), ("Client", BLANK),
                         ("Serial number", BLANK), ("Operator", BLANK), ("Laboratory", BLANK),
                         ("Date of the test", BLANK)):
        assert re.search(rf"{label}\s+{re.escape(value)}", first), (label, first)
    shot_a28 = airgun_xl.load(shot).params.v31
    assert re.search(rf"Gun setting\s+A28 = {shot_a28:.6g} m/s", first), first


def test_a_bad_field_is_refused_in_one_line(tmp_path, capsys):
    """An empty option, one past 120 characters and a formula in the block the tool cannot
    evaluate: one line naming the option or the cell, exit 2, nothing written."""
    from test_recording_channels import refused

    base = ["accept", TEMPLATE, RECORDING, "--sign", "-1", "--peak", "9kG:20%", "-o",
            tmp_path / "v.xlsx"]
    refused(capsys, [*base, "--client", " "], tmp_path, ("--client",))
    refused(capsys, [*base, "--serial", "x" * 121], tmp_path, ("--serial", "at most 120"))
    shot = _shot(tmp_path / "f.xlsx", item="=INDIRECT(\"A1\")")
    line = refused(capsys, ["accept", shot, RECORDING, "--sign", "-1", "--peak", "9kG:20%",
                            "-o", tmp_path / "w.xlsx"], tmp_path, ("'Specification'!J4",))
    assert "Test item" in line


@pytest.mark.skipif(not shutil.which("pdftotext"), reason="needs poppler-utils (pdftotext)")
def test_the_fill_report_names_the_test_too(tmp_path):
    """fill --pdf: the prediction's report heads with the sheet's Test block, a blank line
    for each field not given."""
    pytest.importorskip("matplotlib")
    shot = _shot(tmp_path / "shot.xlsx", client="Acme Aerospace", serial="SN-0007")
    pdf = tmp_path / "f.pdf"
    assert main(["fill", str(shot), "-o", str(tmp_path / "f.xlsx"), "--pdf", str(pdf),
                 "--quiet"]) == 0
    first = subprocess.run(["pdftotext", "-layout", "-f", "1", "-l", "1", str(pdf), "-"],
                           capture_output=True, text=True, check=True).stdout
    for label, value in (("Client", "Acme Aerospace"), ("Serial number", "SN-0007"),
                         ("Test number", BLANK), ("Operator", BLANK)):
        assert re.search(rf"{label}\s+{re.escape(value)}", first), (label, first)
