"""Hostile input files: each is refused with one line (or, where harmless, runs), never a
traceback, never a native abort, nothing written, and memory stays under 500 MB.

The files are built here (builders.py): far cells, zip bombs, XXE and billion laughs, CRC and
XML corruption, a bad shared-string index, a million-row sheet, devices and FIFOs.
"""
import os
import shutil

import builders as b
import openpyxl
import pytest
from support import MEMORY_CAP, formulas_in, refused, run_child, snapshot, strings_in

from airgun_xl.cli import main

#: builder, what fill's line must name (None: fill runs), what diff's line must name.
REFUSED = {
    "far_cell": (b.far_cell, None, "at least 1,048,576 rows"),
    "whitespace_bomb": (b.whitespace_bomb, "zip bomb", "zip bomb"),
    # the template's own members and the 5,000 added
    "many_members": (b.many_members, f"{5_000 + len(b.members()):,} zip members",
                     f"{5_000 + len(b.members()):,} zip members"),
    "xxe_strings": (b.xxe_strings, "DTD", "DTD"),
    "laughs_strings": (b.laughs_strings, "DTD", "DTD"),
    "xxe_sheet": (b.xxe_sheet, "DTD", "DTD"),
    "laughs_sheet": (b.laughs_sheet, "DTD", "DTD"),
    "crc_error": (b.crc_error, "CRC", "CRC"),
    "corrupt_sheet": (b.corrupt_sheet, "not a readable", "not a readable"),
    "bad_shared_string": (b.bad_shared_string, "not a readable", "not a readable"),
    "million_rows": (b.million_rows, None, "at least 500,001 rows x 8 columns"),
    "distinct_strings": (b.distinct_strings, "expected at most 4.0 MB", "expected at most 4.0 MB"),
    # a deflate stream broken past the parameter block: fill never reads that far
    "corrupt_deflate": (b.corrupt_deflate, None, "invalid block type"),
}


