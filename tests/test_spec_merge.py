"""Issue 30: a field given is a field judged. One merge of profile, sheet and options that
knows what was given, the sheet read to its declared limits, and one strict grammar for every
option value, cell and profile key.

The pulses are ideal half-sines on a 100 kHz grid with 2 ms of rest before and after (no
noise: these tests are about which fields reach the verdict, not about measuring)."""
import json
import math
import re
import zipfile

import numpy as np
import openpyxl
import pytest
from conftest import TEMPLATE

import airgun_xl
from airgun_xl.cli import main
from airgun_xl.errors import AirgunXlError, OptionError
from airgun_xl.specification import (
    MAX_SRS_ROWS,
    UNFILTERED,
    Specification,
    Tolerance,
    cfc_record,
    combine,
    load_profile,
)
from airgun_xl.studies.acceptance import ideal, judge
from airgun_xl.studies.shock import srs

RATE = 100_000.0
A, T = 12.0, 5e-3  # [kG], [s]
TIME = np.arange(0, 2e-3 + T + 2e-3, 1 / RATE)
PULSE = ideal("half-sine", TIME - 2e-3, A, T)
FREQS = np.geomspace(200.0, 10_000.0, 12)


def recording(tmp_path, pulse=PULSE):
    path = tmp_path / "rec.csv"
    rows = "\n".join(f"{float(t)!r},{float(a)!r}" for t, a in zip(TIME, pulse, strict=True))
    path.write_text("time [s],acceleration [kG]\n" + rows + "\n")
    return path


def requirement(tmp_path, raise_db):
    """The pulse's own SRS (Q 10), ``raise_db`` dB higher: a requirement CSV in g."""
    levels = srs(PULSE, 1 / RATE, FREQS, 10.0) * 10 ** (raise_db / 20) * 9800 / 9.80665
    path = tmp_path / f"req{raise_db:+g}.csv"
    path.write_text("frequency [Hz],srs [g]\n" + "\n".join(
        f"{float(f)!r},{float(v)!r}" for f, v in zip(FREQS, levels, strict=True)) + "\n")
    return path


def profile(tmp_path, **fields):
    path = tmp_path / "lab.json"
    path.write_text(json.dumps(fields))
    return str(path)


def accept(tmp_path, capsys, *flags, shot=TEMPLATE, pulse=PULSE):
    out = tmp_path / "verdict.xlsx"
    if out.exists():
        out.unlink()
    code = main(["accept", str(shot), str(recording(tmp_path, pulse)), "-o", str(out),
                 *map(str, flags)])
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def refused(capsys, tmp_path, argv, *said):
    """Exit 2, one line naming what ``said`` says, nothing written."""
    before = sorted(p.name for p in tmp_path.iterdir())
    code = main(argv)
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    for part in said:
        assert part in lines[0], lines[0]
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    return lines[0]


def sheet_shot(tmp_path, cells, name="spec.xlsx"):
    """The template with ``cells`` ({"B3": value}) on its Specification sheet."""
    wb = openpyxl.load_workbook(TEMPLATE)
    ws = wb["Specification"]
    for ref, value in cells.items():
        ws[ref] = value
    path = tmp_path / name
    wb.save(path)
    return path


# -- 1. a profile's SRS fields ------------------------------------------------------------------

def test_30_1_a_profiles_srs_tolerance_is_judged(tmp_path, capsys):
    """The shot 4 dB over its requirement: inside the default -3/+6 dB, outside a profile's
    ±1 dB (the profile's SRS fields were dropped, and it passed)."""
    req = requirement(tmp_path, -4.0)
    code, out, _ = accept(tmp_path, capsys, "--srs", req)
    assert code == 0 and "(limits -3 to 6 dB;" in out
    lab = profile(tmp_path, srs_lower_db=-1, srs_upper_db=1, srs_q=10)
    code, out, _ = accept(tmp_path, capsys, "--srs", req, "--profile", lab)
    assert code == 3 and "FAIL  SRS: " in out and "(limits -1 to 1 dB;" in out
    assert "SRS lower tolerance -1dB" in out and "SRS upper tolerance +1dB" in out  # sourced


def test_30_1_the_sheets_srs_tolerance_survives_srs_rows_from_an_option(tmp_path, capsys):
    shot = sheet_shot(tmp_path, {"B15": -1, "B16": 1})
    code, out, _ = accept(tmp_path, capsys, "--srs", requirement(tmp_path, -4.0), shot=shot)
    assert code == 3 and "(limits -1 to 1 dB;" in out


