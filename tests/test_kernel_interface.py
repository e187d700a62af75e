"""Issue 24.2: the kernels' interface is declared once (engine/interface.py); the C source's
enum and finish_run, and the Python twin's constants, are checked against it."""
import re
from pathlib import Path

from airgun_xl.engine import _reference
from airgun_xl.engine.batch import N_FINALS
from airgun_xl.engine.integrators import KERNEL_PARAMS
from airgun_xl.engine.interface import FINALS, PARAMS, SHOT_FIELDS, final, param
from airgun_xl.params import ShotParams

SOURCE = (Path(__file__).resolve().parents[1] / "airgun_xl" / "engine" / "_artsim.c").read_text()


def test_the_c_enum_is_the_declared_order():
    enum = re.search(r"enum\s*\{([^}]*)\}", SOURCE).group(1)
    names = [n.strip() for n in enum.split(",") if n.strip()]
    assert names == [c for _, c in PARAMS] + ["P_COUNT"]


def test_finish_run_copies_the_declared_finals_in_order():
    body = re.search(r"static void finish_run\([^)]*\)\s*\{(.*?)\n\}", SOURCE, re.S).group(1)
    copied = dict((int(k), v) for k, v in
                  re.findall(r"out\[(\d+)\]\s*=\s*(?:\(double\))?\s*(?:s->)?(\w+)", body))
    assert [copied[i] for i in range(len(copied))] == [c for _, c in FINALS]
    lanes = re.search(r"static void lane_finals\([^)]*\)\s*\{(.*?)\n\}", SOURCE, re.S).group(1)
    assert len(re.findall(r"f\[(\d+)\]\s*=", lanes)) == len(FINALS)
    assert f"#define N_FINALS {len(FINALS)}" in SOURCE


def test_the_python_twin_and_the_callers_use_the_declaration():
    for i, (_, c_name) in enumerate(PARAMS):
        assert getattr(_reference, c_name) == i
    assert _reference.N_FINALS == N_FINALS == len(FINALS)
    assert KERNEL_PARAMS == SHOT_FIELDS
    fields = {f for f in ShotParams.__dataclass_fields__}
    assert set(SHOT_FIELDS) <= fields  # every kernel input is a field of the shot
    assert final("bad_row") == 2 and param("bound") == len(PARAMS) - 1
