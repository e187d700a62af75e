"""Issue 44: one grammar for every quantity. The units are one table (airgun_xl.units) that
the options, profiles, the Specification sheet, design's targets and recordings' headers
all read; the same text is read alike, or refused in the same words, wherever it is given."""
import argparse
import json

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airgun_xl import units
from airgun_xl.cli.spec_options import options_spec
from airgun_xl.errors import AirgunXlError
from airgun_xl.readers.recording import read_trace
from airgun_xl.readers.spec_sheet import FIRST_ROW, ROWS
from airgun_xl.readers.spec_sheet import spec_from_cells as sheet_spec
from airgun_xl.specification import load_profile, parse_target


@pytest.mark.parametrize("unit", sorted(units.PEAK_UNITS))
def test_a_recordings_acceleration_header_reads_every_unit_an_option_does(unit, tmp_path):
    """One kG-equivalent per unit: a recording of 1 <unit> reads what --peak 1<unit> reads
    (the header's ² is the option's ²)."""
    path = tmp_path / "r.csv"
    path.write_text(f"time [s],acceleration [{unit}]\n" + "".join(
        f"{k * 1e-5!r},1\n" for k in range(32)), encoding="utf-8")
    trace = read_trace(str(path))
    assert trace.accel_kg[0] == pytest.approx(parse_target("peak", f"1{unit}", "--peak"),
                                              rel=1e-15)


@pytest.mark.parametrize("unit", sorted(units.TIME_UNITS))
def test_a_recordings_time_header_reads_every_unit_an_option_does(unit, tmp_path):
    """Recordings' headers knew neither ns nor µs's other spelling: the step of a record
    in <unit> is what --duration 1<unit> reads."""
    path = tmp_path / "r.csv"
    path.write_text(f"time [{unit}],acceleration [kG]\n" + "".join(
        f"{k},1\n" for k in range(32)), encoding="utf-8")
    trace = read_trace(str(path))
    assert trace.dt == pytest.approx(parse_target("duration", f"1{unit}", "--duration"),
                                     rel=1e-12)


def _option(text):
    ns = argparse.Namespace(peak=text)
    try:
        return options_spec(ns).peak.nominal
    except AirgunXlError as exc:
        return str(exc).removeprefix("--peak: ")


def _target(text):
    try:
        return parse_target("peak", text, "--target-peak")
    except AirgunXlError as exc:
        return str(exc).removeprefix("--target-peak: ")


def _profile(text, folder):
    path = folder / "profile.json"
    path.write_text(json.dumps({"peak": text}))
    try:
        return load_profile(str(path)).peak.nominal
    except AirgunXlError as exc:
        return str(exc).partition(": peak: ")[2]


PEAK_ROW = FIRST_ROW + [name for name, _, _ in ROWS].index("peak")


def _sheet(text):
    """The Specification sheet's Peak cell holding ``text`` (as typed: a text cell)."""
    try:
        return sheet_spec({(PEAK_ROW, 2): (text, None)}).peak.nominal
    except AirgunXlError as exc:
        return str(exc).removeprefix(f"'Specification'!B{PEAK_ROW} (Peak): ")


TEXT = st.one_of(st.text(max_size=14).filter(lambda t: ":" not in t and t.strip()),
                 st.sampled_from(["12kG", "12KG", "12kg", "11750g", "1.2e5m/s^2", "1.2e5m/s²",
                                  "9800m/s2", "12 kG", "-1kG", "+1kG", "0kG", "1e999kG",
                                  "12", "kG", "nan kG", "1e-7kG", "12Kg", "12 g"]))


@settings(max_examples=200, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(text=TEXT)
def test_an_option_a_profile_a_sheet_and_a_design_target_read_a_peak_alike(text, tmp_path):
    """``--peak X``, a profile's ``"peak": X``, the Specification sheet's Peak cell holding
    the text X, and ``design --target-peak X`` (a peak without a tolerance): the same value,
    or the same refusal after the place's name."""
    option, target, profile = _option(text), _target(text), _profile(text, tmp_path)
    sheet = _sheet(text)
    assert option == target == profile == sheet, (text, option, target, profile, sheet)


#: Durations as a user types them, among them the three the two readers once disagreed on
#: (issue 61): a trailing point, a bare number, a step below a nanosecond.
DURATIONS = ["5ms", "5 ms", "5.ms", ".5ms", "+5ms", "-5ms", "5e-3s", "5MS", "5µs", "5e0us",
             "0.5e1ms", " 5ms ", "1e-12s", "5 s", "11s", "5 parsecs", ""]


@pytest.mark.parametrize("text", DURATIONS)
def test_a_time_step_and_a_specifications_duration_are_read_by_one_grammar(text):
    """convergence's --levels (units.parse_duration) and the specification's duration read
    every text alike, or refuse it in the same words; a bare number, which the ladder takes
    as seconds, is the one difference, and reads as the same text with "s"."""
    from airgun_xl.specification import KEYS

    def read(parse, given):
        try:
            return parse(given, "--x")
        except AirgunXlError as exc:
            return str(exc)

    assert read(units.parse_duration, text) == read(KEYS["duration"].parse, text)
    assert units.parse_duration("5e-3", "--x") == read(KEYS["duration"].parse, "5e-3s")
