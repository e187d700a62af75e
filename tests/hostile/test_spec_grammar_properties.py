"""Issue 30 (property tests, hypothesis, derandomized): the specification's merge and grammar
hold four named invariants.

- **precedence**: for every field of :class:`Specification` (iterated from ``fields()``, so a
  new field is covered or the test fails), option over sheet over profile over default;
- **round trip**: a value printed in the tool's own syntax parses back to itself, exactly;
- **sources agree**: the same value through an option, a sheet cell or a profile key gives
  the same specification;
- **any random string**: every option, profile key and sheet cell fed random text ends in a
  checked value or one line naming that option, key or cell.
"""
import argparse
import json
import math
from dataclasses import fields

import pytest
from conftest import command_options
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airgun_xl.cli.commands import build_parser
from airgun_xl.cli.spec_options import PLAIN_OPTIONS, QUANTITY_OPTIONS, options_spec
from airgun_xl.errors import AirgunXlError
from airgun_xl.readers.spec_sheet import FIRST_ROW, ROWS, spec_from_cells
from airgun_xl.specification import (
    CAPS,
    CFC_CLASSES,
    DEFAULTS,
    DURATION_DEFS,
    KEYS,
    OPTIONS,
    PLACEMENTS,
    SHAPE_DEFAULTS,
    SHAPES,
    UNFILTERED,
    Specification,
    SrsRequirement,
    cfc_record,
    combine,
    from_keys,
    judged_fields,
    load_profile,
    spec_of_keys,
    value_of,
)

SETTINGS = settings(max_examples=150, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.function_scoped_fixture])


def fraction(low_open=False):
    return st.floats(1e-9 if low_open else 0.0, 0.999, allow_nan=False)


#: A valid inside value of each grammar key. A key added to the grammar without one here
#: fails test_every_key_and_field_has_a_strategy.
VALUES = {
    "shape": st.sampled_from(SHAPES),
    "peak": st.floats(1e-6, CAPS["peak"]),
    "peak_tolerance": st.tuples(fraction(), fraction()),
    "duration": st.floats(1e-9, CAPS["duration"]),
    "duration_tolerance": st.tuples(fraction(), fraction()),
    "velocity_change": st.floats(1e-6, CAPS["velocity_change"]),
    "velocity_change_tolerance": st.tuples(fraction(), fraction()),
    "corridor": fraction(low_open=True),
    "time_slack": fraction(),
    "dv_window": st.tuples(*[st.one_of(st.tuples(st.floats(0.0, CAPS["window"]), st.just("s")),
                                        st.tuples(st.floats(0.0, CAPS["window_d"]),
                                                  st.just("D")))] * 2),
    "monitor": st.tuples(*[st.one_of(st.tuples(st.floats(0.0, CAPS["window"]), st.just("s")),
                                      st.tuples(st.floats(0.0, CAPS["window_d"]),
                                                st.just("D")))] * 2),
    "duration_def": st.sampled_from(DURATION_DEFS),
    "decay": fraction(),
    "record": st.sampled_from((UNFILTERED, *map(cfc_record, CFC_CLASSES))),
    "placement": st.sampled_from(PLACEMENTS),
    "srs_q": st.floats(0.5, CAPS["srs_q"], exclude_min=True),
    "srs_lower_db": st.floats(-CAPS["db"], 0.0),
    "srs_upper_db": st.floats(0.0, CAPS["db"]),
    "srs_outside": fraction(),
}
#: The SRS requirement's rows: not a text key (a CSV file or the sheet's F and G columns).
ROWS_REQ = st.integers(1, 5).map(lambda n: SrsRequirement(
    tuple(100.0 * 2 ** k for k in range(n)), tuple(10.0 + k for k in range(n))))

#: Fields every source spec carries so that the merged one can be judged (a corridor needs a
#: shape, a peak and a duration; the SRS fields need rows).
BASE = {"shape": "half-sine", "peak": 12.0, "peak_tolerance": (0.1, 0.1), "duration": 5e-3,
        "duration_tolerance": (0.1, 0.1), "velocity_change": 35.0,
        "velocity_change_tolerance": (0.2, 0.2)}


def test_every_key_and_field_has_a_strategy():
    assert set(VALUES) == set(KEYS)
    covered = {KEYS[k].field for k in KEYS} | {"srs"}
    assert set(judged_fields()) == covered, "a Specification field no source can give"
    assert [f.name for f in fields(Specification) if f.metadata.get("meta")] == [
        "source", "notes", "origins", "places", "set_aside", "units"]


def keys_of(name):
    return [k for k in KEYS if KEYS[k].field == name]


SOURCES = ("profile lab", "the 'Specification' sheet", "options")


