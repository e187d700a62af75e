"""Bad input: every parameter cell with every kind of bad value, and the file-level cases.

Each case must give exit code 2, one line on stderr that names the cell (or file, or option),
what was found and what is expected, no traceback, an unchanged input, and no output file.
"""
import shutil
import zipfile

import openpyxl
import pytest
from conftest import TEMPLATE

from airgun_xl.cells import CELLS, TIME_HEADER
from airgun_xl.cli import main

#: kind -> (value written, text expected after "found ")
KINDS = {
    "blank": (None, "a blank cell"),
    "text": ("abc", "'abc'"),
    "nan text": ("NaN", "'NaN'"),
    "not available": ("=NA()", "the error #N/A from =NA()"),
    "huge": (1e300, "1e+300"),
    "formula error": ("=1/0", "the error #DIV/0! from =1/0"),
    "zero": (0, "0"),
    "negative": (-1.5, "-1.5"),
    "positive": (1.5, "1.5"),
    "boolean": (True, "TRUE"),
}

#: Which of the value kinds each check rejects (the others are valid values for that cell).
REJECTS = {
    "positive": {"zero", "negative"},
    "negative": {"zero", "positive"},
    "nonnegative": {"negative"},
    "fraction": {"zero", "negative"},
    "any": set(),
}
ALWAYS = {"blank", "text", "nan text", "not available", "huge", "formula error", "boolean"}

CELL_CASES = [(c, kind) for c in CELLS for kind in KINDS if kind in ALWAYS | REJECTS[c.check]]


def _write_variant(path, changes):
    wb = openpyxl.load_workbook(TEMPLATE)
    ws = wb.worksheets[0]
    for address, value in changes.items():
        ws[address] = value
    wb.save(path)


def _run_rejected(tmp_path, capsys, args, inputs=()):
    """Run the CLI; check exit 2, one clean line, inputs untouched, nothing created."""
    before = {p: p.read_bytes() for p in inputs if p.is_file()}
    listing = sorted(tmp_path.rglob("*"))
    assert main(args) == 2
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("airgun-xl: error: ")
    assert "Traceback" not in err
    assert sorted(tmp_path.rglob("*")) == listing
    for p, data in before.items():
        assert p.read_bytes() == data
    return lines[0]


def test_the_matrix_is_large_enough():
    assert len(CELL_CASES) >= 60


@pytest.mark.parametrize("cell,kind", CELL_CASES,
                         ids=[f"{c.address}-{k}" for c, k in CELL_CASES])
def test_bad_cell(tmp_path, capsys, cell, kind):
    value, found = KINDS[kind]
    shot = tmp_path / "shot.xlsx"
    changes = {cell.address: value}
    if cell.address in ("A28",):  # A29, A30 are formulas =A28 in the template
        changes.update({"A29": 243.5, "A30": 243.5})
    _write_variant(shot, changes)
    line = _run_rejected(tmp_path, capsys, ["fill", str(shot)], [shot])
    assert f"{cell.address} ({cell.label}): found {found}, expected " in line


@pytest.mark.parametrize("changes,cell,phrase", [
    ({"E2": 0.5, "E6": 0.25}, "E2 (Timestep)", "a time step no longer than E6"),
    ({"E2": 1e-9, "E6": 1.0}, "E6 (Max Time)", "at most 50,000,000 steps"),
    ({"E37": 1.5}, "E37 (Compacting Strain)", "greater than 0 and at most 1"),
    ({"H1": "Zeit"}, f"H1 ({TIME_HEADER.label})", "'Time' or a blank cell"),
    ({"E22": "abc"}, "E25 (Mass of Mitigator)", "found the error #VALUE! from =E10*E22"),
    ({"E25": "=FOO(1)"}, "E25 (Mass of Mitigator)", "cannot evaluate =FOO(1)"),
    ({"E25": "=E10*Z99"}, "E25 (Mass of Mitigator)", "outside the parameter block"),
])
def test_bad_combination(tmp_path, capsys, changes, cell, phrase):
    shot = tmp_path / "shot.xlsx"
    _write_variant(shot, changes)
    line = _run_rejected(tmp_path, capsys, ["fill", str(shot)], [shot])
    assert cell in line and phrase in line


