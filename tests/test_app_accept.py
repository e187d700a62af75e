"""Issue 44: accept as a function (airgun_xl.app.accept.run) and as the Python API
(airgun_xl.accept), driven without the CLI.

The pulses are constructed: a 40 g, 11 ms half-sine with 5 ms of rest each side, sampled at
51.2 kHz with no noise, written to CSV with every digit (repr); the template's shot (its
Specification sheet empty) gives only the shot's warnings."""
import dataclasses
import inspect
import subprocess
import sys

import numpy as np
import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.app.accept import AcceptRequest, run
from airgun_xl.app.specifying import PLAIN_OPTIONS, QUANTITY_OPTIONS, SpecFields, SpecKeywords
from airgun_xl.cli import main
from airgun_xl.errors import OptionError
from airgun_xl.specification import OPTIONS
from airgun_xl.studies.acceptance import ideal
from airgun_xl.units import KG_MS2, G

A_G, D, REST, RATE = 40.0, 11e-3, 5e-3, 51_200.0
A = A_G * G / KG_MS2  # [kG]


@pytest.fixture
def recording(tmp_path):
    t = np.arange(0.0, 2 * REST + D, 1 / RATE)
    kg = ideal("half-sine", t - REST, A, D)
    path = tmp_path / "rec.csv"
    path.write_text("time [s],acceleration [kG]\n" + "\n".join(
        f"{float(a)!r},{float(b)!r}" for a, b in zip(t, kg, strict=True)) + "\n")
    return path


def test_the_api_judges_an_ideal_half_sine_by_its_keywords(recording):
    """40 g:10 %, 11 ms:10 %, a half-sine judged unfiltered: the peak within 1e-5 of 40 g
    (the nearest sample to the crest is at most 1/(2 x 51.2 kHz) off it:
    1 - cos(pi x 9.8 us / 11 ms) = 4e-6), the duration (the base, from the 10 % crossings
    interpolated between samples) within 1e-5 of 11 ms (O((dt/D)^2) = 3e-6), the corridor's
    margin its 20 % (the tool's default half-width) to 1e-6 %."""
    v = airgun_xl.accept(TEMPLATE, recording, shape="half-sine", peak="40g:10%",
                         duration="11ms:10%", cfc="none")
    assert v.passed and v.word == "PASS"
    by = {c.name: c for c in v.criteria}
    assert list(by) == ["peak", "duration", "corridor"]
    assert by["peak"].unit == "g" and by["peak"].value == pytest.approx(40.0, rel=1e-5)
    assert by["peak"].low == pytest.approx(36.0) and by["peak"].high == pytest.approx(44.0)
    assert by["duration"].unit == "ms" and by["duration"].value == pytest.approx(11.0, rel=1e-5)
    assert by["corridor"].margin == pytest.approx(20.0, abs=1e-6)
    # a half-sine's SRS is enveloped by itself: 40 g (0.0400 kG) and 11 ms, to the 2 % of the
    # equivalent's search grid (issue 25)
    peak, duration = v.equivalent_half_sine
    assert peak == pytest.approx(A, rel=2e-2) and duration == pytest.approx(D, rel=2e-2)
    assert v.output is None and v.files == () and v.archived is None
    # where the fields came from, each in the unit it was typed in (not 0.0400271kG)
    assert v.verdict.sources()[0].startswith("from options: peak 40g, peak tolerance 10%, "
                                             "duration 11ms, duration tolerance 10%")
    # the 5 ms of rest are shorter than the default monitoring window (1D = 11 ms each side)
    assert v.warnings == ("corridor: monitored from 0.0000 to 20.9961 ms only, what the "
                          "record holds of the tool's default window (-6.0000 to 27.0000 ms,"
                          " 1D before, 1D after the pulse): give --monitor to judge a window "
                          "of your own",)


def test_a_pulse_out_of_tolerance_fails_and_says_which_criterion(recording):
    v = airgun_xl.accept(TEMPLATE, recording, peak="50g:10%", duration="11ms:10%", cfc="none")
    assert not v.passed and v.word == "FAIL"
    assert [(c.name, c.passed) for c in v.criteria] == [("peak", False), ("duration", True)]
    # 40 g is 20 % under 50 g: 10 % past the lower limit, to the 1e-5 of the peak's reading
    assert v.criteria[0].margin == pytest.approx(-10.0, abs=1e-3)


