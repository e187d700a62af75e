"""Outputs that are not regular files, and two commands racing for one output."""
import os
import subprocess
import sys

import builders as b
import numpy as np
import openpyxl
import pandas as pd
import pytest
from support import refused, snapshot

from airgun_xl.cli import main

SHOT = b.TEMPLATE


@pytest.mark.parametrize("command", [["fill", SHOT], ["template"], ["diff", SHOT, SHOT]])
def test_an_output_that_is_not_a_regular_file_is_refused(tmp_path, capsys, command):
    fifo = tmp_path / "pipe.xlsx"
    os.mkfifo(fifo)
    folder = tmp_path / "folder.xlsx"
    folder.mkdir()
    flag = "--report" if command[0] == "diff" else "-o"
    if command[0] == "template":
        cases = [(fifo, "a FIFO"), (folder, "is a folder"), ("/dev/null", "character device")]
        for target, phrase in cases:
            refused(capsys, ["template", target], tmp_path, naming=[phrase])
        return
    for target, phrase in ((fifo, "a FIFO"), (folder, "is a folder"),
                           ("/dev/null", "character device")):
        refused(capsys, [*command, flag, target, "--force"], tmp_path, naming=[phrase])


@pytest.mark.parametrize("name", ["out.xlsm", "out.csv", "out", "out.xls"])
def test_the_output_must_be_named_xlsx(tmp_path, capsys, name):
    refused(capsys, ["fill", SHOT, "-o", tmp_path / name], tmp_path,
            naming=[name, "expected .xlsx"])


def test_a_symlink_output_is_replaced_only_with_force_and_never_its_target(tmp_path, capsys):
    target = tmp_path / "precious.txt"
    target.write_text("not a workbook")
    link = tmp_path / "out.xlsx"
    link.symlink_to(target)
    refused(capsys, ["fill", SHOT, "-o", link], tmp_path, naming=["symbolic link", "--force"])
    assert main(["fill", str(SHOT), "-o", str(link), "--force", "--only", "summary"]) == 0
    assert not link.is_symlink() and openpyxl.load_workbook(link)["Summary"]
    assert target.read_text() == "not a workbook"
    dangling = tmp_path / "dangling.xlsx"
    dangling.symlink_to(tmp_path / "nowhere")
    refused(capsys, ["fill", SHOT, "-o", dangling], tmp_path, naming=["symbolic link"])


def test_an_output_that_is_the_input_by_another_name_is_refused(tmp_path, capsys):
    shot = tmp_path / "shot.xlsx"
    shot.write_bytes(SHOT.read_bytes())
    (tmp_path / "alias.xlsx").symlink_to(shot)
    os.link(shot, tmp_path / "hard.xlsx")
    for alias in ("alias.xlsx", "hard.xlsx"):
        refused(capsys, ["fill", shot, "-o", tmp_path / alias, "--force"], tmp_path,
                naming=["is the input workbook"])


def _fill(out, *extra, zeta="0.02"):
    shot = out.parent / f"shot_{zeta}.xlsx"
    if not shot.exists():
        wb = openpyxl.load_workbook(SHOT)
        wb.worksheets[0]["E43"] = float(zeta)
        wb.save(shot)
    return subprocess.Popen([sys.executable, "-m", "airgun_xl", "fill", str(shot), "-o",
                             str(out), *extra], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)


def test_two_fills_to_one_output_without_force_exactly_one_wins(tmp_path):
    """Both pass the early check (no output yet); the exclusive link(2) at the end lets one
    publish and refuses the other with one line."""
    for round_ in range(3):
        out = tmp_path / f"race{round_}.xlsx"
        procs = [_fill(out, "--only", "summary", zeta=z) for z in ("0.02", "0.05")]
        errs = [p.communicate(timeout=300)[1] for p in procs]  # read to the end, closed
        results = [(p.returncode, err) for p, err in zip(procs, errs, strict=True)]
        codes = sorted(code for code, _ in results)
        assert codes == [0, 2], results
        loser = next(err for code, err in results if code == 2).strip().splitlines()
        assert len(loser) == 1 and "already exists" in loser[0] and "Traceback" not in loser[0]
        assert openpyxl.load_workbook(out)["Summary"]
        assert [p.name for p in tmp_path.iterdir() if ".airgun-xl-" in p.name] == []


def test_forced_fills_racing_keep_each_workbook_with_its_own_sidecar(tmp_path):
    """Two --force fills of different shots into one output, many times: the workbook and
    its sidecar always come from the same run (the folder lock serializes the publication)."""
    out = tmp_path / "o.xlsx"
    sidecar = tmp_path / "o.history.parquet"
    for _ in range(4):
        procs = [_fill(out, "--force", "--sidecar", "always", "--only", "positions",
                       zeta=z) for z in ("0.02", "0.3")]
        for p in procs:
            p.communicate(timeout=300)  # pipes read to the end and closed
        assert [p.returncode for p in procs] == [0, 0]
        book = openpyxl.load_workbook(out, read_only=True)
        sheet = book.worksheets[0]
        zeta = sheet["E43"].value
        y33 = np.array([r[0] for r in sheet.iter_rows(min_row=2, max_row=12003, min_col=12,
                                                       max_col=12, values_only=True)])
        book.close()  # read-only workbooks hold their file open until closed
        history = pd.read_parquet(sidecar)
        assert zeta in (0.02, 0.3)
        np.testing.assert_array_equal(history["y33"].to_numpy(), y33)  # exact: same run


def test_force_removes_a_stale_sidecar_the_new_run_does_not_write(tmp_path):
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(SHOT), "-o", str(out), "--sidecar", "always",
                 "--only", "summary"]) == 0
    assert (tmp_path / "o.history.parquet").exists()
    assert main(["fill", str(SHOT), "-o", str(out), "--force", "--only", "summary"]) == 0
    assert not (tmp_path / "o.history.parquet").exists()  # it belonged to the old workbook
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.xlsx"]


def test_a_refused_fill_leaves_the_folder_as_it_was(tmp_path, capsys):
    (tmp_path / "o.xlsx").write_bytes(b"old")
    before = snapshot(tmp_path)
    refused(capsys, ["fill", SHOT, "-o", tmp_path / "o.xlsx"], tmp_path,
            naming=["already exists", "--force"])
    assert snapshot(tmp_path) == before