@SETTINGS
@given(data=st.data())
def test_precedence_option_over_sheet_over_profile_over_default(data):
    for name in judged_fields():
        keys = keys_of(name) if name != "srs" else ["srs"]
        drawn = {}  # (source, key) -> value, for the sources that give it
        for source in SOURCES:
            for key in keys:
                if key == "srs" and source == "profile lab":
                    continue  # a profile carries no rows
                if data.draw(st.booleans(), label=f"{source} gives {key}"):
                    drawn[source, key] = data.draw(ROWS_REQ if key == "srs" else VALUES[key],
                                                   label=f"{source} {key}")
        parts = []
        for source in SOURCES:
            parsed = {key: v for (src, key), v in drawn.items() if src == source and
                      key != "srs"}
            if source == "profile lab":  # what a judged specification needs
                parsed = {**BASE, **parsed}
            rows = drawn.get((source, "srs"), ROWS_REQ_BASE if source == "profile lab"
                             and name != "srs" else None)
            parts.append(spec_of_keys(parsed, source, rows) if parsed or rows else None)
        spec = combine(*parts)
        for key in keys:
            givers = [src for src in SOURCES if (src, key) in drawn]
            if givers:
                expected, origin = drawn[givers[-1], key], givers[-1]
            elif key == "srs":
                expected, origin = None, None
            else:
                default = DEFAULTS.get(key)
                if key == "corridor":  # a named shape is judged in the tool's band
                    default = SHAPE_DEFAULTS[key] if spec.shape != "none" else None
                if key == "decay":  # a sawtooth's decay allowance
                    default = SHAPE_DEFAULTS[key] if spec.shape == "sawtooth" else None
                expected = BASE.get(key, default)
                origin = "profile lab" if key in BASE else (
                    "default" if default is not None else None)
            got = spec.srs if key == "srs" else value_of(spec, key)
            assert got == expected, (key, givers)
            assert spec.origin(key) == origin, (key, givers)


ROWS_REQ_BASE = SrsRequirement((100.0,), (10.0,))


@SETTINGS
@given(data=st.data())
def test_round_trip_every_key_prints_in_its_own_syntax_and_parses_back(data):
    for key, k in KEYS.items():
        value = data.draw(VALUES[key], label=key)
        if key.endswith("_tolerance") and data.draw(st.booleans(), label=f"{key} symmetric"):
            value = (value[0], value[0])
        text = k.show(value)
        assert k.parse(text, OPTIONS[key]) == value, (key, value, text)


def namespace(**given):
    names = ("profile", "shape", "peak", "duration", "velocity_change", "corridor",
             "time_slack", "window", "dv_window", "monitor", "duration_def", "decay",
             "placement", "record", "srs", "srs_tol", "srs_q", "srs_outside", "accel_unit")
    return argparse.Namespace(**{n: given.get(n) for n in names})


@SETTINGS
@given(data=st.data())
def test_sources_agree_an_option_a_sheet_cell_and_a_profile_key(data, tmp_path):
    for key in KEYS:
        value = data.draw(VALUES[key], label=key)
        group = [key]  # keys an option gives together
        if key.endswith("_tolerance"):
            group = [key.removesuffix("_tolerance"), key]
        elif key in ("srs_lower_db", "srs_upper_db"):
            group = ["srs_lower_db", "srs_upper_db"]
        values = {g: value if g == key else data.draw(VALUES[g], label=g) for g in group}
        texts = {g: KEYS[g].show(v) for g, v in values.items()}
        # options
        if key in ("srs_lower_db", "srs_upper_db"):
            ns = namespace(srs_tol=f"{texts['srs_lower_db']},{texts['srs_upper_db']}")
        elif group[0] in dict(QUANTITY_OPTIONS):
            nominal = group[0]
            ns = namespace(**{nominal: texts[nominal] + (
                f":{texts[f'{nominal}_tolerance']}" if f"{nominal}_tolerance" in texts
                else "")})
        elif key == "record":  # the command line's spelling: --cfc 600, --cfc none
            ns = command_options("fill", record=texts[key])
        else:
            ns = namespace(**{key: texts[key]})
        by_option = options_spec(ns)
        # a profile: the text, and where the key has a unit, the bare number in it
        path = tmp_path / "p.json"
        path.write_text(json.dumps(texts))
        by_profile = load_profile(str(path))
        # the sheet: the text in the key's row
        rows = {name: FIRST_ROW + r for r, (name, _, _) in enumerate(ROWS)}
        by_sheet = spec_from_cells({(rows[g], 2): (t, None) for g, t in texts.items()})
        for g in group:
            expected = values[g]
            assert value_of(by_option, g) == value_of(by_profile, g) == \
                value_of(by_sheet, g) == expected, (g, texts)


