"""Issue 21: a day's shots in one command (fill of many workbooks, --jobs, --summary), the
archive as the lab's record (history's figures, --where, -o) and its library of crush laws."""
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import openpyxl
import pytest
from conftest import TEMPLATE, template_with, write_trace_csv

from airgun_xl.archive import Archive
from airgun_xl.cli import main
from airgun_xl.reports.campaign import TABLE

SPEEDS = {"a": 243.53532, "b": 200.0, "c": 150.0}


def _day(folder, speeds=SPEEDS, bad=()):
    """Shot workbooks in ``folder``: one per speed (A28..A30), and ``bad`` ones (E2 = 'abc')."""
    folder.mkdir(exist_ok=True)
    for name, v in speeds.items():
        path = template_with(folder, A28=v, A29=v, A30=v)
        path.rename(folder / f"{name}.xlsx")
    for name in bad:
        template_with(folder, E2="abc").rename(folder / f"{name}.xlsx")
    return folder


def _owned(folder):
    return sorted(p.name for p in folder.rglob("*") if ".airgun-xl-" in p.name)


def test_three_shots_one_bad(tmp_path, capsys):
    """Two outputs, exit 2 with the count, the bad shot's one line naming its file and cell,
    and a summary of three rows whose figures are the fills' own."""
    day = _day(tmp_path / "day", {"a": 243.53532, "b": 200.0}, bad=["bad"])
    summary = tmp_path / "day.xlsx"
    code = main(["fill", str(day), "--jobs", "2", "--summary", str(summary), "--peak",
                 "8.5kG:10%"])  # each shot's prediction judged (issue 25)
    err = capsys.readouterr().err
    assert code == 2
    assert f"{day / 'bad.xlsx'}: E2 (Timestep): found 'abc'" in err
    assert "1 of 3 shots failed" in err and "Traceback" not in err
    assert sorted(p.name for p in day.glob("*.out.xlsx")) == ["a.out.xlsx", "b.out.xlsx"]
    ws = openpyxl.load_workbook(summary)["Shots"]
    rows = [r for r in ws.iter_rows(min_row=4, values_only=True) if r[0] and r[0].endswith(
        ".xlsx")][:3]
    col = {key: k for k, (_, key, _) in enumerate(TABLE)}
    assert [r[col["status"]] for r in rows] == ["filled", "filled", "failed"]
    # v0 243.5 m/s: its record judged (the default low-pass) peaks at about 8.46 kG, inside
    # 8.5 kG ±10 %; v0 200 m/s falls short
    assert [r[col["verdict"]] for r in rows] == ["PASS", "FAIL", None]
    for row in rows[:2]:  # the summary's peak is the filled workbook's (kG, same double)
        filled = openpyxl.load_workbook(row[col["output"]])["Summary"]
        assert row[2] == filled["B2"].value and row[1] in (243.53532, 200.0)
    assert rows[2][2] is None and rows[2][col["output"]] is None  # nothing of the bad shot
    # the chart of the peak against v0, and the failure listed on the printed page
    texts = [c for r in ws.iter_rows(values_only=True) for c in r if isinstance(c, str)]
    assert any("E2 (Timestep)" in t for t in texts)


def test_a_second_run_skips_what_exists_and_the_summary_is_not_a_shot(tmp_path, capsys):
    day = _day(tmp_path / "day", {"a": 243.53532})
    summary = day / "day.xlsx"
    assert main(["fill", str(day), "--jobs", "1", "--summary", str(summary)]) == 0
    capsys.readouterr()
    assert main(["fill", str(day), "--jobs", "1"]) == 0  # day.xlsx and a.out.xlsx left out
    out = capsys.readouterr()
    assert "1 shots: 0 filled, 0 failed, 1 skipped" in out.out
    assert "a.out.xlsx exists (--force overwrites it)" in out.err


