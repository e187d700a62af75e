"""Issue 35: the tests test the compiled kernels wherever they could be built. ``python -m
pytest`` puts the clone first on the path; a clone whose extensions were never built in place
(``pip install .`` builds them elsewhere) would silently run the pure-Python twins. README's
test command installs editable, which builds them in the clone; this checks that it did."""
import os
import shutil
import sysconfig
from pathlib import Path

import pytest

import airgun_xl
from airgun_xl.engine import kernel
from airgun_xl.xlsx import sheet_xml

ROOT = Path(__file__).resolve().parents[1]


def _can_compile():
    """A C compiler and the Python headers: what setup.py needs to build the extensions."""
    cc = (sysconfig.get_config_var("CC") or "cc").split()[0]
    headers = Path(sysconfig.get_paths()["include"]) / "Python.h"
    return shutil.which(cc) is not None and headers.is_file()


def test_the_package_under_test_is_the_clones():
    assert Path(airgun_xl.__file__).resolve().parent == ROOT / "airgun_xl"


@pytest.mark.skipif(os.environ.get("AIRGUN_XL_PURE") == "1",
                    reason="AIRGUN_XL_PURE=1 asks for the twins")
def test_the_compiled_kernels_are_under_test_where_a_compiler_is_present():
    if not _can_compile():
        pytest.skip("no C compiler or Python headers here: the twins are what runs")
    assert kernel.COMPILED, ("the kernel extension is not built in the clone: install with "
                             "pip install -e \".[test]\" (README's test command)")
    assert sheet_xml.COMPILED
    from airgun_xl.engine import _artsim
    from airgun_xl.xlsx import _sheet_xml

    for ext in (_artsim, _sheet_xml):  # built in the clone, not found elsewhere on the path
        assert Path(ext.__file__).resolve().is_relative_to(ROOT / "airgun_xl"), ext.__file__
