"""Property tests: whatever a parameter cell holds (any text, number, error text or formula),
``fill`` either runs or refuses with one line; text copied from the sheet stays text."""
import math
from collections import Counter

import builders as b
import openpyxl
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from support import formulas_in

from airgun_xl.cells import CELLS
from airgun_xl.cli import main

#: Text that openpyxl can store (XML 1.0 forbids most control characters and lone surrogates).
TEXT = st.text(st.characters(blacklist_categories=("Cs", "Cc")), max_size=60)
NUMBERS = st.one_of(st.floats(allow_nan=True, allow_infinity=True),
                    st.floats(min_value=-1e-290, max_value=1e-290),
                    st.integers(min_value=-10**20, max_value=10**20))
FORMULAS = st.one_of(
    st.sampled_from(["=1/0", "=E10*E22", "=SUM(A2:D2)", "=A2+", "=FOO(1)", "=Z999", "=E6/E2",
                     "=-E40", "=1e308*10", "=\"text\"", "=TRUE", "=#N/A", "=A1:A3",
                     "=cmd|' /C calc'!A0", "=[1]Sheet1!A1", "=E43+E43"]),
    TEXT.map(lambda t: "=" + t))
CONTENT = st.one_of(TEXT, NUMBERS, st.booleans(), st.none(),
                    st.sampled_from(["#DIV/0!", "#N/A", "#VALUE!", "#REF!"]),
                    FORMULAS.map(lambda f: ("formula", f)))


@pytest.fixture(scope="module")
def short_template(tmp_path_factory):
    """Shot A cut to 0.2 ms (402 rows), so that each example runs in a fraction of a second."""
    path = tmp_path_factory.mktemp("short") / "short.xlsx"
    wb = openpyxl.load_workbook(b.TEMPLATE)
    wb.worksheets[0]["E6"] = 2e-4
    wb.save(path)
    return path


# derandomize: CI sees the same 80 examples every run; @example keeps cases found before
@settings(max_examples=80, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(cell=st.sampled_from([c.address for c in CELLS]), content=CONTENT, label=TEXT)
@example(cell="A2", content=1.0, label="=E10")  # a label inside a real formula's text
@example(cell="A2", content=1, label="")  # NaN figures: the error literal #NUM!
def test_any_cell_content_runs_or_is_one_line(tmp_path, capsys, short_template, cell, content,
                                              label):
    wb = openpyxl.load_workbook(short_template)
    ws = wb.worksheets[0]
    if isinstance(content, tuple):
        ws[cell] = content[1]
        ws[cell].data_type = "f"
    else:
        ws[cell] = content
        if isinstance(content, str):
            ws[cell].data_type = "s"  # text, even when it starts with "="
    ws["G30"] = label
    ws["G30"].data_type = "s"
    shot, out = tmp_path / "shot.xlsx", tmp_path / "shot.out.xlsx"
    wb.save(shot)
    capsys.readouterr()
    code = main(["fill", str(shot), "-o", str(out), "--force", "--only", "summary"])
    _, err = capsys.readouterr()
    assert "Traceback" not in err
    if code == 2:
        errors = [line for line in err.splitlines() if line.startswith("airgun-xl: error:")]
        assert len(errors) == 1 and err.strip().splitlines()[-1] == errors[0], err
        return
    assert code == 0, err
    result = openpyxl.load_workbook(out).worksheets[0]
    if label:
        assert result["G30"].value == label and result["G30"].data_type == "s"
    if isinstance(content, str):  # text ran: it must have been a blank-like text, kept as text
        assert result[cell].data_type == "s" and result[cell].value == content
    # every formula in the output is one of the input's real formulas (charts aside, and the
    # error literals #NUM! and #DIV/0! that nan_inf_to_errors writes for NaN and inf)
    written = Counter(f for f in formulas_in(out)
                      if "$" not in f and f not in ("#NUM!", "#DIV/0!"))
    assert not written - Counter(formulas_in(shot))


def test_the_property_strategies_reach_both_outcomes(tmp_path, capsys, short_template):
    """The property above is not vacuous: a valid number runs, a text refuses."""
    for value, expected in ((0.05, 0), ("=0.05", 2), (math.nan, 2)):
        wb = openpyxl.load_workbook(short_template)
        wb.worksheets[0]["E43"] = value
        wb.worksheets[0]["E43"].data_type = "s" if isinstance(value, str) else "n"
        wb.save(tmp_path / "s.xlsx")
        assert main(["fill", str(tmp_path / "s.xlsx"), "--force", "--only", "summary"]) \
            == expected
