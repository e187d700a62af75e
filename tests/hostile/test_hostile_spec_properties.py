"""Issue 25 (property tests): the specification's readers (the options, a profile file, the
Specification sheet) fed random input either give a specification that passes its checks, or
refuse with one line naming the option, file or cell; `accept` refuses bad options with exit 2
and writes nothing."""
import argparse
import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airgun_xl.cli import main
from airgun_xl.cli.spec_options import options_spec
from airgun_xl.errors import AirgunXlError
from airgun_xl.readers.spec_sheet import ROWS, spec_from_cells
from airgun_xl.specification import check, load_profile

TEXT = st.one_of(st.text(max_size=12), st.sampled_from([
    "12kG:10%", "12kG", "0.3ms:10%", "35m/s:-10%,+20%", "12kG:150%", ":10%", "12kG:",
    "-5kG:10%", "1e999kG:10%", "nan", "20%", "0%", "100%", "-3dB,+6dB", "3dB,-6dB", "cfc600",
    "cfc7", "unfiltered", "half-sine", "square", "5ms", "0ms", "-1ms"]))
OPTIONS = ("peak", "duration", "velocity_change", "corridor", "time_slack", "window")


def namespace(values):
    ns = argparse.Namespace(profile=None, shape=None, peak=None, duration=None,
                            velocity_change=None, corridor=None, time_slack=None, window=None,
                            dv_window=None, monitor=None, duration_def=None, decay=None,
                            placement=None, record=None, srs=None, srs_tol=None, srs_q=None,
                            srs_outside=None, accel_unit=None)
    for name, value in values.items():
        setattr(ns, name, value)
    return ns


@settings(max_examples=300, deadline=None, derandomize=True)
@given(values=st.dictionaries(st.sampled_from(OPTIONS + ("shape", "placement")), TEXT,
                              max_size=5))
def test_random_options_give_a_checked_specification_or_one_line(values):
    try:
        spec = options_spec(namespace(values))
        if spec is None:
            return
        check(spec, "the specification")
    except AirgunXlError as exc:
        text = str(exc)
        assert text and "\n" not in text and len(text) < 400
        return
    for name in ("peak", "duration", "velocity_change"):
        tol = getattr(spec, name)
        assert tol is None or (tol.nominal > 0 and 0 <= tol.minus < 1 and 0 <= tol.plus < 1)


CELL = st.one_of(st.none(), st.floats(allow_nan=True, allow_infinity=True), st.booleans(),
                 st.integers(-10, 10**6), st.text(max_size=10),
                 st.sampled_from(["half-sine", "none", "CFC 600", "unfiltered", "peak", ""]))


@settings(max_examples=300, deadline=None, derandomize=True)
@given(cells=st.dictionaries(st.tuples(st.integers(1, len(ROWS) + 3), st.integers(1, 8)),
                             CELL, max_size=12))
def test_random_specification_sheets_give_a_specification_or_one_line(cells):
    block = {pos: (value, None) for pos, value in cells.items()}
    try:
        spec = spec_from_cells(block)
        if spec is not None:
            check(spec, "the sheet")
    except AirgunXlError as exc:
        text = str(exc)
        assert text and "\n" not in text
        assert "'Specification'" in text or "the sheet" in text or "Specification" in text


@settings(max_examples=100, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(content=st.one_of(st.text(max_size=200), st.dictionaries(
    st.sampled_from(["shape", "peak_tolerance", "corridor", "notes", "bogus", "window"]),
    st.one_of(st.floats(allow_nan=True), st.text(max_size=8), st.lists(st.integers(),
                                                                        max_size=2)),
    max_size=4).map(json.dumps)))
def test_random_profile_files_give_a_profile_or_one_line(tmp_path, content):
    path = tmp_path / "profile.json"
    path.write_text(content)
    try:
        load_profile(str(path))
    except AirgunXlError as exc:
        assert "\n" not in str(exc) and "profile" in str(exc)


@pytest.mark.parametrize("flags", [
    ["--peak", "12kG:10%", "--corridor", "abc"],
    ["--duration", "-5ms:10%"],
    ["--velocity-change", "fast:10%"],
    ["--peak", "12kG:10%", "--window", "1e400ms"],
    ["--shape", "square", "--peak", "12kG:10%"],
])
def test_accept_refuses_and_writes_nothing(tmp_path, capsys, flags):
    from conftest import TEMPLATE

    recording = tmp_path / "r.csv"
    recording.write_text("time [ms],acceleration [g]\n0,0\n0.02,1\n0.04,0\n")
    out = tmp_path / "out.xlsx"
    code = main(["accept", str(TEMPLATE), str(recording), "-o", str(out), *flags])
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.csv"]