@pytest.fixture(scope="module")
def hostile(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hostile")
    paths = {}
    for name, (build, _, _) in REFUSED.items():
        paths[name] = folder / f"{name}.xlsx"
        paths[name].write_bytes(build())
    paths["xls_far_cell"] = folder / "xls_far_cell.xls"
    paths["xls_far_cell"].write_bytes(b.xls_far_cell())
    return paths


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_fill_of_a_hostile_file(tmp_path, capsys, hostile, name):
    shot = tmp_path / f"{name}.xlsx"
    shutil.copy(hostile[name], shot)
    phrase = REFUSED[name][1]
    if phrase is None:  # the hostile part lies outside the parameter block: the shot runs
        assert main(["fill", str(shot), "--only", "summary"]) == 0
        assert openpyxl.load_workbook(tmp_path / f"{name}.out.xlsx")["Summary"]["B2"].value \
            == pytest.approx(11.99446, abs=1e-5)  # shot A at 0.5 us, as the template
        return
    refused(capsys, ["fill", shot], tmp_path, naming=[str(shot), phrase])


@pytest.mark.parametrize("name", sorted(REFUSED))
def test_diff_of_a_hostile_file(tmp_path, capsys, hostile, name):
    refused(capsys, ["diff", hostile[name], hostile[name]], tmp_path, hostile[name].parent,
            naming=[REFUSED[name][2]])


def test_an_xls_with_a_far_cell_is_refused_before_calamine(tmp_path, capsys, hostile):
    """65,536 x 256 cells would be 0.5 GB in calamine's dense range."""
    for command in (["fill"], ["diff", hostile["xls_far_cell"]]):
        refused(capsys, [*command, hostile["xls_far_cell"]], tmp_path,
                naming=["65,536 rows x 256 columns"])


@pytest.mark.parametrize("name", ["far_cell", "whitespace_bomb", "million_rows"])
def test_memory_stays_under_the_cap(tmp_path, hostile, name):
    """Measured in a child process: fill and diff of each file stay under 500 MB resident
    (the far cell once made calamine allocate 512 GB; the million-row sheet took 3.9 GB)."""
    for argv in (["fill", hostile[name], "-o", tmp_path / "o.xlsx", "--only", "summary"],
                 ["diff", hostile[name], hostile[name]]):
        code, err, rss = run_child(tmp_path, argv)
        assert code in (0, 2) and "Traceback" not in err, err
        assert rss is not None and rss < MEMORY_CAP, (argv[0], rss)


def test_not_regular_files_are_refused(tmp_path, capsys):
    fifo = tmp_path / "pipe.xlsx"
    os.mkfifo(fifo)
    refused(capsys, ["fill", fifo], tmp_path, naming=["a FIFO"])
    refused(capsys, ["fill", "/dev/zero"], tmp_path, naming=["/dev/zero", "character device"])
    refused(capsys, ["diff", "/dev/zero", fifo], tmp_path, naming=["character device"])
    refused(capsys, ["fill", tmp_path], tmp_path, naming=["holds no .xlsx shot"])  # a campaign


def test_a_file_past_the_size_cap_is_refused_unread(tmp_path, capsys):
    big = tmp_path / "big.xlsx"
    with open(big, "wb") as fh:
        fh.write(b"PK\x03\x04")
        fh.truncate(60 * 2**20)  # sparse: nothing of it is ever read
    refused(capsys, ["fill", big], tmp_path, naming=["60.0 MB", "at most 50.0 MB"])


def test_a_file_name_that_is_not_utf8(tmp_path, capsys):
    """A name with an undecodable byte runs; a missing one is one readable line."""
    shot = tmp_path / os.fsdecode(b"shot\xff.xlsx")
    shutil.copy(b.TEMPLATE, shot)
    assert main(["fill", str(shot), "--only", "summary"]) == 0
    out = tmp_path / os.fsdecode(b"shot\xff.out.xlsx")
    summary = openpyxl.load_workbook(out)["Summary"]
    values = [row[1] for row in summary.iter_rows(values_only=True)]
    assert any(isinstance(v, str) and v.endswith("shot\\udcff.xlsx") for v in values)
    refused(capsys, ["fill", tmp_path / os.fsdecode(b"gone\xfe.xlsx")], tmp_path,
            naming=["gone\\udcfe.xlsx", "no such file"])


# -- text stays text ----------------------------------------------------------------------------
@pytest.mark.parametrize("text", b.INJECTIONS)
def test_injection_text_in_labels_and_the_shot_name_stays_text(tmp_path, text):
    """A label, the Shot name and a note, each holding text that a spreadsheet would run, are
    copied as text: the output holds exactly the input's real formulas, and the text."""
    shot = tmp_path / "shot.xlsx"
    shot.write_bytes(b.text_cells({"A1": text, "F1": "Shot", "G1": text, "G20": text}))
    assert main(["fill", str(shot), "--archive", str(tmp_path / "archive")]) == 0
    out = tmp_path / "shot.out.xlsx"
    payload = text.lstrip("=+-@")
    assert not [f for f in formulas_in(out) if payload in f]  # charts and sheets alike
    assert sorted(f for f in formulas_in(out) if "$" not in f) == sorted(
        formulas_in(b.TEMPLATE))  # the input's real formulas, and only those (+ chart refs)
    ws = openpyxl.load_workbook(out).worksheets[0]
    for address in ("A1", "G1", "G20"):
        assert ws[address].value == text and ws[address].data_type == "s"
    assert text.replace("&", "&amp;") in strings_in(out)


def test_text_in_a_parameter_cell_is_a_cell_error(tmp_path, capsys):
    """'=0.02' typed as text in E43 is not a formula: the run refuses the cell."""
    shot = tmp_path / "shot.xlsx"
    shot.write_bytes(b.text_cells({"E43": "=0.02"}))
    refused(capsys, ["fill", shot], tmp_path, naming=["E43 (Damping Factor (Zeta))", "'=0.02'"])


def test_a_formula_that_calls_out_is_written_as_its_value(tmp_path, capsys):
    """A real DDE formula in the input is not copied as a formula (a warning says so)."""
    def add_dde(s):
        return s.replace('<c r="E43"><v>0.02</v></c>',
                         '<c r="E43"><v>0.02</v></c><c r="F43"><f>cmd|\' /C calc\'!A0</f>'
                         '<v>7</v></c>')
    shot = tmp_path / "shot.xlsx"
    shot.write_bytes(b.edit(b.SHEET, add_dde))
    assert main(["fill", str(shot), "--only", "summary"]) == 0
    assert "reaches outside the workbook" in capsys.readouterr().err
    out = tmp_path / "shot.out.xlsx"
    assert not any("cmd" in f for f in formulas_in(out))
    assert openpyxl.load_workbook(out).worksheets[0]["F43"].value == 7


@pytest.mark.parametrize("title,expected", [
    ("Summary", ["Summary", "Parameters", "Summary (2)"]),
    ("charts", ["charts", "Parameters", "Summary", "Charts (2)"]),
    ("a/b[c]'", ["a_b_c_", "Parameters", "Summary"]),
    ("'quoted'", ["quoted", "Parameters", "Summary"]),
])
def test_odd_first_sheet_names_rename_the_output_sheets(tmp_path, title, expected):
    shot = tmp_path / "shot.xlsx"
    shot.write_bytes(b.first_sheet_named(title))
    assert main(["fill", str(shot)]) == 0
    names = openpyxl.load_workbook(tmp_path / "shot.out.xlsx").sheetnames
    assert names[:len(expected)] == expected
    assert all(f.split("!")[0].strip("'") in names for f in formulas_in(
        tmp_path / "shot.out.xlsx") if "!" in f)


def test_diff_report_keeps_a_hostile_header_as_text(tmp_path):
    """A legacy workbook whose header is an injection: the report's cells and its chart title
    hold it as text (a chart name like 'x!A1' would otherwise become a reference)."""
    filled = tmp_path / "new.xlsx"
    assert main(["fill", str(b.TEMPLATE), "-o", str(filled), "--only", "positions"]) == 0
    legacy = tmp_path / "legacy.xlsx"
    wb = openpyxl.load_workbook(filled)
    ws = wb.worksheets[0]
    ws["I1"] = "x"
    ws["I1"].value = b.INJECTIONS[0]
    ws["I1"].data_type = "s"
    ws["I500"] = ws["I500"].value * (1 + 1e-6)
    wb.save(legacy)
    report = tmp_path / "report.xlsx"
    before = snapshot(tmp_path)
    assert main(["diff", str(legacy), str(filled), "--report", str(report)]) == 1
    assert set(snapshot(tmp_path)) - set(before) == {str(report)}
    assert not any("cmd" in f for f in formulas_in(report))


@pytest.mark.skipif(shutil.which("soffice") is None, reason="LibreOffice is not installed")
def test_libreoffice_shows_the_text_and_does_not_run_it(tmp_path):
    """In a real spreadsheet app: the label '=1+1' reads back as those characters, not 2, and
    a parameter sheet named Summary opens beside the renamed 'Summary (2)'."""
    import subprocess

    shot = tmp_path / "shot.xlsx"
    shot.write_bytes(b.text_cells({"A1": "=1+1", "G1": "=cmd|' /C calc'!A0"}))
    shot.write_bytes(b.first_sheet_named("Summary", data=shot.read_bytes()))
    assert main(["fill", str(shot), "--only", "summary,positions"]) == 0
    out = tmp_path / "shot.out.xlsx"
    done = subprocess.run(["soffice", f"-env:UserInstallation=file://{tmp_path}/lo",
                           "--headless", "--convert-to", "csv", "--outdir", str(tmp_path),
                           str(out)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    import csv

    with (tmp_path / "shot.out.csv").open() as text:
        rows = list(csv.reader(text))
    assert rows[0][0] == "=1+1" and rows[0][6] == "=cmd|' /C calc'!A0"
    assert rows[0][7] == "Time" and float(rows[1][4]) == 5e-07  # E2 as written