@pytest.mark.parametrize("argv, message", [
    (["--jobs", "0"], "--jobs: found '0', expected a whole number of worker processes"),
    (["-o", "x.xlsx"], "-o: found with 2 shots, expected one shot"),
    (["--crush-law", "LOT-1"], "--crush-law: found 'LOT-1' without --archive"),
])
def test_a_campaign_refuses_bad_options_before_any_shot(tmp_path, capsys, argv, message):
    day = _day(tmp_path / "day", {"a": 243.53532, "b": 200.0})
    assert main(["fill", str(day), *argv]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err
    assert not list(day.glob("*.out.xlsx"))


def _batch(folder, *argv, **kwargs):
    return subprocess.Popen([sys.executable, "-m", "airgun_xl", "fill", str(folder), *argv],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            **kwargs)


def test_ctrl_c_in_the_middle_of_a_batch(tmp_path):
    """Ctrl-C (SIGINT to the process group, as a terminal sends it) once the first shot is
    out: exit 130, the finished shots stay whole, the others leave nothing, no temp file."""
    day = _day(tmp_path / "day", {f"s{k:02d}": 150.0 + 8 * k for k in range(12)})
    proc = _batch(day, "--jobs", "2", start_new_session=True)
    deadline = time.monotonic() + 120
    while not list(day.glob("*.out.xlsx")) and proc.poll() is None:  # polled, not slept
        assert time.monotonic() < deadline
        time.sleep(0.02)
    os.killpg(proc.pid, signal.SIGINT)
    out, err = proc.communicate(timeout=120)
    assert proc.returncode == 130, (out, err)
    assert "Traceback" not in err and "stopped by signal 2" in err
    done = sorted(day.glob("*.out.xlsx"))
    assert 1 <= len(done) < 12
    assert f": {len(done)} of 12 shots were filled and stay" in err
    for path in done:  # each a whole workbook
        assert openpyxl.load_workbook(path, read_only=True).sheetnames[2] == "Summary"
    assert _owned(day) == []


def test_two_batches_into_one_archive_at_once(tmp_path):
    """Two campaigns of three shots each, two jobs each, into one new archive together: six
    entries, and the archive verifies clean."""
    archive = tmp_path / "archive"
    days = [_day(tmp_path / f"day{k}", {f"{name}{k}": v for name, v in SPEEDS.items()})
            for k in (1, 2)]
    procs = [_batch(day, "--jobs", "2", "--archive", str(archive)) for day in days]
    for proc in procs:
        out, err = proc.communicate(timeout=300)
        assert proc.returncode == 0 and "Traceback" not in err, err
    entries = Archive(archive).entries()
    assert sorted(e.shot for e in entries) == ["a1", "a2", "b1", "b2", "c1", "c2"]
    assert Archive(archive).verify() == []


def test_history_figures_where_and_output(tmp_path, capsys):
    """history lists the figures with their units; --where picks a lot by E40 (a value or a
    range); -o writes the table whose peaks are the entries' own."""
    day = _day(tmp_path / "day", {"a": 243.53532})
    template_with(day, E40=2.9e7).rename(day / "lot2.xlsx")
    archive = tmp_path / "archive"
    assert main(["fill", str(day), "--jobs", "1", "--archive", str(archive)]) == 0
    capsys.readouterr()
    assert main(["history", "--archive", str(archive), "--where", "E40=2.703e7"]) == 0
    out = capsys.readouterr().out
    assert "peak kG" in out and "filt. kG" in out and "pulse ms" in out and "crush m" in out
    assert "a@1" in out and "lot2@1" not in out and "1 entry of 2 (--where)" in out
    table = tmp_path / "shots.xlsx"
    assert main(["history", "--archive", str(archive), "--where", "E40=2.8e7:3e7", "-o",
                 str(table)]) == 0
    ws = openpyxl.load_workbook(table)["Shots"]
    rows = [r for r in ws.iter_rows(min_row=4, values_only=True) if r[0] == "lot2@1"]
    entry = Archive(archive).get("lot2")
    assert len(rows) == 1 and rows[0][3] == entry.load("summary.json")["peak_kg"]
    assert rows[0][11] == "legacy (Eq. 8)"
    assert main(["history", "--archive", str(archive), "--where", "E99=1"]) == 2


def test_a_law_stored_and_run_by_name_equals_the_same_law_from_its_workbook(tmp_path,
                                                                             capsys):
    """calibrate --archive --name keeps the law; fill --crush-law NAME runs it: the same
    acceleration, bit for bit, as the calibrated workbook's Crush law sheet gives; the fill's
    archive entry records the law by name."""
    import airgun_xl
    from airgun_xl.studies.calibrate import synthetic_measurement

    p = airgun_xl.load(TEMPLATE).params
    trace = synthetic_measurement(p.replace(sigmay=p.sigmay * 1.05), seed=5)
    measured = write_trace_csv(tmp_path / "m.csv", trace)
    archive = tmp_path / "archive"
    calibrated = tmp_path / "cal.xlsx"
    assert main(["calibrate", str(TEMPLATE), str(measured), "--cfc", "1000", "-o",
                 str(calibrated), "--archive", str(archive), "--name", "LOT-2026-07"]) == 0
    said = capsys.readouterr().out
    assert "stored the law as LOT-2026-07@1" in said
    # the law's record keeps its nodes' intervals, the ones calibrate printed
    record = json.loads((archive / ".laws" / "LOT-2026-07" / "v0001.json").read_text())
    assert len(record["intervals"]) == 7
    for n in record["intervals"]:
        assert (f"    {n['velocity']:6.1f} m/s: {n['value']:.4f} ({n['low']:.4f} to "
                f"{n['high']:.4f}, +/- ") in said
        assert n["low"] < n["value"] < n["high"]
    by_name, by_sheet = tmp_path / "by_name.xlsx", tmp_path / "by_sheet.xlsx"
    assert main(["fill", str(TEMPLATE), "--crush-law", "LOT-2026-07", "--archive",
                 str(archive), "-o", str(by_name), "--name", "shot"]) == 0
    assert main(["fill", str(calibrated), "-o", str(by_sheet)]) == 0

    def accel(path):
        ws = openpyxl.load_workbook(path, read_only=True).worksheets[0]
        return np.array([r[0] for r in ws.iter_rows(min_row=3, max_row=12001, min_col=21,
                                                    max_col=21, values_only=True)])

    np.testing.assert_array_equal(accel(by_name), accel(by_sheet))
    provenance = Archive(archive).get("shot").load("provenance.json")
    assert provenance["crush_law"]["name"] == "fitted (LOT-2026-07@1)"
    capsys.readouterr()
    assert main(["history", "--archive", str(archive)]) == 0
    out = capsys.readouterr().out
    assert "LOT-2026-07@1" in out and "fitted on 1 shot" in out
    law_line = next(line for line in out.splitlines()
                    if line.strip().startswith("LOT-2026-07@1"))
    assert " holds at " in law_line and " -" not in law_line  # no negative speed said
    assert main(["fill", str(TEMPLATE), "--crush-law", "LOT-9", "--archive", str(archive),
                 "-o", str(tmp_path / "x.xlsx")]) == 2
    assert "there: LOT-2026-07@1" in capsys.readouterr().err
