"""Issue 44: the shot's 23 parameters are declared once, in the cell table (airgun_xl/cells.py).
ShotParams's fields, the kernels' interface (itself checked against the C enum by
tests/test_kernel_interface.py) and the template writer's sheet are tied to it here, so that
any drift fails; and no code names a parameter cell by a literal address outside the table
(the template's own sheet content aside, tied below)."""
import ast
import dataclasses
import re
from pathlib import Path

from conftest import TEMPLATE

from airgun_xl.cells import BY_NAME, CELLS, address
from airgun_xl.choices import DESIGN_VARIABLES
from airgun_xl.engine.interface import SHOT_FIELDS
from airgun_xl.params import ShotParams
from airgun_xl.reports import template
from airgun_xl.studies.design import VARIABLES

PACKAGE = Path(__file__).resolve().parents[1] / "airgun_xl"
ADDRESSES = {c.address for c in CELLS}

#: The two inputs the kernels do not take: the run's length sets the rows, and the filter's
#: frequency is applied after the run (engine/filtered.py).
NOT_KERNEL_INPUTS = ("max_time", "filter_frequency")


def test_shotparams_fields_are_the_tables_names_in_its_order():
    fields = [f.name for f in dataclasses.fields(ShotParams)]
    assert fields == [c.name for c in CELLS] + ["crush_law", "unloading"]


def test_the_kernels_take_the_tables_fields_in_its_order():
    assert SHOT_FIELDS == tuple(c.name for c in CELLS if c.name not in NOT_KERNEL_INPUTS)


def test_the_template_writes_every_parameter_cell_under_its_label():
    written = dict(template.CELLS)
    assert ADDRESSES <= set(written)
    for cell in CELLS:
        column, row = re.fullmatch(r"([A-E])(\d+)", cell.address).groups()
        above = written.get(f"{column}{int(row) - 1}")
        if cell.name in ("v1", "v31", "v32", "v33"):  # one heading over the velocity column
            assert written["A26"] == "Initial Velocity Matrix"
            assert cell.label.startswith(written["A26"])
        else:
            assert above == cell.label, cell.address
    values = {**{a: v for a, v in written.items() if isinstance(v, (int, float))},
              **template.template_values()}  # numbers as written, formulas as evaluated
    shot = ShotParams.from_cells({a: v for a, v in values.items() if a in ADDRESSES})
    import airgun_xl

    assert shot == airgun_xl.load(TEMPLATE).params  # the table reads what the writer wrote


def test_design_and_its_choices_name_the_tables_cells():
    assert DESIGN_VARIABLES == tuple(VARIABLES)
    for var in VARIABLES.values():
        assert var.cells == tuple(address(f) for f in var.fields)
        assert var.unit == BY_NAME[var.fields[0]].unit


def _literal_addresses(path, root=PACKAGE):
    tree = ast.parse(path.read_text())
    docstrings = {id(node.body[0].value) for node in ast.walk(tree)
                  if isinstance(node, (ast.Module, ast.FunctionDef, ast.ClassDef))
                  and node.body and isinstance(node.body[0], ast.Expr)}
    return [f"{path.relative_to(root)}:{node.lineno} {node.value!r}"
            for node in ast.walk(tree)
            if isinstance(node, ast.Constant) and node.value in ADDRESSES
            and id(node) not in docstrings]


def test_no_code_names_a_parameter_cell_by_a_literal_address():
    allowed = {PACKAGE / "cells.py", PACKAGE / "reports" / "template.py"}
    found = [hit for path in sorted(PACKAGE.rglob("*.py")) if path not in allowed
             for hit in _literal_addresses(path)]
    assert found == []


def test_the_scan_finds_a_literal_address(tmp_path):
    """The scan above can fail: a module naming E40 by a literal is found."""
    probe = tmp_path / "probe.py"
    probe.write_text('def f(p):\n    """E40 in a docstring is words."""\n    return p["E40"]\n')
    assert _literal_addresses(probe, tmp_path) == ["probe.py:3 'E40'"]
