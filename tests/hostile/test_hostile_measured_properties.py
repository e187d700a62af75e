"""Issue 23 (property tests): compare-measured and calibrate fed random recordings, headers,
units and options either run or refuse with one line, and a refusal writes nothing."""
import math

import builders as b
import openpyxl
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airgun_xl.cli import main

UNITS_T = ["s", "ms", "us", "µs", "MS", "min", "", "x"]
UNITS_A = ["g", "kG", "m/s^2", "m/s2", "Kg", "G", "", "psi"]
VALUES = st.one_of(st.floats(allow_nan=True, allow_infinity=True, width=64),
                   st.floats(min_value=-2000, max_value=2000),
                   st.sampled_from(["", "abc", "1,5", "--", "1e999", "=1+1"]))
HEADER = st.tuples(st.sampled_from(["time", "t", "Time", "zeit", ""]),
                   st.sampled_from(UNITS_T), st.sampled_from(["acceleration", "acc", "a", ""]),
                   st.sampled_from(UNITS_A))


@st.composite
def recordings(draw):
    """A CSV as a data acquisition might export it (half the examples: a whole pulse with a
    known header, metadata lines and a delimiter), or a broken one (random header, units,
    rate, length and cells)."""
    whole = draw(st.booleans())
    delimiter = draw(st.sampled_from([",", ";", "\t"]))
    if whole:
        t_name, t_unit, a_name, a_unit = ("time", draw(st.sampled_from(["s", "ms"])),
                                          "acceleration", draw(st.sampled_from(["g", "kG"])))
        n, dt, bad = draw(st.integers(400, 700)), draw(st.sampled_from([1e-5, 2e-5])), []
    else:
        t_name, t_unit, a_name, a_unit = draw(HEADER)
        n = draw(st.integers(0, 300))
        dt = draw(st.sampled_from([1e-5, 2e-5, 5e-5, 0.0, -1e-5, 1.0]))
        bad = draw(st.lists(st.tuples(st.integers(0, max(n - 1, 0)), VALUES), max_size=4))
    lines = [f"# {draw(st.text(max_size=20))}" for _ in range(draw(st.integers(0, 3)))]
    lines.append(f"{t_name} [{t_unit}]{delimiter}{a_name} [{a_unit}]")
    scale = {"ms": 1e3, "us": 1e6, "µs": 1e6}.get(t_unit, 1.0)
    level = 11_000.0 if a_unit in ("g", "G") else 11.0
    cells = {}
    for k in range(n):
        t = k * dt
        a = level * math.sin(math.pi * (t - 1e-3) / 5e-3) if 1e-3 < t < 6e-3 else 0.0
        cells[k] = [repr(t * scale), repr(a)]
    for k, value in bad:
        if k in cells:
            cells[k][1] = value if isinstance(value, str) else repr(value)
    lines += [delimiter.join(cells[k]) for k in range(n)]
    return "\n".join(lines) + "\n"


OPTIONS = st.one_of(
    st.fixed_dictionaries({}, optional={  # options a user would give
        "--cfc": st.sampled_from(["180", "600", "1000"]),
        "--anti-alias": st.sampled_from(["auto", "none", "5000"])}),
    st.fixed_dictionaries({}, optional={  # any
        "--cfc": st.sampled_from(["60", "180", "600", "1000", "7", "x"]),
        "--sign": st.sampled_from(["1", "-1", "0"]),
        "--time-unit": st.sampled_from(UNITS_T),
        "--accel-unit": st.sampled_from(UNITS_A),
        "--anti-alias": st.sampled_from(["auto", "none", "2000", "-5", "abc", "1e9"])}))


@pytest.fixture(scope="module")
def shot(tmp_path_factory):
    """Shot A at 1 us: a second's fraction per run."""
    path = tmp_path_factory.mktemp("measured") / "shot.xlsx"
    wb = openpyxl.load_workbook(b.TEMPLATE)
    wb.worksheets[0]["E2"] = 1e-6
    wb.save(path)
    return path


def _check(capsys, argv, out, codes):
    capsys.readouterr()
    code = main(argv)
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert code in codes, (code, err)
    if code == 2:
        errors = [line for line in err.splitlines() if line.startswith("airgun-xl: error:")]
        assert len(errors) == 1 and err.strip().splitlines()[-1] == errors[0], err
        assert not out.exists()
    else:
        assert out.exists()


# derandomize: CI sees the same examples every run
@settings(max_examples=60, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(csv=recordings(), options=OPTIONS, align=st.sampled_from(["threshold", "xcorr"]))
def test_compare_measured_runs_or_refuses_in_one_line(tmp_path, capsys, shot, csv, options,
                                                      align):
    recording = tmp_path / "m.csv"
    recording.write_text(csv, encoding="utf-8")
    out = tmp_path / "c.xlsx"
    out.unlink(missing_ok=True)
    argv = ["compare-measured", str(shot), str(recording), "-o", str(out), "--align", align]
    for flag, value in options.items():
        argv += [flag, value]
    _check(capsys, argv, out, (0, 2))


@settings(max_examples=20, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(csv=recordings(), options=OPTIONS,
       fit=st.sampled_from([None, "E40", "E43", "scale", "E40,E43", "E99"]))
def test_calibrate_runs_or_refuses_in_one_line(tmp_path, capsys, shot, csv, options, fit):
    """Exit 0 (trusted), 3 (written but not trusted, its warnings said) or 2 (refused)."""
    recording = tmp_path / "m.csv"
    recording.write_text(csv, encoding="utf-8")
    out = tmp_path / "cal.xlsx"
    out.unlink(missing_ok=True)
    argv = ["calibrate", str(shot), str(recording), "-o", str(out)]
    if fit:
        argv += ["--fit", fit]
    for flag, value in options.items():
        argv += [flag, value]
    _check(capsys, argv, out, (0, 2, 3))