def test_30_1_a_profiles_srs_fields_without_a_requirement_are_said_not_judged(tmp_path):
    spec = combine(profile(tmp_path, srs_q=5, peak_tolerance=10), None,
                   Specification(peak=Tolerance(A, math.nan, math.nan), source="options",
                                 origins=(("peak", "options"),)))
    verdict = judge(TIME, PULSE, spec)
    assert verdict.passed
    assert any(line.startswith("not judged: SRS Q") for line in verdict.definitions)


# -- 2. a value equal to its default overrides --------------------------------------------------

@pytest.mark.parametrize("flags, field, value", [
    (["--time-slack", "0%"], "time_slack", 0.0),
    (["--placement", "least-squares"], "placement", "least-squares"),
    (["--shape", "none"], "shape", "none"),
    (["--cfc", "none"], "record", UNFILTERED),
    (["--record", "unfiltered"], "record", UNFILTERED),  # the old spelling, one release
])
def test_30_2_an_option_equal_to_the_default_overrides_the_profile(tmp_path, capsys, flags,
                                                                   field, value):
    lab = profile(tmp_path, shape="half-sine", peak_tolerance=20, duration_tolerance=10,
                  corridor=20, time_slack=10, placement="peak", record="cfc600")
    from airgun_xl.cli.commands import build_parser
    from airgun_xl.cli.spec_options import options_spec

    ns = build_parser().parse_args(["fill", str(TEMPLATE), "--profile", lab, "--peak", "12kG",
                                    "--duration", "5ms", *flags])
    spec = combine(lab, airgun_xl.load(TEMPLATE).spec, options_spec(ns))
    assert getattr(spec, field) == value and spec.origin(field) == "options"


def test_30_2_shape_none_over_a_profiles_shape_judges_limits_only_and_says_so(tmp_path,
                                                                              capsys):
    lab = profile(tmp_path, shape="sawtooth", peak_tolerance=20, duration_tolerance=10,
                  corridor=20)
    code, out, _ = accept(tmp_path, capsys, "--profile", lab, "--peak", "12kG",
                          "--duration", "5ms")
    assert code == 3 and "FAIL  corridor" in out  # a half-sine is no sawtooth
    code, out, _ = accept(tmp_path, capsys, "--profile", lab, "--peak", "12kG",
                          "--duration", "5ms", "--shape", "none")
    assert code == 0 and "corridor:" not in out.split("\n  record judged")[0]
    assert "not judged: the corridor 20% from profile lab" in out


def test_30_2_time_slack_zero_over_a_profiles_slack_changes_the_corridor(tmp_path, capsys):
    """A half-sine 6 % long, placed on its peak: inside a ±5 % corridor with the profile's
    10 % slack (margin +5 %), outside it with none (margin -3.9 %): the 0 % must win."""
    lab = profile(tmp_path, shape="half-sine", peak_tolerance=20, duration_tolerance=10,
                  corridor=5, time_slack=10, placement="peak")
    stretched = ideal("half-sine", TIME - 2e-3, A, T * 1.06)
    common = ("--profile", lab, "--peak", "12kG", "--duration", "5ms")
    assert accept(tmp_path, capsys, *common, pulse=stretched)[0] == 0
    code, out, _ = accept(tmp_path, capsys, *common, "--time-slack", "0%", pulse=stretched)
    assert code == 3 and "time slack ±0%" in out and "time slack 0%" in out


# -- 3. the sheet's SRS rows --------------------------------------------------------------------

def test_30_3_the_sheets_srs_rows_are_read_to_max_srs_rows(tmp_path):
    cells = {}
    for k in range(299):
        cells[f"F{2 + k}"], cells[f"G{2 + k}"] = 100.0 + k, 50.0
    spec = airgun_xl.load(sheet_shot(tmp_path, cells)).spec
    assert len(spec.srs.frequencies) == 299 and spec.srs.frequencies[-1] == 398.0
    full = {}
    for k in range(MAX_SRS_ROWS):
        full[f"F{2 + k}"], full[f"G{2 + k}"] = 100.0 + k, 50.0
    spec = airgun_xl.load(sheet_shot(tmp_path, full, "full.xlsx")).spec
    assert len(spec.srs.frequencies) == MAX_SRS_ROWS


def test_30_3_a_row_after_a_blank_row_is_refused_naming_it(tmp_path):
    cells = {"F2": 100, "G2": 50, "F3": 200, "G3": 60, "F5": 400, "G5": 70}
    with pytest.raises(AirgunXlError, match=r"'Specification'!F5 \(SRS requirement\): found "
                                            r"400.*after the blank row 4"):
        airgun_xl.load(sheet_shot(tmp_path, cells))


