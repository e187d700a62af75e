"""Issue 11: the pure-Python reference stepper gives the compiled kernel's numbers bit for bit,
so an install without a C compiler runs the same shots (AIRGUN_XL_PURE=1 forces it)."""
import json

import numpy as np
import pytest
from conftest import (
    CASES,
    REFERENCE,
)

import airgun_xl
from airgun_xl.engine import _reference as ref
from airgun_xl.engine.batch import N_FINALS
from airgun_xl.engine.integrators import displacement_bound, kernel_params

compiled = pytest.importorskip("airgun_xl.engine._artsim")

SHOT_A = airgun_xl.load(REFERENCE / CASES["shot_a_appendix_5us"]["input"]).params
UNSTABLE = json.loads((REFERENCE / "unstable_cases.json").read_text())
INPUTS = sorted({c["input"] for c in CASES.values()} | {c["input"] for c in UNSTABLE.values()})


def _buffers(rows):
    return [np.zeros(rows) for _ in range(5)] + [np.full(rows, np.nan) for _ in range(8)]


def _both(kernel_name, p):
    values = kernel_params(p) + [displacement_bound(p)]
    out = []
    for module in (compiled, ref):
        arrays = _buffers(p.rows)
        finals = getattr(module, kernel_name)(values, p.rows, *arrays)
        out.append((finals, arrays))
    return out


def _same(a, b):
    """Bit for bit: equal, NaN where the other is NaN (array_equal with equal_nan)."""
    return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)


@pytest.mark.parametrize("name", INPUTS)
def test_legacy_scheme_bit_for_bit_on_every_legacy_case(name):
    p = airgun_xl.load(REFERENCE / name).params
    (fc, ac), (fr, ar) = _both("legacy_kernel", p)
    assert _same(fc, fr)
    for i, (x, y) in enumerate(zip(ac, ar, strict=True)):
        assert _same(x, y), (name, i)


@pytest.mark.parametrize("changes", [{}, {"k3": -5e11}, {"zeta": 0.0}, {"hcone": 0.0}])
def test_newmark_bit_for_bit(changes):
    p = airgun_xl.load(REFERENCE / CASES["shot_a_appendix_5us"]["input"]).params
    (fc, ac), (fr, ar) = _both("newmark_kernel", p.replace(**changes))
    assert _same(fc, fr) and all(_same(x, y) for x, y in zip(ac, ar, strict=True))


@pytest.mark.parametrize("integrator", [0, 1])
def test_batch_bit_for_bit(integrator):
    base = airgun_xl.load(REFERENCE / CASES["low_velocity_60"]["input"]).params
    shots = [base.replace(v31=v, v32=v, v33=v) for v in (20.0, 60.0, 150.0)]
    matrix = np.array([kernel_params(p) + [displacement_bound(p)] for p in shots])
    results = []
    for module in (compiled, ref):
        t, y, finals = np.empty(base.rows), np.empty((3, base.rows)), np.empty((3, N_FINALS))
        module.batch_kernel(matrix, base.rows, integrator, 3, t, y, finals)
        results.append((t, y, finals))
    for x, z in zip(*results, strict=True):
        assert _same(x, z)


def test_sheet_xml_python_twin_writes_the_same_text():
    from airgun_xl.xlsx import sheet_xml

    compiled_xml = pytest.importorskip("airgun_xl.xlsx._sheet_xml")
    rng = np.random.default_rng(5)
    values = np.concatenate([rng.normal(size=200) * 10.0 ** rng.integers(-300, 300, 200),
                             [0.0, -0.0, 5e-324, 1.7976931348623157e308, 0.1, 1e-5, 123456.0]])
    assert compiled_xml.render_cells("AB", 7, values) == sheet_xml.render_cells_python(
        "AB", 7, values)
    styled = compiled_xml.render_cells("AB", 7, values, 12)  # a column's number format
    assert styled == sheet_xml.render_cells_python("AB", 7, values, 12)
    assert styled[0].startswith('<c r="AB7" s="12"><v>') and styled[0].endswith("</v></c>")
    assert compiled_xml.render_cells("AB", 7, values, -1) == compiled_xml.render_cells(
        "AB", 7, values)
    with pytest.raises(ValueError):
        sheet_xml.render_cells_python("A", 1, np.array([1.0, np.nan]))


def _refusal(call):
    try:
        call()
    except (ValueError, TypeError, BufferError) as exc:
        return type(exc).__name__ if not isinstance(exc, ValueError) else str(exc)
    return None


@pytest.mark.parametrize("case", ["rows past the address space", "int64 columns",
                                  "short columns", "batch rows past the address space",
                                  "batch short finals", "batch int64 params"])
def test_the_twins_refuse_the_same_inputs_and_never_write_out_of_bounds(case):
    """Issue 24.3: lengths are compared by division, so 2**61 rows over 10-element buffers (a
    product that overflowed) is refused by the C kernel and by its Python twin alike, with the
    same message, before anything is written."""
    params = [0.0] * (len(kernel_params(SHOT_A)) + 1)
    columns = {"rows past the address space": (2**61, [np.zeros(10)] * 13),
               "int64 columns": (5, [np.zeros(10, dtype=np.int64)] * 13),
               "short columns": (11, [np.zeros(10)] * 13)}
    if case in columns:
        rows, arrays = columns[case]
        said = [_refusal(lambda m=m: m.legacy_kernel(params, rows, *arrays))
                for m in (compiled, ref)]
    else:
        n = len(params)
        batch = {"batch rows past the address space": (np.zeros(n), 2**60, np.zeros(10),
                                                        np.zeros(10), np.zeros(N_FINALS)),
                 "batch short finals": (np.zeros(n), 5, np.zeros(5), np.zeros(5),
                                        np.zeros(N_FINALS - 1)),
                 "batch int64 params": (np.zeros(n, dtype=np.int64), 5, np.zeros(5),
                                        np.zeros(5), np.zeros(N_FINALS))}[case]
        p, rows, t, y, finals = batch
        said = [_refusal(lambda m=m: m.batch_kernel(p, rows, 0, 3, t, y, finals))
                for m in (compiled, ref)]
    assert said[0] is not None and said[0] == said[1], said


def test_the_sheet_xml_twins_refuse_the_same_inputs():
    """The Python render_cells took int64 arrays and long column names, which the C one
    refuses: now both refuse them, with the same message."""
    from airgun_xl.xlsx import sheet_xml

    compiled_xml = pytest.importorskip("airgun_xl.xlsx._sheet_xml")
    for column, values in (("A" * 9, np.zeros(3)), ("A", np.zeros(3, dtype=np.int64)),
                           ("A", np.zeros((3, 2))[:, 0])):
        said = [_refusal(lambda f=f: f(column, 1, values))
                for f in (compiled_xml.render_cells, sheet_xml.render_cells_python)]
        assert said[0] is not None and said[0] == said[1], said