@SETTINGS
@given(data=st.data())
def test_bare_numbers_in_the_keys_unit_read_as_their_text(data):
    for key, k in KEYS.items():
        if not k.unit or key.endswith("_tolerance"):
            continue
        number = data.draw(st.floats(-1e6, 1e6, allow_nan=False), label=key)
        sign = "+" if key == "srs_upper_db" and number > 0 else ("-" if number < 0 else "")
        text = f"{sign}{abs(number)!r}{k.unit}"
        try:
            from_text = k.parse(text, key)
        except AirgunXlError:
            from_text = "refused"
        try:
            from_number = from_keys({key: number}, "p", lambda q: q)
            from_number = value_of(from_number, key)
        except AirgunXlError:
            from_number = "refused"
        assert from_text == from_number, (key, number)


OPTION_NAMES = dict(PLAIN_OPTIONS + QUANTITY_OPTIONS)
NOISE = st.one_of(st.text(max_size=16), st.sampled_from([
    "", " ", "inf", "-inf", "nan", "1e308", "1e309", "-0", "0", "+5", "12kG:10%", "12kg",
    "12KG", "5:10%", "5MS", "-10%", "+10%", "-10%,+20%", "10%,20%", "±10%", "0%", "100%",
    "-3dB,+6dB", "3dB", "cfc600", "CFC 7", "unfiltered", "half-sine", "Peak", "12 kG",
    "1e-400ms", "9" * 400 + "kG", "0x10", "1_000kG", "١٢kG", "12kG:10%:5%"]))


@SETTINGS
@given(option=st.sampled_from(sorted(OPTION_NAMES) + ["srs_tol"]), text=NOISE)
def test_any_random_string_in_an_option_is_a_checked_value_or_one_line_naming_it(option,
                                                                                  text):
    name = "--srs-tol" if option == "srs_tol" else OPTION_NAMES[option]
    try:
        spec = options_spec(namespace(**{option: text}))
    except AirgunXlError as exc:
        line = str(exc)
        assert "\n" not in line and line.startswith(f"{name}: ") and len(line) < 400, line
        return
    assert spec is not None
    for key in (k for k, o in OPTIONS.items() if o == name):
        value = value_of(spec, key)
        if value is not None:  # parsed: prints and parses back to itself
            assert KEYS[key].parse(KEYS[key].show(value), name) == value


@SETTINGS
@given(key=st.sampled_from(sorted(KEYS)), value=st.one_of(
    NOISE, st.floats(), st.integers(-10**30, 10**30), st.booleans(), st.none(),
    st.lists(st.integers(), max_size=2)))
def test_any_random_value_of_a_profile_key_is_a_value_or_one_line_naming_the_key(
        key, value, tmp_path):
    path = tmp_path / "p.json"
    path.write_text(json.dumps({key: value}))
    try:
        load_profile(str(path))
    except AirgunXlError as exc:
        line = str(exc)
        assert "\n" not in line and line.startswith(f"--profile {path}: "), line
        if "JSON" not in line:  # a value JSON itself refuses (NaN, 1e999) names the file
            assert f": {key}: " in line, line


@SETTINGS
@given(row=st.sampled_from(range(len(ROWS))), value=st.one_of(
    NOISE, st.floats(), st.integers(-10**30, 10**30), st.booleans()))
def test_any_random_value_of_a_sheet_cell_is_a_value_or_one_line_naming_the_cell(row,
                                                                                 value):
    cell = f"B{FIRST_ROW + row}"
    try:
        spec_from_cells({(FIRST_ROW + row, 2): (value, None)})
    except AirgunXlError as exc:
        line = str(exc)
        assert "\n" not in line and line.startswith(f"'Specification'!{cell} "), line


@SETTINGS
@given(command=st.sampled_from(["fill", "design", "accept", "srs", "compare-measured",
                                "calibrate"]),
       option=st.sampled_from(["--cfc", "--record"]), text=NOISE)
def test_any_random_string_as_the_filter_is_a_class_or_one_line_naming_the_option(
        command, option, text):
    """--cfc (and its old spelling --record) in every command that takes it: a J211 class,
    none, or one line naming the option and the text found."""
    if option == "--record" and command not in ("fill", "design", "accept"):
        return  # --record was a specification option only
    try:
        ns = build_parser().parse_args([command, "s.xlsx", *(["r.csv"] * (command in (
            "accept", "compare-measured", "calibrate"))), f"{option}={text}"])
    except AirgunXlError as exc:
        line = str(exc)
        assert "\n" not in line and f"argument {option}: found {text!r}" in line, line
        return
    assert ns.cfc is None or ns.cfc in CFC_CLASSES
    assert ns.cfc_given == option


def test_a_quantity_past_float_range_is_one_line_not_an_overflow():
    with pytest.raises(AirgunXlError, match="--peak: found"):
        options_spec(namespace(peak="9" * 400 + "kG:10%"))
    assert math.isfinite(KEYS["peak"].parse("1e4kG", "--peak"))