def test_the_function_and_the_command_give_the_same_verdict(tmp_path, recording, capsys):
    """The CLI is the function: the same figures printed, to the digits printed."""
    out = tmp_path / "cli.xlsx"
    assert main(["accept", str(TEMPLATE), str(recording), "--peak", "40g:10%", "--duration",
                 "11ms:10%", "--cfc", "none", "-o", str(out)]) == 0
    printed = capsys.readouterr().out
    request = AcceptRequest(TEMPLATE, str(recording),
                            SpecFields(peak="40g:10%", duration="11ms:10%", cfc=None,
                                       cfc_given="--cfc"), tmp_path / "app.xlsx")
    outcome = run(request)
    for c in outcome.criteria:
        assert f"PASS  {c.name}: {c.value:.5g} {c.unit}" in printed
    assert outcome.files == (tmp_path / "app.xlsx",) and (tmp_path / "app.xlsx").is_file()
    assert f"{outcome.equivalent_half_sine[0]:.4f} kG" in printed


def test_nothing_is_written_unless_asked_and_what_is_written_is_listed(tmp_path, recording):
    before = sorted(tmp_path.iterdir())
    airgun_xl.accept(TEMPLATE, recording, peak="40g:10%")
    assert sorted(tmp_path.iterdir()) == before
    v = airgun_xl.accept(TEMPLATE, recording, peak="40g:10%", output=tmp_path / "v.xlsx",
                         archive=tmp_path / "lab")
    assert v.archived is not None and v.archived.is_file()
    assert v.files == (v.archived, tmp_path / "v.xlsx")
    assert all(p.is_file() for p in v.files)


@pytest.mark.parametrize("given, named", [
    ({"peak": "12KG"}, "--peak: found the unit 'KG'"),
    ({"peak": "40g:10%", "cfc": 42}, "--cfc: found '42', expected a J211 class"),
    ({"peak": "40g:10%", "sign": 2}, "sign: found 2, expected 1 or -1"),
    ({"peak": "40g:10%", "archive": "lab"}, "--archive: found no verdict workbook"),
    ({}, "its Specification sheet is empty and no option gives a criterion"),
])
def test_bad_keywords_are_refused_naming_the_option_and_write_nothing(tmp_path, recording,
                                                                      given, named):
    before = sorted(tmp_path.rglob("*"))
    with pytest.raises(OptionError) as caught:
        airgun_xl.accept(TEMPLATE, recording, **given)
    assert named in str(caught.value) and "\n" not in str(caught.value)
    assert sorted(tmp_path.rglob("*")) == before


def test_the_keywords_are_the_specifications_fields():
    """One declaration: the API's keywords (SpecKeywords, which accept and design take),
    the request's fields and the grammar's table (specification.OPTIONS) name the same
    fields; a field added to the table and not here fails."""
    table = {key for key, _ in QUANTITY_OPTIONS + PLAIN_OPTIONS} | {"srs", "srs_tol", "profile",
                                                                   "cfc"}
    assert {o for k, o in OPTIONS.items()} == {
        "--" + k.replace("_", "-") for k in table - {"srs", "profile", "cfc"}} | {"--cfc"}
    fields = {f.name for f in dataclasses.fields(SpecFields)}
    assert table <= fields and fields - table == {"window", "cfc_given", "accel_unit"}
    assert set(SpecKeywords.__annotations__) == table
    for function in (airgun_xl.accept, airgun_xl.design):
        assert str(inspect.signature(function).parameters["spec"]).startswith("**spec")


def test_a_keyword_that_is_not_a_field_is_refused_with_the_nearest(recording):
    with pytest.raises(OptionError, match=r"^accept: found the keyword 'peek', expected a "
                                          r"field of the specification \(did you mean peak\?\)$"):
        airgun_xl.accept(TEMPLATE, recording, peek="40g:10%")
    with pytest.raises(OptionError, match="design: found the keyword 'colour', expected a "
                                          "field of the specification .profile, shape, peak"):
        airgun_xl.design(TEMPLATE, colour="red")


