"""Build the compiled ArtSim kernel; everything else is in pyproject.toml."""
import sys

from setuptools import Extension, setup

# No fused multiply-add: the port must round exactly where the macro rounds.
FLAGS = [] if sys.platform == "win32" else ["-O2", "-ffp-contract=off", "-fno-fast-math"]

setup(ext_modules=[Extension("airgun_xl.engine._artsim", ["airgun_xl/engine/_artsim.c"],
                             extra_compile_args=FLAGS)])
