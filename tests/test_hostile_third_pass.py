"""Issue 32 (hostile input, third pass): profiles and the archive's records read as the
untrusted input they are, by one bounded, typed reader (airgun_xl/untrusted_json.py), and
every record the tool writes into an archive kept inside it.

Each test is named after the finding it closes. A refusal is exit 2, one line, no traceback,
nothing written or changed; a listing flags a bad record, names it and goes on."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from conftest import TEMPLATE
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airgun_xl.archive.laws import list_laws, load_law, store_law
from airgun_xl.archive.verdicts import list_verdicts
from airgun_xl.cli import main
from airgun_xl.crush_law import LEGACY_COEFFICIENTS, CrushLaw
from airgun_xl.errors import AirgunXlError, ArchiveError
from airgun_xl.untrusted_json import MAX_DEPTH, read_json

POSIX = os.name == "posix"


def one_line(capsys, code, *said):
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    for part in said:
        assert part in lines[0], lines[0]
    return lines[0]


def law(root, name="LOT"):
    return store_law(root, name, CrushLaw(tuple(LEGACY_COEFFICIENTS), (100.0, 300.0),
                                          "fitted"), [], [])


def record_path(root, name="LOT", version=1):
    return root / ".laws" / name / f"v{version:04d}.json"


# -- 1. records written outside the archive ------------------------------------------------------

@pytest.mark.skipif(not POSIX, reason="symlinks as an unprivileged user")
def test_32_1_a_law_folder_that_links_out_of_the_archive_is_refused(tmp_path):
    root, outside = tmp_path / "archive", tmp_path / "outside"
    law(root, "OTHER")  # the archive exists
    outside.mkdir()
    (root / ".laws" / "LOT").symlink_to(outside, target_is_directory=True)
    with pytest.raises(ArchiveError, match=r"LOT: is a link to .*outside, expected the law "
                                           r"inside the archive"):
        law(root)
    assert list(outside.iterdir()) == []


@pytest.mark.skipif(not POSIX, reason="symlinks as an unprivileged user")
def test_32_1_a_verdicts_folder_that_links_out_of_the_archive_is_refused(tmp_path, capsys):
    import numpy as np

    from airgun_xl.studies.acceptance import ideal

    root, outside = tmp_path / "archive", tmp_path / "outside"
    law(root, "OTHER")
    outside.mkdir()
    (root / ".verdicts").symlink_to(outside, target_is_directory=True)
    t = np.arange(0, 15e-3, 1e-5)
    rec = tmp_path / "r.csv"
    rec.write_text("time [s],acceleration [kG]\n" + "\n".join(
        f"{float(a)!r},{float(b)!r}" for a, b in zip(t, ideal("half-sine", t - 5e-3, 12.0,
                                                               5e-3), strict=True)))
    out = tmp_path / "v.xlsx"
    code = main(["accept", str(TEMPLATE), str(rec), "--peak", "12kG:10%", "-o", str(out),
                 "--archive", str(root)])
    one_line(capsys, code, ".verdicts: is a link")
    assert list(outside.iterdir()) == [] and not out.exists()


# -- 3, 5. FIFOs, devices and files too large to be records ---------------------------------------

@pytest.mark.skipif(not POSIX, reason="FIFOs and /dev/zero")
@pytest.mark.parametrize("kind", ["fifo", "/dev/zero", "/dev/urandom"])
def test_32_3_and_5_a_profile_that_is_a_fifo_or_a_device_is_refused_at_once(tmp_path, kind):
    if kind == "fifo":
        path = tmp_path / "profile.json"
        os.mkfifo(path)
    else:
        path = kind
    out = tmp_path / "o.xlsx"
    proc = subprocess.run([sys.executable, "-m", "airgun_xl", "fill", str(TEMPLATE), "-o",
                           str(out), "--profile", str(path)], capture_output=True, text=True,
                          timeout=120)  # a bound on a hang, not a speed test
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "is not a regular file" in lines[0] and not out.exists()


@pytest.mark.skipif(not POSIX, reason="sparse files")
def test_32_5_a_3_gb_sparse_law_record_is_refused_by_its_size(tmp_path):
    root = tmp_path / "archive"
    law(root)
    with open(record_path(root), "r+b") as fh:
        fh.truncate(3 * 2**30)
    with pytest.raises(ArchiveError, match=r"found 3,221,225,472 bytes, expected a law record "
                                           r"of at most 1,048,576"):
        load_law(root, "LOT")
    assert list_laws(root)[0]["created"].startswith("unreadable: ")


# -- 6. a profile's JSON past its bounds ----------------------------------------------------------

@pytest.mark.parametrize("text, said", [
    ("[" * 30_000 + "]" * 30_000, f"nested over {MAX_DEPTH} deep"),
    ('{"peak": ' + "1" * 401 + "}", "an integer of 401 digits"),
    ('{"peak": ' + "1" * 5_001 + "}", "an integer of 5,001 digits"),
    ('{"peak": 1e999}', "past a float"),
    ('{"peak": NaN}', "NaN, which is not JSON"),
])
def test_32_6_a_profile_past_the_readers_bounds_is_one_line(tmp_path, capsys, text, said):
    path = tmp_path / "p.json"
    path.write_text(text)
    code = main(["fill", str(TEMPLATE), "-o", str(tmp_path / "o.xlsx"), "--profile",
                 str(path)])
    one_line(capsys, code, f"--profile {path}: ", said)


# -- 7, 11. archive records edited by hand or by a broken disk ------------------------------------

BAD_LAWS = {
    "v_range of text": {"coefficients": list(LEGACY_COEFFICIENTS), "v_range": ["a", "b"]},
    "v_range of nulls": {"coefficients": list(LEGACY_COEFFICIENTS), "v_range": [None, None]},
    "coefficients as text (11)": {"coefficients": "1234567", "v_range": [100, 300]},
    "an empty object": {},
    "a list": [1, 2, 3],
}


@pytest.mark.parametrize("name", sorted(BAD_LAWS))
def test_32_7_and_11_a_bad_law_is_flagged_by_history_and_refused_by_fill(tmp_path, capsys,
                                                                         name):
    root = tmp_path / "archive"
    law(root)
    law(root, "GOOD")
    record_path(root).write_text(json.dumps(BAD_LAWS[name]))
    assert main(["history", "--archive", str(root)]) == 0
    out = capsys.readouterr().out
    assert "LOT@1" in out and "unreadable: " in out and "GOOD@1" in out
    code = main(["fill", str(TEMPLATE), "--crush-law", "LOT", "--archive", str(root), "-o",
                 str(tmp_path / "o.xlsx")])
    one_line(capsys, code, "v0001.json: ")
    assert not (tmp_path / "o.xlsx").exists()


@pytest.mark.parametrize("text, said", [
    ('{"coefficients": [' + "1" * 401 + ',0,0,0,0,0,0], "v_range": [100, 300]}',
     "an integer of 401 digits"),
    ('{"coefficients": [0,0,0,0,0,0,0], "v_range": [-Infinity, Infinity]}',
     "-Infinity, which is not JSON"),
    ('{"coefficients": ' + "[" * 40 + "]" * 40 + "}", "nested over 32 deep"),
])
def test_32_7_fill_refuses_a_law_past_the_readers_bounds(tmp_path, capsys, text, said):
    root = tmp_path / "archive"
    law(root)
    record_path(root).write_text(text)
    code = main(["fill", str(TEMPLATE), "--crush-law", "LOT", "--archive", str(root), "-o",
                 str(tmp_path / "o.xlsx")])
    one_line(capsys, code, said)


def test_32_7_a_law_version_of_5000_digits_is_one_line(tmp_path, capsys):
    root = tmp_path / "archive"
    law(root)
    code = main(["fill", str(TEMPLATE), "--crush-law", "LOT@" + "9" * 5_000, "--archive",
                 str(root), "-o", str(tmp_path / "o.xlsx")])
    line = one_line(capsys, code, "--crush-law: found")
    assert len(line) < 600


def test_32_7_a_verdict_record_of_an_empty_object_is_flagged(tmp_path):
    folder = tmp_path / "archive" / ".verdicts" / "shot"
    folder.mkdir(parents=True)
    (folder / "v0001.json").write_text("{}")
    (folder / "v0002.json").write_text('{"shot": "shot", "verdict": "PASS", "criteria": []}')
    listed = list_verdicts(tmp_path / "archive")
    assert listed[0]["verdict"] == "?"
    assert "the record: found {}, expected the fields shot, verdict, criteria" in listed[0][
        "created"]
    assert listed[1]["verdict"] == "PASS"


@pytest.fixture(scope="module")
def entry(tmp_path_factory):
    """An archive with one entry of shot A, judged by a specification (its summary.json has a
    predicted verdict)."""
    root = tmp_path_factory.mktemp("entry") / "archive"
    assert main(["fill", str(TEMPLATE), "--archive", str(root), "--name", "shot", "-o",
                 str(root.parent / "o.xlsx"), "--peak", "12kG:10%"]) == 0
    return root, next(root.glob("shot/v*/summary.json"))


EDITS = {
    "peak as text": lambda s: {**s, "peak_kg": "12 kG"},
    "verdict as a number": lambda s: {**s, "predicted_verdict": 3},
    "verdict without criteria": lambda s: {**s, "predicted_verdict": {"verdict": "PASS"}},
    "a criterion without a value": lambda s: {**s, "predicted_verdict": {
        "verdict": "PASS", "criteria": [{"name": "peak"}]}},
    "a criterion's value as text": lambda s: {**s, "predicted_verdict": {
        "verdict": "PASS", "criteria": [{"name": "peak", "value": "x", "unit": "kG",
                                         "margin": 1.0, "margin_unit": "%",
                                         "passed": True}]}},
    "a verdict word unknown": lambda s: {**s, "predicted_verdict": {
        "verdict": "MAYBE", "criteria": []}},
    "criteria as an object": lambda s: {**s, "predicted_verdict": {
        "verdict": "PASS", "criteria": {"peak": 1}}},
    "warnings as a number": lambda s: {**s, "warnings": 7},
}


@pytest.mark.parametrize("name", sorted(EDITS))
def test_32_7_show_refuses_an_edited_summary_and_history_flags_it(entry, capsys, name):
    root, summary = entry
    kept = summary.read_bytes()
    try:
        summary.write_text(json.dumps(EDITS[name](json.loads(kept))))
        code = main(["show", "shot@1", "--archive", str(root)])
        # refused as verify reports it (issue 43): altered, before its schema is read
        one_line(capsys, code, "shot@1: summary.json altered (SHA-256 differs)")
        assert main(["history", "--archive", str(root)]) == 0
        assert "unreadable: shot@1: summary.json" in capsys.readouterr().out
    finally:
        summary.write_bytes(kept)


@pytest.mark.skipif(not POSIX, reason="symlinks as an unprivileged user")
def test_32_5_a_summary_that_links_to_dev_zero_is_refused(entry, capsys):
    root, summary = entry
    kept = summary.read_bytes()
    summary.unlink()
    try:
        summary.symlink_to("/dev/zero")
        code = main(["show", "shot@1", "--archive", str(root)])
        one_line(capsys, code, "summary.json is a link to /dev/zero")
    finally:
        summary.unlink()
        summary.write_bytes(kept)


# -- 15. what a record holds is printed as text ---------------------------------------------------

def test_32_15_history_prints_no_escape_sequence_from_a_record(tmp_path, capsys):
    law(tmp_path / "archive", "OTHER")
    folder = tmp_path / "archive" / ".verdicts" / "shot"
    folder.mkdir(parents=True)
    (folder / "v0001.json").write_text(json.dumps(
        {"shot": "shot\x1b[2J", "verdict": "PASS", "criteria": [], "created": "\x1b]0;x\x07",
         "recording": "r.csv\x1b[31m"}))
    assert main(["history", "--archive", str(tmp_path / "archive")]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\x07" not in out and "shot\\x1b[2J" in out


# -- the invariant, over random records -----------------------------------------------------------

RECORD = st.recursive(
    st.one_of(st.none(), st.booleans(), st.integers(-10**6, 10**6), st.floats(allow_nan=False,
                                                                              allow_infinity=False),
              st.text(max_size=8)),
    lambda inner: st.one_of(st.lists(inner, max_size=4),
                            st.dictionaries(st.sampled_from(
                                ["coefficients", "v_range", "shot", "verdict", "criteria",
                                 "created", "recording", "name", "x"]), inner, max_size=5)),
    max_leaves=12)


@settings(max_examples=150, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(laws=st.lists(RECORD, min_size=1, max_size=3), verdicts=st.lists(RECORD, max_size=3))
def test_a_listing_never_fails_on_a_bad_record_and_a_load_refuses_it_in_one_line(
        tmp_path, laws, verdicts):
    import shutil

    root = tmp_path / "archive"
    shutil.rmtree(root, ignore_errors=True)
    law(root, "OTHER")
    for k, record in enumerate(laws, 1):
        folder = root / ".laws" / "RANDOM"
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"v{k:04d}.json").write_text(json.dumps(record))
    for k, record in enumerate(verdicts, 1):
        folder = root / ".verdicts" / "shot"
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"v{k:04d}.json").write_text(json.dumps(record))
    listed = list_laws(root)
    assert len(listed) == len(laws) + 1
    assert len(list_verdicts(root)) == len(verdicts)
    for k in range(1, len(laws) + 1):
        try:
            load_law(root, f"RANDOM@{k}")
        except AirgunXlError as exc:
            assert "\n" not in str(exc) and len(str(exc)) < 600


def test_the_reader_refuses_what_the_library_would_choke_on(tmp_path):
    path = tmp_path / "r.json"
    path.write_text('{"coefficients": [1,2,3,4,5,6,7], "v_range": [1, 2]}')
    assert read_json(path, "law", "r")["v_range"] == [1, 2]
    path.write_text('{"coefficients": [1,2,3,4,5,6], "v_range": [1, 2]}')
    with pytest.raises(AirgunXlError, match=r"r: coefficients: found \[1, 2, 3, 4, 5, 6\], "
                                            r"expected 7 numbers"):
        read_json(path, "law", "r")


# -- 2. a campaign's summary that is one of its shots ---------------------------------------------

def test_32_2_a_summary_that_is_an_input_shot_is_refused_before_any_shot(tmp_path, capsys):
    import shutil

    day = tmp_path / "day"
    day.mkdir()
    for name in ("shot_01.xlsx", "shot_02.xlsx"):
        shutil.copy(TEMPLATE, day / name)
    kept = (day / "shot_01.xlsx").read_bytes()
    code = main(["fill", str(day), "--summary", str(day / "shot_01.xlsx"), "--force"])
    one_line(capsys, code, "--summary: found", "one of the campaign's shots")
    assert (day / "shot_01.xlsx").read_bytes() == kept
    assert sorted(p.name for p in day.iterdir()) == ["shot_01.xlsx", "shot_02.xlsx"]
    code = main(["fill", str(day), "--summary", str(day / "shot_02.out.xlsx")])
    one_line(capsys, code, "the output of one of the campaign's shots")
    assert sorted(p.name for p in day.iterdir()) == ["shot_01.xlsx", "shot_02.xlsx"]


# -- 4, 8. an SRS the record cannot resolve, and a slow record's spectra ---------------------------

def _csv(path, t, kg):
    path.write_text("time [s],acceleration [kG]\n" + "\n".join(
        f"{float(a)!r},{float(b)!r}" for a, b in zip(t, kg, strict=True)) + "\n")
    return path


def test_32_4_an_srs_row_below_what_the_record_resolves_is_refused_at_once(tmp_path, capsys):
    """A 15 ms record and a requirement row at 0.01 Hz (it took 60 s and more to compute)."""
    import time

    import numpy as np

    from airgun_xl.studies.acceptance import ideal

    t = np.arange(0, 15e-3, 1e-5)
    rec = _csv(tmp_path / "r.csv", t, ideal("half-sine", t - 5e-3, 12.0, 5e-3))
    req = tmp_path / "req.csv"
    req.write_text("frequency [Hz],srs [g]\n0.01,10\n1000,20000\n")
    began = time.perf_counter()
    code = main(["accept", str(TEMPLATE), str(rec), "--srs", str(req), "-o",
                 str(tmp_path / "v.xlsx")])
    one_line(capsys, code, "--srs: found a row at 0.01 Hz, below the 66.7 Hz the record's "
                           "14.99 ms can resolve")
    assert time.perf_counter() - began < 30  # a bound on the hang, not a speed test


def test_32_8_a_record_at_500_hz_gets_its_srs_page_not_a_valueerror(tmp_path, capsys):
    """A 20 ms half-sine sampled at 500 Hz (10 samples across it), 10 ms at rest each side."""
    import numpy as np

    from airgun_xl.studies.acceptance import ideal

    t = np.arange(0, 40e-3, 2e-3)
    rec = _csv(tmp_path / "slow.csv", t, ideal("half-sine", t - 10e-3, 12.0, 20e-3))
    out = tmp_path / "v.xlsx"
    code = main(["accept", str(TEMPLATE), str(rec), "--peak", "12kG:10%", "--duration",
                 "20ms:10%", "-o", str(out)])
    captured = capsys.readouterr()
    assert code == 0 and out.exists() and "Traceback" not in captured.err
    assert "from a library" not in captured.err  # no numpy warning either
    assert "10 samples across the nominal duration 20 ms" in captured.err


# -- 9, 14. design --confidence: its options checked before the Monte Carlo ----------------------

def test_32_9_a_negative_seed_is_one_line(tmp_path, capsys):
    code = main(["design", str(TEMPLATE), "--peak", "12kG:10%", "--confidence", "0.9", "--sd",
                 "A28=1%", "--seed", "-1", "-o", str(tmp_path / "d.xlsx")])
    one_line(capsys, code, "--seed: found -1, expected a whole number from 0")


def test_32_14_an_existing_output_is_refused_before_the_monte_carlo(tmp_path, capsys):
    import time

    out = tmp_path / "d.xlsx"
    out.write_bytes(b"kept")
    began = time.perf_counter()
    code = main(["design", str(TEMPLATE), "--peak", "12kG:10%", "--confidence", "0.9",
                 "--sd", "A28=1%", "--shots", "100000", "-o", str(out)])
    one_line(capsys, code, "already exists")
    assert out.read_bytes() == b"kept"
    assert time.perf_counter() - began < 20  # refused before 100,000 shots, not after


# -- 16. a spike past any recorder's range ---------------------------------------------------------

@pytest.mark.parametrize("command", ["accept", "compare-measured"])
def test_32_16_a_1e200_spike_is_named_not_an_inf_noise(tmp_path, capsys, command):
    import numpy as np

    t = np.arange(0, 15e-3, 1e-5)
    kg = np.where((t > 5e-3) & (t < 10e-3), 12 * np.sin(np.pi * (t - 5e-3) / 5e-3), 0.0)
    kg[100] = 1e200
    rec = _csv(tmp_path / "spike.csv", t, kg)
    extra = ["--peak", "12kG:10%"] if command == "accept" else []
    code = main([command, str(TEMPLATE), str(rec), *extra, "-o", str(tmp_path / "o.xlsx")])
    line = one_line(capsys, code, "found 1e+200 kG at 1.0000 ms")
    assert "inf" not in line


# -- 17. npTDMS's own log lines --------------------------------------------------------------------

@pytest.mark.parametrize("damage", ["truncated", "garbage", "huge string length"])
def test_32_17_a_broken_tdms_file_is_one_line_with_none_of_nptdms_log_lines(tmp_path, damage):
    """A TDMS file written by npTDMS, then cut to its first 40 bytes, overwritten with
    random bytes after its lead-in (seed 3), or given a 2**31-byte object path length."""
    import numpy as np
    from nptdms import ChannelObject, TdmsWriter

    good = tmp_path / "good.tdms"
    with TdmsWriter(str(good)) as writer:
        writer.write_segment([ChannelObject("g", "accel", np.linspace(0, 1, 500),
                                            properties={"wf_increment": 1e-5})])
    data = bytearray(good.read_bytes())
    if damage == "truncated":
        data = data[:40]
    elif damage == "garbage":
        data[28:] = np.random.default_rng(3).integers(0, 256, len(data) - 28,
                                                      dtype=np.uint8).tobytes()
    else:
        data[32:36] = (2**31).to_bytes(4, "little")
    bad = tmp_path / "bad.tdms"
    bad.write_bytes(bytes(data))
    proc = subprocess.run([sys.executable, "-m", "airgun_xl", "compare-measured",
                           str(TEMPLATE), str(bad), "-o", str(tmp_path / "c.xlsx")],
                          capture_output=True, text=True, timeout=120)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr
    assert "bad.tdms" in lines[0] and "nptdms" not in proc.stderr.lower().replace(
        "needs nptdms", "")


# -- 13. a campaign names a failed shot once ------------------------------------------------------

def test_32_13_a_campaign_names_a_failed_shot_once_and_a_bad_profile_before_any(tmp_path,
                                                                                 capsys):
    import shutil

    day = tmp_path / "day"
    day.mkdir()
    shutil.copy(TEMPLATE, day / "a_good.xlsx")
    (day / "b_bad.xlsx").write_bytes(b"not a workbook at all")
    main(["fill", str(day)])
    err = capsys.readouterr().err
    line = next(x for x in err.splitlines() if "b_bad.xlsx" in x)
    assert line.count("b_bad.xlsx") == 1, line
    filled = (day / "a_good.out.xlsx").read_bytes()
    bad = tmp_path / "p.json"
    bad.write_text('{"peak": "12kg"}')
    code = main(["fill", str(day), "--profile", str(bad), "--force"])
    one_line(capsys, code, "did you mean kG?")  # once, before any shot
    assert (day / "a_good.out.xlsx").read_bytes() == filled  # no shot was run again


# -- 12. accept on a recording longer than a sheet ------------------------------------------------

def test_32_12_accept_judges_a_recording_of_1_2_million_samples(tmp_path, capsys):
    """1,200,000 samples (past Excel's 1,048,576 rows) at 1 MHz: a 5 ms half-sine after 2 ms
    of rest, then the rest of 1.2 s: judged on every sample, charted by each bucket's least
    and largest (it was refused after judging, naming an option accept does not have)."""
    import numpy as np
    import openpyxl

    from airgun_xl.studies.acceptance import ideal

    t = np.arange(1_200_000) * 1e-6
    kg = ideal("half-sine", t - 2e-3, 12.0, 5e-3)
    rec = tmp_path / "long.csv"
    rec.write_text("time [s],acceleration [kG]\n" + "\n".join(
        f"{a!r},{b!r}" for a, b in zip(t.tolist(), kg.tolist(), strict=True)) + "\n")
    out = tmp_path / "v.xlsx"
    code = main(["accept", str(TEMPLATE), str(rec), "--peak", "12kG:10%", "--duration",
                 "5ms:10%", "-o", str(out)])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    ws = openpyxl.load_workbook(out, read_only=True)["Pulse"]
    said = str(next(ws.iter_rows(max_row=1, values_only=True)))
    assert "of the record's 1,200,000 samples" in said and "every sample was judged" in said


def test_32_4_an_srs_past_its_cost_cap_is_refused_before_it_is_computed(tmp_path, capsys):
    """2,000 requirement rows over a 150,000-sample record: 3e8 filter steps, past the 2e8
    cap (docs/security.md), refused at once naming --srs."""
    import time

    import numpy as np

    from airgun_xl.studies.acceptance import ideal

    t = np.arange(150_000) * 1e-6
    rec = _csv(tmp_path / "r.csv", t, ideal("half-sine", t - 2e-3, 12.0, 5e-3))
    req = tmp_path / "req.csv"
    f = np.geomspace(100, 50_000, 2_000)
    req.write_text("frequency [Hz],srs [g]\n" + "\n".join(f"{x!r},100" for x in f.tolist()))
    began = time.perf_counter()
    code = main(["accept", str(TEMPLATE), str(rec), "--srs", str(req), "-o",
                 str(tmp_path / "v.xlsx")])
    one_line(capsys, code, "--srs: found 2,000 rows over the record's 150,000 samples",
             "expected at most 2e+08")
    assert time.perf_counter() - began < 30  # refused, not computed (a bound, not a speed)


def test_32_10_a_worker_killed_by_sigkill_loses_its_shot_only(tmp_path):
    """SIGKILL the worker filling a shot of six (two jobs) while its workbook is staged (the
    temp file names its owner's pid): that shot is named as lost in one line, the five others
    are filled, the summary is written with the lost row, exit 2, no traceback, and no temp
    file of the dead worker is left."""
    import re
    import signal
    import time

    import openpyxl
    from conftest import template_with

    day = tmp_path / "day"
    day.mkdir()
    for k in range(6):
        template_with(day, A28=150.0 + 10 * k, A29=150.0 + 10 * k,
                      A30=150.0 + 10 * k).rename(day / f"s{k}.xlsx")
    summary = tmp_path / "day.xlsx"
    proc = subprocess.Popen([sys.executable, "-m", "airgun_xl", "fill", str(day), "--jobs", "2",
                             "--summary", str(summary)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    owner = re.compile(r"^\.(s\d)\.out\.xlsx\.(\d+)\.\d+\.[a-z][a-z0-9]*-[0-9a-f]{16}"
                       r"\.airgun-xl-tmp$")
    deadline = time.monotonic() + 120
    killed = None
    while killed is None and proc.poll() is None:  # polled, not slept
        assert time.monotonic() < deadline
        for path in day.iterdir():
            m = owner.match(path.name)
            if m:
                os.kill(int(m[2]), signal.SIGKILL)
                killed = m[1]
                break
        else:
            time.sleep(0.005)
    out, err = proc.communicate(timeout=300)
    assert killed is not None, (out, err)
    assert proc.returncode == 2, (out, err)
    assert "Traceback" not in err and "BrokenProcessPool" not in err
    lost = [line for line in err.splitlines() if ": lost: " in line]
    assert len(lost) == 1 and "died before the shot was published" in lost[0], err
    name = re.search(r"error: (\S+\.xlsx): lost", lost[0])[1]
    filled = sorted(p.name for p in day.glob("*.out.xlsx"))
    assert len(filled) == 5 and Path(name).name.replace(".xlsx", ".out.xlsx") not in filled
    assert "6 shots: 5 filled, 0 failed, 1 lost, 0 skipped" in out
    assert "1 of 6 shots lost with their worker (each said above)" in err
    rows = list(openpyxl.load_workbook(summary)["Shots"].values)
    assert sum(1 for r in rows if "lost" in r) == 1
    assert [p.name for p in day.iterdir() if ".airgun-xl-" in p.name] == []