def test_importing_the_package_stays_light():
    """accept is a function of the package, and importing the package still loads neither
    numpy nor the application layer (the CLI sets up its signals first)."""
    done = subprocess.run([sys.executable, "-c", "import sys, airgun_xl; "
                           "assert callable(airgun_xl.accept); "
                           "print(sorted(m for m in ('numpy', 'airgun_xl.app', 'pandas') "
                           "if m in sys.modules))"], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


def test_accept_json_is_the_outcome_for_a_lims(tmp_path, recording, capsys):
    """``accept --json``: one JSON document on stdout, the same criteria as the function's,
    the same exit status (3 on FAIL) and the warnings on stderr as well as in the document."""
    import json

    out = tmp_path / "v.xlsx"
    code = main(["accept", str(TEMPLATE), str(recording), "--shape", "half-sine", "--peak",
                 "50g:10%", "--duration", "11ms:10%", "--cfc", "none", "-o", str(out),
                 "--json"])
    captured = capsys.readouterr()
    assert code == 3
    document = json.loads(captured.out)
    outcome = airgun_xl.accept(TEMPLATE, recording, shape="half-sine", peak="50g:10%",
                               duration="11ms:10%", cfc="none")
    assert document["verdict"] == "FAIL" and document["passed"] is False
    assert [(c["name"], c["value"], c["unit"], c["low"], c["high"], c["passed"])
            for c in document["criteria"]] == [
        (c.name, c.value, c.unit, c.low, c.high, c.passed) for c in outcome.criteria]
    assert document["files"] == [str(out)] and document["archived"] is None
    assert document["warnings"] == list(outcome.warnings) != []
    assert all(w in captured.err for w in outcome.warnings)
    assert document["equivalent_half_sine"]["duration_s"] == pytest.approx(D, rel=2e-2)


def test_accept_json_escapes_what_the_files_say(tmp_path, recording, capsys):
    """A recording's name with a terminal's escape sequence reaches stdout escaped (JSON's
    \\u001b), never as the control character itself."""
    import json

    hostile = tmp_path / "rec\x1b[2J.csv"
    hostile.write_bytes(recording.read_bytes())
    assert main(["accept", str(TEMPLATE), str(hostile), "--peak", "40g:10%", "-o",
                 str(tmp_path / "v.xlsx"), "--json"]) == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out and "\\u001b[2J" in out
    assert json.loads(out)["recording"] == str(hostile)


def test_an_archived_verdict_keeps_the_record_it_judged_and_its_corridor(tmp_path, recording):
    """The verdict record keeps the judged workbook's SHA-256 (an archive's entry of that
    workbook is the verdict's run), the record judged (here 1,076 samples: whole) and the
    corridor's limits at its times inside the window monitored, each to 6 significant digits
    (the drawing's precision; the criteria keep full precision), read back by the archive's
    bounded reader (``serve`` draws them on a shot's page)."""
    import hashlib
    import json

    from airgun_xl.studies.acceptance import corridor_limits

    v = airgun_xl.accept(TEMPLATE, recording, shape="half-sine", peak="40g:10%",
                         duration="11ms:10%", cfc="none", archive=tmp_path / "arch",
                         output=tmp_path / "verdict.xlsx")
    record = json.loads(v.archived.read_text())
    assert record["shot_sha256"] == hashlib.sha256(TEMPLATE.read_bytes()).hexdigest()
    trace = record["trace"]
    t, kg = v.verdict.record
    assert trace["samples"] == len(t) == 1076 and trace["thinned"] == "whole"
    assert trace["time_ms"] == [float(f"{x * 1e3:.6g}") for x in t]
    assert trace["kg"] == [float(f"{x:.6g}") for x in kg]
    assert trace["onset_ms"] == float(f"{v.verdict.onset * 1e3:.6g}")
    upper, lower = corridor_limits(v.verdict.spec, t - v.verdict.onset)
    lo, hi = v.verdict.window
    inside = (t >= lo) & (t <= hi)
    assert trace["upper_kg"] == [float(f"{u:.6g}") if k else None
                                 for u, k in zip(upper, inside, strict=True)]
    assert trace["lower_kg"] == [float(f"{x:.6g}") if k else None
                                 for x, k in zip(lower, inside, strict=True)]
    assert None not in trace["upper_kg"]  # the whole record lies in the window monitored


def test_a_long_record_is_kept_as_its_envelope_so_no_peak_is_lost():
    """A record of 1,000,000 samples with a one-sample spike: the kept trace is at most 4,000
    points in time order, holds the spike's value exactly and every span's extremes (so the
    drawn record's largest and smallest values are the record's own)."""
    from types import SimpleNamespace

    from airgun_xl.archive.verdicts import TRACE_SPANS, judged_trace

    t = np.arange(1_000_000) / 1e6
    kg = np.sin(2 * np.pi * 50 * t)
    kg[654_321] = 7.0
    verdict = SimpleNamespace(record=(t, kg), onset=None, window=None,
                              spec=SimpleNamespace(corridor=None))
    trace = judged_trace(verdict)
    assert len(trace["time_ms"]) <= 2 * TRACE_SPANS
    assert all(a < b for a, b in zip(trace["time_ms"], trace["time_ms"][1:], strict=False))
    assert max(trace["kg"]) == 7.0 and min(trace["kg"]) == float(f"{kg.min():.6g}")
    assert trace["time_ms"][trace["kg"].index(7.0)] == float(f"{t[654_321] * 1e3:.6g}")
    assert trace["samples"] == 1_000_000 and trace["upper_kg"] is None
    assert trace["thinned"] == "the smallest and largest sample of each of 2,000 spans"
