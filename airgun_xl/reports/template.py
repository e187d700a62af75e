"""The shot A template: the report's parameter sheet (page 29), with live formulas.

Values are shot A as the report's appendix ran it (shared notes, ``shot-a.md``), at the report's
time step of 0.5 us. Derived cells are formulas: the mitigator mass E25 = E10*E22, the mass,
stiffness and inverse-mass matrices, and the copies A29, A30 of the bird velocity.

Page 29 also shows final masses and their change; the macro writes the final masses below
column I, so they are left out here: finding them needs lookup functions (INDEX, COUNT), and
evaluating any spreadsheet function makes ``formulas`` import scipy, which costs more than a
whole run of shot A. Only operator formulas are used.

A second sheet, Outputs, holds the output selection with its defaults
(:mod:`airgun_xl.outputs`).

Every formula is written with its evaluated value cached, because LibreOffice shows (and the
legacy macro reads) cached values of .xlsx files without recalculating them.
"""
from ..outputs import SHEET_NAME as OUTPUTS_SHEET
from ..outputs import block_cells
from ..readers.formula_eval import Evaluator, SheetView
from ..xlsx.report import report_workbook
from ..xlsx.spec_sheet import write_spec_sheet

SHEET = "Sheet1"

#: (cell, content): a number, a label, or a formula text.
CELLS = (
    ("A1", "M1"), ("B1", "M31"), ("C1", "M32"), ("D1", "M33"), ("E1", "Timestep"),
    ("H1", "Time"),
    ("A2", 680.388555), ("B2", 4.8761179775), ("C2", 5.488467677), ("D2", 5.5111472955),
    ("E2", 5e-07),
    ("A5", "K1"), ("B5", "K2"), ("C5", "K3"), ("E5", "Max Time"),
    ("B6", -6.084e9), ("C6", -1.2084e10), ("E6", 0.006),
    # K1 (A6, -2e8 on the report's page) is left blank: the macro never reads it
    ("A7", "K1 (A6) is not used: the macro computes k1 from E13, E31, E16, E19"),
    ("E9", "Density of Honeycomb"),
    ("A10", "Mass Matrix"), ("E10", 385),
    ("A11", "=A2+E25"), ("B11", 0), ("C11", 0), ("D11", 0),
    ("A12", 0), ("B12", "=B2"), ("C12", 0), ("D12", 0), ("E12", "Radius of Mitigator"),
    ("A13", 0), ("B13", 0), ("C13", "=C2"), ("D13", 0), ("E13", 0.08811),
    ("A14", 0), ("B14", 0), ("C14", 0), ("D14", "=D2"),
    ("E15", "Length of Wedge Part"),
    ("A16", "Stiffness Matrix"), ("E16", 0.098298),
    ("A17", 0), ("B17", 0), ("C17", 0), ("D17", 0),
    ("A18", 0), ("B18", "=B6"), ("C18", "=-B6"), ("D18", 0),
    ("E18", "Length of Cylindrical Part"),
    ("A19", 0), ("B19", "=-B6"), ("C19", "=B6+C6"), ("D19", "=-C6"), ("E19", 0.803),
    ("A20", 0), ("B20", 0), ("C20", "=-C6"), ("D20", "=C6"),
    ("A21", "Inverse Mass Matrix"), ("E21", "Volume of Mitigator"),
    ("A22", "=1/A11"), ("B22", 0), ("C22", 0), ("D22", 0), ("E22", 0.022739834),
    ("A23", 0), ("B23", "=1/B12"), ("C23", 0), ("D23", 0),
    ("A24", 0), ("B24", 0), ("C24", "=1/C13"), ("D24", 0), ("E24", "Mass of Mitigator"),
    ("A25", 0), ("B25", 0), ("C25", 0), ("D25", "=1/D14"), ("E25", "=E10*E22"),
    ("A26", "Initial Velocity Matrix"),
    ("A27", 0), ("E27", "Volume of Conical Mitigator"),
    ("A28", 243.53532), ("E28", 9.94838e-05),
    ("A29", "=A28"),
    ("A30", "=A28"), ("E30", "Elastic Modulus of Mitigator"),
    ("E31", 4060000000),
    ("E33", "Filter Frequency"),
    ("E34", 6250),
    ("E36", "Compacting Strain"),
    ("E37", 0.64),
    ("E39", "Yield Stress"),
    ("E40", 27030000),
    ("E42", "Damping Factor (Zeta)"),
    ("E43", 0.02),
)

COLUMN_WIDTHS = {"A:D": 12, "E:E": 28, "H:H": 12}


def _is_formula(content):
    return isinstance(content, str) and content.startswith("=")


def template_values():
    """Cached values of the template's formulas: ``{cell: value}``."""
    from openpyxl.utils.cell import coordinate_to_tuple

    cells = {}
    for address, content in CELLS:
        pos = coordinate_to_tuple(address)
        cells[pos] = (None, content) if _is_formula(content) else (content, None)
    evaluator = Evaluator(SheetView({SHEET.upper(): cells}, SHEET.upper()))
    return {address: evaluator.value(SHEET.upper(), *coordinate_to_tuple(address))
            for address, content in CELLS if _is_formula(content)}


def write_template(path, force=False):
    """Write the shot A template to ``path`` (atomically).

    Raises
    ------
    airgun_xl.errors.OutputError
        When ``path`` exists and ``force`` is false, or its folder is unusable.
    """
    values = template_values()
    with report_workbook(path, force) as wb:
        ws = wb.add_worksheet(SHEET)
        for columns, width in COLUMN_WIDTHS.items():
            ws.set_column(columns, width)
        for address, content in CELLS:
            if _is_formula(content):
                value = values[address]
                ws.write_formula(address, content, None, "" if value is None else value)
            elif isinstance(content, str):
                ws.write_string(address, content)
            else:
                ws.write_number(address, content)
        write_outputs_sheet(wb)
        write_spec_sheet(wb)


def write_outputs_sheet(wb):
    """The Outputs block with its defaults: output, write?, what it is."""
    ws = wb.add_worksheet(OUTPUTS_SHEET)
    ws.set_column(0, 0, 16)
    ws.set_column(1, 1, 10)
    ws.set_column(2, 2, 90)
    bold = wb.add_format({"bold": True})
    for col, text in enumerate(("Output", "Write", "What")):
        ws.write_string(0, col, text, bold)
    for row, (label, value, what) in enumerate(block_cells(), start=1):
        ws.write_string(row, 0, label)
        if isinstance(value, bool):
            ws.write_boolean(row, 1, value)
        elif isinstance(value, int):
            ws.write_number(row, 1, value)
        else:
            ws.write_string(row, 1, value)
        ws.write_string(row, 2, what)
    ws.write_string(len(block_cells()) + 2, 0, "airgun-xl fill reads this block; its flags "
                    "--only, --no-charts, --every, --max-sheet-rows and --sidecar override it.")
