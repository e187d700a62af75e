"""Build the compiled ArtSim kernel; everything else is in pyproject.toml.

The extension is optional: where it cannot be built (no C compiler), the install goes on and
the package uses its pure-Python reference stepper, which gives the same numbers bit for bit
(airgun_xl/engine/kernel.py). It uses Python 3.11's limited API, so one abi3 wheel serves
every later Python on a platform (cibuildwheel: see README, "Building wheels").
"""
import sys

from setuptools import Extension, setup

# No fused multiply-add: the port must round exactly where the macro rounds. Every operation
# stays IEEE-rounded; -fno-trapping-math only lets the compiler compute both sides of a select
# (the batch's lanes, in SIMD registers), which cannot change a value: no trap is ever enabled.
FLAGS = ["/fp:precise"] if sys.platform == "win32" else [
    "-O3", "-ffp-contract=off", "-fno-fast-math", "-fno-trapping-math"]


def extension(name, source):
    return Extension(name, [source], extra_compile_args=FLAGS, optional=True,
                     py_limited_api=True, define_macros=[("Py_LIMITED_API", "0x030B0000")])


setup(
    ext_modules=[extension("airgun_xl.engine._artsim", "airgun_xl/engine/_artsim.c"),
                 extension("airgun_xl.xlsx._sheet_xml", "airgun_xl/xlsx/_sheet_xml.c")],
    options={"bdist_wheel": {"py_limited_api": "cp311"}},
)