def test_30_3_a_cell_past_the_last_row_read_is_refused_naming_it(tmp_path):
    row = MAX_SRS_ROWS + 2
    with pytest.raises(AirgunXlError, match=rf"'Specification'!G{row} \(SRS requirement\).*"
                                            rf"nothing past row {row - 1:,}"):
        airgun_xl.load(sheet_shot(tmp_path, {"F2": 100, "G2": 50, f"G{row}": 1}))


def test_30_3_cli_a_dropped_row_is_one_line(tmp_path, capsys):
    shot = sheet_shot(tmp_path, {"B3": 12, "B4": 10, "F2": 100, "G2": 50, "F4": 400, "G4": 7})
    refused(capsys, tmp_path, ["accept", str(shot), str(recording(tmp_path)), "-o",
                               str(tmp_path / "v.xlsx")], "'Specification'!F4")


# -- 4. SRS options with no SRS to apply to ------------------------------------------------------

def test_30_4_srs_q_applies_to_the_sheets_requirement(tmp_path, capsys):
    levels = srs(PULSE, 1 / RATE, FREQS, 10.0) * 9800 / 9.80665
    cells = {}
    for k, (f, v) in enumerate(zip(FREQS, levels, strict=True)):
        cells[f"F{2 + k}"], cells[f"G{2 + k}"] = float(f), float(v)
    shot = sheet_shot(tmp_path, cells)
    code, out, _ = accept(tmp_path, capsys, shot=shot)
    assert code == 0 and "; Q 10" in out
    code, out, _ = accept(tmp_path, capsys, "--srs-q", "2", "--srs-tol", "-1dB,+1dB",
                          shot=shot)
    assert code == 3 and "; Q 2" in out and "(limits -1 to 1 dB;" in out  # Q 2 is not Q 10


@pytest.mark.parametrize("flag, value", [("--srs-q", "2"), ("--srs-outside", "50%"),
                                         ("--srs-tol", "-3dB,+6dB")])
def test_30_4_an_srs_option_with_no_srs_is_refused_naming_it(tmp_path, capsys, flag, value):
    refused(capsys, tmp_path, ["accept", str(TEMPLATE), str(recording(tmp_path)), "-o",
                               str(tmp_path / "v.xlsx"), "--peak", "12kG:10%", flag, value],
            f"{flag}: found", "with no SRS requirement")


def test_30_4_an_srs_cell_with_no_srs_is_refused_naming_the_cell(tmp_path, capsys):
    shot = sheet_shot(tmp_path, {"B3": 12, "B4": 10, "B14": 2})
    refused(capsys, tmp_path, ["accept", str(shot), str(recording(tmp_path)), "-o",
                               str(tmp_path / "v.xlsx")],
            "'Specification'!B14 (SRS Q): found 2 with no SRS requirement")


# -- 5. option values read strictly --------------------------------------------------------------

@pytest.mark.parametrize("flags, said", [
    (["--corridor=-20%", "--shape", "half-sine"], ("--corridor: found the sign '-'",)),
    (["--time-slack", "-1%"], ("--time-slack: found the sign '-'",)),
    (["--peak", "12kg:10%"], ("--peak: found the unit 'kg'", "did you mean kG?")),
    (["--peak", "12KG:10%"], ("did you mean kG?",)),
    (["--duration", "5:10%"], ("--duration: found '5' without a unit",)),
    (["--duration", "5MS:10%"], ("did you mean ms?",)),
    (["--peak="], ("--peak: found an empty value",)),
    (["--record="], ("--record: found ''",)),
    (["--srs-q", "inf"], ("--srs-q: found 'inf'",)),
    (["--srs-q", "1e308"], ("--srs-q: found '1e308'", "at most 1,000")),
    (["--peak", "12kG:-10%"], ("--peak: found '-10%', a single signed tolerance",
                               "ambiguous")),
    (["--peak", "12kG:+10%"], ("a single signed tolerance",)),
    (["--peak", "1e308kG:10%"], ("--peak: found '1e308kG'", "at most 10,000 kG")),
    (["--peak", "-12kG:10%"], ("--peak: found the sign '-'",)),
    (["--velocity-change", "35:10%"], ("--velocity-change: found '35' without a unit",)),
    (["--window", "-1ms"], ("--window: found the sign '-'",)),
    (["--peak", "12kG:10%,20%"], ("--peak: found '10%,20%'", "- and the upper with +")),
    (["--srs-tol", "3dB,+6dB"], ("--srs-tol: found '3dB'",)),
    (["--srs-tol", "-3db,+6dB"], ("did you mean dB?",)),
    (["--shape", "square"], ("--shape: found 'square'",)),
])
def test_30_5_option_values_are_read_strictly(tmp_path, capsys, flags, said):
    # a criterion besides the one refused (a second --duration is refused for itself: 43.11)
    given = [] if "--duration" in flags else ["--duration", "5ms:10%"]
    with np.errstate(all="raise"):  # no numpy RuntimeWarning reaches the terminal either
        refused(capsys, tmp_path, ["accept", str(TEMPLATE), str(recording(tmp_path)), "-o",
                                   str(tmp_path / "v.xlsx"), *given, *flags], *said)


