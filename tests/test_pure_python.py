"""Issue 24.8: the pure-Python engine (AIRGUN_XL_PURE=1: the reference stepper and sheet XML
twins) fills legacy cases equal to the macro. This file needs no compiled extension: on an
install without a C compiler, where the twins are what runs, it is not skipped."""
import os
import subprocess
import sys

from conftest import CASES, REFERENCE, columns_off_the_macro, sheet_values


def test_pure_fill_matches_the_macro(tmp_path):
    """AIRGUN_XL_PURE=1, a fresh process: the kernel in use is the reference one, and a fill of
    two legacy cases equals the macro's output to the legacy rule (1e-12 of each column)."""
    env = dict(os.environ, AIRGUN_XL_PURE="1")
    probe = subprocess.run([sys.executable, "-c", "from airgun_xl.engine import kernel; "
                            "from airgun_xl.xlsx import sheet_xml; "
                            "print(kernel.COMPILED, sheet_xml.COMPILED)"], env=env,
                           capture_output=True, text=True, check=True)
    assert probe.stdout.strip() == "False False"
    for name in ("shot_a_appendix_5us", "mem_faster_clamp"):
        case = CASES[name]
        out = tmp_path / f"{name}.xlsx"
        subprocess.run([sys.executable, "-m", "airgun_xl", "fill", str(REFERENCE / case["input"]),
                        "-o", str(out)], env=env, check=True, capture_output=True)
        legacy, new = sheet_values(REFERENCE / case["legacy_output"]), sheet_values(out)
        assert columns_off_the_macro(legacy, new) == [], name