def _make_file(tmp_path, kind):
    path = tmp_path / "shot.xlsx"
    if kind == "missing":
        return path, "no such file"
    if kind == "folder":
        path.mkdir()
        return path, "holds no .xlsx shot"  # a folder is a campaign of its shots
    if kind == "empty":
        path.write_bytes(b"")
        return path, "is not a workbook"
    if kind == "text":
        path.write_text("M1,M31\n680,4.8\n")
        return path, "is not a workbook"
    if kind == "truncated":
        path.write_bytes(TEMPLATE.read_bytes()[:2000])
        return path, "is not a readable .xlsx workbook"
    if kind == "zip without a workbook":
        with zipfile.ZipFile(path, "w") as z:
            z.writestr("hello.txt", "hi")
        return path, "is not a readable .xlsx workbook"
    if kind == "password-protected":
        # An encrypted .xlsx is an OLE compound file holding an "EncryptedPackage" stream.
        header = bytes.fromhex("D0CF11E0A1B11AE1") + bytes(504)
        path.write_bytes(header + "EncryptedPackage".encode("utf-16-le") + bytes(1000))
        return path, "is password-protected"
    if kind == "broken xls":
        path = tmp_path / "shot.xls"
        path.write_bytes(bytes.fromhex("D0CF11E0A1B11AE1") + bytes(2000))
        return path, "is not a readable .xls workbook"
    raise ValueError(kind)


FILE_KINDS = ["missing", "folder", "empty", "text", "truncated", "zip without a workbook",
              "password-protected", "broken xls"]


@pytest.mark.parametrize("kind", FILE_KINDS)
def test_bad_file(tmp_path, capsys, kind):
    path, phrase = _make_file(tmp_path, kind)
    line = _run_rejected(tmp_path, capsys, ["fill", str(path), "-o", str(tmp_path / "o.xlsx")],
                         [path])
    assert str(path) in line and phrase in line


def test_existing_output_needs_force(tmp_path, capsys, shot_copy):
    out = tmp_path / "shot.out.xlsx"
    out.write_bytes(b"keep me")
    line = _run_rejected(tmp_path, capsys, ["fill", str(shot_copy)], [shot_copy, out])
    assert "already exists" in line and "--force" in line


def test_output_may_not_be_the_input(tmp_path, capsys, shot_copy):
    line = _run_rejected(tmp_path, capsys, ["fill", str(shot_copy), "-o", str(shot_copy),
                                            "--force"], [shot_copy])
    assert "is the input workbook" in line


def test_output_folder_must_exist(tmp_path, capsys, shot_copy):
    line = _run_rejected(tmp_path, capsys, ["fill", str(shot_copy), "-o",
                                            str(tmp_path / "nowhere" / "o.xlsx")], [shot_copy])
    assert "does not exist" in line


@pytest.mark.parametrize("args,phrase", [
    (["fill", "{shot}", "--host", "numbers"], "--host"),
    (["fill"], "SHOT.xlsx"),
    (["fill", "{shot}", "--bogus"], "--bogus"),
    (["frobnicate"], "frobnicate"),
    (["template"], "OUT.xlsx"),
])
def test_bad_option(tmp_path, capsys, shot_copy, args, phrase):
    args = [a.format(shot=shot_copy) for a in args]
    line = _run_rejected(tmp_path, capsys, args, [shot_copy])
    assert phrase in line


def test_template_refuses_to_overwrite(tmp_path, capsys):
    out = tmp_path / "t.xlsx"
    shutil.copy(TEMPLATE, out)
    line = _run_rejected(tmp_path, capsys, ["template", str(out)], [out])
    assert "already exists" in line