def test_30_5_accept_has_no_anti_alias_option_to_ignore(tmp_path, capsys):
    code = main(["accept", str(TEMPLATE), str(recording(tmp_path)), "--peak", "12kG:10%",
                 "--anti-alias", "abc", "-o", str(tmp_path / "v.xlsx")])
    err = capsys.readouterr().err
    assert code == 2 and "--anti-alias" in err and not (tmp_path / "v.xlsx").exists()


def test_30_5_srs_outside_takes_a_percentage(tmp_path, capsys):
    code, out, _ = accept(tmp_path, capsys, "--srs", requirement(tmp_path, 0.0),
                          "--srs-outside", "50%")
    assert code == 0 and "(allowed 6)" in out  # half of 12 frequencies


def test_30_5_a_refusal_of_q_or_outside_names_its_option(tmp_path, capsys):
    req = requirement(tmp_path, 0.0)
    for flag, value in (("--srs-q", "0.2"), ("--srs-outside", "100%")):
        line = refused(capsys, tmp_path, ["accept", str(TEMPLATE), str(recording(tmp_path)),
                                          "-o", str(tmp_path / "v.xlsx"), "--srs", str(req),
                                          flag, value], f"{flag}: found")
        assert "--srs:" not in line


def test_30_5_record_unfiltered_is_said_unfiltered(tmp_path, capsys):
    """--cfc none over a sheet that judges CFC 600: the option wins, field by field, and the
    record is said unfiltered (not 'CFC 0'); the filter given by both its spellings,
    differently, is refused in one line (the old spelling's note held: issue 43.16)."""
    shot = sheet_shot(tmp_path, {"B3": 12, "B4": 10, "B12": "CFC 600"})
    code, out, _ = accept(tmp_path, capsys, "--cfc", "none", shot=shot)
    assert code == 0 and "record judged: unfiltered" in out and "CFC 0" not in out
    assert re.search(r"from options: .*record judged unfiltered", out)  # where it came from
    code = main(["accept", str(shot), str(recording(tmp_path)), "-o",
                 str(tmp_path / "v.xlsx"), "--record", "unfiltered", "--cfc", "600"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and err == ["airgun-xl: error: --cfc: found 600, where --record gave it "
                                 "(none); expected the filter once (--cfc)"]
    assert not (tmp_path / "v.xlsx").exists()


def test_30_5_the_grammar_is_the_same_in_a_profile_and_on_the_sheet(tmp_path):
    with pytest.raises(OptionError, match=r"--profile .*lab.json: peak: found the unit 'kg'"
                                          r".*did you mean kG\?"):
        load_profile(profile(tmp_path, peak="12kg"))
    with pytest.raises(OptionError, match=r"peak_tolerance: found -10, a single signed "
                                          r"tolerance"):
        load_profile(profile(tmp_path, peak_tolerance=-10))
    with pytest.raises(AirgunXlError, match=r"'Specification'!B3 \(Peak\): found the unit 'KG' "
                                            r"in '12 KG' \(did you mean kG\?\)"):
        airgun_xl.load(sheet_shot(tmp_path, {"B3": "12 KG"}))
    spec = airgun_xl.load(sheet_shot(tmp_path, {"B3": "11750g", "B4": "-10%,+20%"})).spec
    assert spec.peak == Tolerance(11750 * 9.80665 / 9800, 0.1, 0.2)


# -- 6. a repeated --sd --------------------------------------------------------------------------

def test_30_6_a_repeated_sd_is_refused(tmp_path, capsys):
    refused(capsys, tmp_path, ["design", str(TEMPLATE), "--peak", "12kG:10%", "--confidence",
                               "0.9", "--sd", "A28=1%", "--sd", "A28=2%", "-o",
                               str(tmp_path / "d.xlsx")],
            "--sd: found A28 twice ('A28=1%' and 'A28=2%')")


# -- 7. a formula over Excel's length on the Specification sheet ---------------------------------

def with_cached(path, sheet_xml, ref, cached):
    """The workbook with a cached value written beside ``ref``'s formula (openpyxl writes
    none; a spreadsheet app does)."""
    out = path.with_name("cached_" + path.name)
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(out, "w") as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == sheet_xml:
                text, n = re.subn(rf'(<c r="{ref}"[^>]*>)(<f>.*?</f>)(<v>.*?</v>|<v\s*/>)?',
                                  lambda m: f"{m.group(1)}{m.group(2)}<v>{cached!r}</v>",
                                  data.decode())
                assert n == 1
                data = text.encode()
            dst.writestr(item, data)
    return out


def test_30_7_a_formula_past_excels_length_is_refused_not_run_on_its_cache(tmp_path, capsys):
    long = "=" + "+".join(["0.0001"] * 1_169) + "+11.8831+0"  # 8,193 characters, = 12
    assert len(long) == 8_193
    shot = with_cached(sheet_shot(tmp_path, {"B3": long, "B4": 10}),
                       "xl/worksheets/sheet3.xml", "B3", 12.0)
    line = refused(capsys, tmp_path, ["accept", str(shot), str(recording(tmp_path)), "-o",
                                      str(tmp_path / "v.xlsx")],
                   "'Specification'!B3 (Peak): found a formula of 8,193 characters, over "
                   "Excel's 8,192")
    assert len(line) < 300


def test_30_7_the_parameter_sheet_refuses_it_too(tmp_path, capsys):
    wb = openpyxl.load_workbook(TEMPLATE)
    wb["Sheet1"]["E43"] = "=" + "+".join(["0.001"] * 1_638)  # 9,828 characters
    path = tmp_path / "p.xlsx"
    wb.save(path)
    shot = with_cached(path, "xl/worksheets/sheet1.xml", "E43", 1.638)
    refused(capsys, tmp_path, ["fill", str(shot), "-o", str(tmp_path / "o.xlsx")],
            "E43", "over Excel's 8,192")


# -- the merge rule and the defaults, as a verdict prints them -----------------------------------

def test_the_verdict_prints_where_each_field_came_from_and_the_defaults(tmp_path, capsys):
    lab = profile(tmp_path, peak_tolerance=20, duration_tolerance=10)
    shot = sheet_shot(tmp_path, {"B5": 5})
    code, out, _ = accept(tmp_path, capsys, "--profile", lab, "--peak", "12kG", shot=shot)
    assert code == 0
    assert "from profile lab: peak tolerance 20%, duration tolerance 10%" in out
    assert "from the 'Specification' sheet: duration 5ms" in out
    assert "from options: peak 12kG" in out
    assert ("defaults (the tool's, no source gave them): shape none, time slack 0%, "
            "placement least-squares, velocity-change window 0.5D,0.5D, monitoring window "
            "1D,1D, duration definition base, record judged default") in out


def test_the_documented_profile_example_loads_as_documented(tmp_path):
    """docs/acceptance.md's JSON example is a working profile of the grammar it describes."""
    from pathlib import Path

    text = (Path(__file__).parents[1] / "docs" / "acceptance.md").read_text()
    example = text.split("```json\n", 1)[1].split("```", 1)[0]
    path = tmp_path / "drop-table.json"
    path.write_text(example)
    spec = load_profile(str(path))
    assert math.isnan(spec.peak.nominal) and (spec.peak.minus, spec.peak.plus) == (0.1, 0.2)
    assert (spec.shape, spec.corridor, spec.record) == ("half-sine", 0.15, cfc_record(1000))
    assert (spec.srs_lower_db, spec.srs_upper_db) == (-1.0, 1.0)
    assert spec.duration.minus == spec.duration.plus == 0.1


def test_a_tolerance_typed_as_a_percentage_in_excel_is_read_as_it_shows(tmp_path):
    """Typed "10%" in Excel, a cell holds 0.1 with a percent format: it is 10 %, not 0.1 %
    (the sheet's unit column says %). Without the format, 0.1 is 0.1 %."""
    wb = openpyxl.load_workbook(TEMPLATE)
    ws = wb["Specification"]
    ws["B3"], ws["B4"], ws["B9"], ws["B10"] = 12, 0.1, 0.2, 0.05
    for ref in ("B4", "B9", "B10"):
        ws[ref].number_format = "0%"
    ws["B2"], ws["B5"], ws["B6"] = "half-sine", 5, 10
    path = tmp_path / "pct.xlsx"
    wb.save(path)
    spec = airgun_xl.load(path).spec
    assert (spec.peak.minus, spec.corridor, spec.time_slack) == (0.1, 0.2, 0.05)
    ws["B4"].number_format = "General"
    wb.save(path)
    assert airgun_xl.load(path).spec.peak.minus == 0.001
