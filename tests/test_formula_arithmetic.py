"""Issue 24.11: the short arithmetic evaluator (`formula_eval.arithmetic`), which spares a fill
the 0.1-0.2 s of importing and compiling ``formulas``, gives what ``formulas`` gives.

Random formulas of the subset (numbers, same-sheet cells, + - * /, unary signs, brackets) over
random cells (numbers, blanks, zeros, text, logicals, huge values) are evaluated twice: by
:meth:`Evaluator.evaluate` (short version first) and by :meth:`Evaluator.library` (``formulas``
alone). Both run IEEE double arithmetic in the same order, so they must agree exactly; where
the short version cannot vouch for a case (text or logical operands, division by zero,
overflow), it hands it to the library, and the two agree by construction.
"""
import openpyxl
import pytest
from conftest import TEMPLATE
from hypothesis import given, settings
from hypothesis import strategies as st

import airgun_xl
from airgun_xl.readers import formula_eval
from airgun_xl.readers.formula_eval import Evaluator, SheetView, arithmetic

CELLS = ["A1", "B2", "C3", "$D$4", "e5"]
POSITIONS = [(1, 1), (2, 2), (3, 3), (4, 4), (5, 5)]
CELL_VALUES = st.one_of(
    st.floats(min_value=-1e6, max_value=1e6, allow_nan=False),
    st.sampled_from([0.0, None, 1e300, -1e300, 1e-300, 3, "3", "abc", True, False]))
NUMBERS = st.one_of(st.sampled_from(["0", "1", "2.5", ".5", "1e+3", "2E-2", "0.1", "1e+300"]),
                    st.integers(0, 10**6).map(str),
                    st.floats(min_value=0, max_value=1e6, allow_nan=False).map(repr))


def formulas_text():
    """Text of the arithmetic subset, with optional spaces between tokens."""
    leaf = st.one_of(NUMBERS, st.sampled_from(CELLS))

    def extend(inner):
        return st.one_of(
            st.tuples(inner, st.sampled_from(["+", "-", "*", "/", " + ", "* "]), inner).map(
                "".join),
            st.tuples(st.sampled_from(["-", "+", " -"]), inner).map("".join),
            inner.map(lambda t: f"({t})"))

    return st.recursive(leaf, extend, max_leaves=8).map(lambda t: f"={t}")


def view(values):
    cells = {pos: (value, None) for pos, value in zip(POSITIONS, values, strict=True)}
    return SheetView({"S": cells}, "S")


@settings(max_examples=400, deadline=None, derandomize=True)
@given(formula=formulas_text(), values=st.lists(CELL_VALUES, min_size=5, max_size=5))
def test_the_short_version_agrees_with_formulas(formula, values):
    assert arithmetic(formula) is not None, formula  # every formula drawn is in the subset
    fast = Evaluator(view(values)).evaluate(formula, "S")
    slow = Evaluator(view(values)).library(formula, "S")
    assert type(fast) is type(slow) and fast == slow, (formula, values, fast, slow)


@pytest.mark.parametrize("formula", [
    "=SUM(A1:A3)", "=A1:B2", "=Sheet2!A1", "='My sheet'!A1", "=LOG10(2)", "=2^3", "=50%",
    "=1.", "=1e", "=1e3", "=A1 B1", "=(1+2", "=1+", "=TRUE", "=Mass*2", "=XFE1", "=A1048577", "=",
    "=A1&B1", "=R1C1", "=A0", "=+", "=1+*2"])
def test_what_is_outside_the_subset_goes_to_formulas(formula):
    assert arithmetic(formula) is None


def test_the_template_formulas_need_no_library(monkeypatch):
    """The template's formulas (all arithmetic) are read without importing ``formulas``: the
    library's entry point, made to fail, is never reached."""
    def refuse(formula):
        raise AssertionError(f"formulas was asked for {formula}")

    monkeypatch.setattr(formula_eval, "_compile", refuse)
    shot = airgun_xl.load(TEMPLATE)
    cells = openpyxl.load_workbook(TEMPLATE)["Sheet1"]
    # A29 = A28 and E25 = E10 * E22: what the formulas say, to the last bit
    assert shot.params.v32 == shot.params.v31 == cells["A28"].value
    assert shot.params.mmitigator == cells["E10"].value * cells["E22"].value


def test_a_formula_outside_the_subset_still_reads(tmp_path):
    """A function (SUM) is past the short version: ``formulas`` evaluates it."""
    shot_file = tmp_path / "sum.xlsx"
    wb = openpyxl.load_workbook(TEMPLATE)
    wb["Sheet1"]["A29"] = "=SUM(A28)*2"
    wb.save(shot_file)
    v31 = airgun_xl.load(TEMPLATE).params.v31
    assert airgun_xl.load(shot_file).params.v32 == 2 * v31
