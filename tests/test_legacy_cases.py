"""Every legacy case: each result column equals the original macro's output.

The outputs in legacy_reference/ were written by ArtSim itself running in LibreOffice Calc.
"""
import json

import numpy as np
import pytest
from conftest import (
    CASES,
    LEGACY_RTOL,
    MACRO_COLUMNS,
    REFERENCE,
    column,
    relative_error,
    sheet_values,
)

from airgun_xl.cli import main

#: Calc ignores a fractional Offset argument (README of legacy_reference): cases whose
#: 1/(E2*E34) is fractional, and the random ones, carry "host": "calc" in cases.json and are
#: compared with the Calc reproduction of column AB (fill --host calc).
CALC_HOST_CASES = {name for name, case in CASES.items() if case.get("host") == "calc"}


@pytest.fixture(scope="module", params=sorted(CASES))
def filled(request, tmp_path_factory):
    name = request.param
    case = CASES[name]
    out = tmp_path_factory.mktemp(name) / "out.xlsx"
    host = "calc" if name in CALC_HOST_CASES else "excel"
    assert main(["fill", str(REFERENCE / case["input"]), "-o", str(out), "--host", host]) == 0
    return name, sheet_values(REFERENCE / case["legacy_output"]), sheet_values(out)


def _rows(cells):
    return max(r for (r, c) in cells if c == "H") - 1


def test_same_row_count(filled):
    _, legacy, new = filled
    assert _rows(new) == _rows(legacy)


def test_headers_as_the_macro_writes_them(filled):
    _, legacy, new = filled
    for letter in MACRO_COLUMNS + ("O", "R", "AA"):
        assert new[(1, letter)] == legacy[(1, letter)]


@pytest.mark.parametrize("letter", MACRO_COLUMNS)
def test_column_equals_macro(filled, letter):
    name, legacy, new = filled
    rows = _rows(legacy)
    if letter == "AB":  # AB may run past the last time row (to 2x it, below one row)
        rows = max(r for (r, c) in legacy if c == "AB") - 1
    expected = column(legacy, letter, rows + 3)
    got = column(new, letter, rows + 3)
    if letter == "I":  # final masses sit below column I; compared in their own test
        expected, got = expected[:rows], got[:rows]
    if np.isnan(expected).all():
        assert np.isnan(got).all(), f"{name}: {letter} should be empty"
        return
    assert relative_error(got, expected) <= LEGACY_RTOL


def test_final_masses(filled):
    _, legacy, new = filled
    rows = _rows(legacy)
    for r in (rows + 3, rows + 4):
        assert new[(r, "I")] == pytest.approx(legacy[(r, "I")], rel=LEGACY_RTOL)
    assert (rows + 2, "I") not in new


def test_every_branch_is_covered():
    """The cases together reach every branch of the position loop and the filter."""
    import numpy as np

    from airgun_xl import load

    seen = set()
    for case in CASES.values():
        result = load(REFERENCE / case["input"]).run()
        h, p = result.history, result.params
        d = h.deflection[2:]
        unloading = d < np.maximum.accumulate(d)
        seen.add("unloading" if unloading.any() else "loading only")
        seen.add("cylinder" if h.x_plastic[2:].max() > p.hcone else "wedge only")
        if (h.x_plastic[2] > p.hcone):
            seen.add("front past the wedge on the first step")
        if (h.crush_factor[2:] == 1).any():
            seen.add("crush factor clamped")
        if (h.force[2:][unloading] == 0).any():
            seen.add("force clamped")
        seen.add("filtered" if len(result.filtered.rows) else "no filtered samples")
        if not float(p.samplerate).is_integer():
            seen.add("fractional samplerate")
        if not float(p.max_time / p.delta).is_integer():
            seen.add("fractional row count")
        if p.hcone == 0:
            seen.add("no wedge")
    assert seen >= {"unloading", "loading only", "cylinder", "wedge only", "crush factor clamped",
                    "force clamped", "filtered", "no filtered samples", "fractional samplerate",
                    "front past the wedge on the first step", "fractional row count",
                    "no wedge"}


ERROR_CASES = json.loads((REFERENCE / "error_cases.json").read_text())


@pytest.mark.parametrize("name", sorted(ERROR_CASES))
def test_where_the_macro_fails_fill_refuses_naming_the_cell(tmp_path, capsys, name):
    """The macro stopped with a runtime error (the runner wrote it into AZ1): fill refuses with
    one line naming the cell, at the same row, and writes nothing."""
    import openpyxl

    case = ERROR_CASES[name]
    legacy = openpyxl.load_workbook(REFERENCE / case["legacy_output"]).worksheets[0]
    assert legacy["AZ1"].value == case["macro_error"]
    shot = REFERENCE / case["input"]
    out = tmp_path / "o.xlsx"
    assert main(["fill", str(shot), "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err.startswith("airgun-xl: error: E16 (Length of Wedge Part): found 0 with the "
                          "plastic front not yet moved on a loading step (row 4,")
    assert "Division by zero" in err and not out.exists()
