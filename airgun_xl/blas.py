"""OpenBLAS's kernel, pinned: the same inputs give the same workbook on any x86-64 machine.

numpy's and scipy's wheels ship OpenBLAS built for every x86-64 CPU, and it picks its
kernels by the CPU it runs on: SkylakeX on an Intel Xeon with AVX-512, Zen or Haswell on an
AMD EPYC. Those kernels sum in different orders, so every figure that passes through linear
algebra (the critical time steps' eigenvalues, a calibration's least squares, a Monte
Carlo's draws from a covariance) differed in its last digits between an Intel and an AMD lab
PC, and a fit's path (and so its 4th digit) with it (issue 59).

:func:`pin` sets, before numpy or scipy is loaded, the kernel every x86-64 CPU that runs
numpy 2 has (:data:`KERNEL`, SSE4.2) and one thread (OpenBLAS splits a long dot product
among its threads, so the sum would depend on the number of cores). airgun-xl's own matrices
are at most a few thousand by a dozen, so neither costs a measurable time. The variables are
read by OpenBLAS when it loads: a process that imported numpy before airgun-xl keeps the
kernel it got (:data:`PINNED` is then False, and the provenance says so).
"""
import os
import sys

#: The OpenBLAS kernel every process of airgun-xl runs (OPENBLAS_CORETYPE).
KERNEL = "Nehalem"

#: The variables set, and their values.
SETTINGS = {"OPENBLAS_CORETYPE": KERNEL, "OPENBLAS_NUM_THREADS": "1"}


def pin() -> bool:
    """Set :data:`SETTINGS` in the environment (and so in every child process) unless numpy
    or scipy is loaded already; whether this process runs the pinned kernel."""
    if "numpy" in sys.modules or "scipy" in sys.modules:
        return all(os.environ.get(k) == v for k, v in SETTINGS.items())
    os.environ.update(SETTINGS)
    return True


#: Whether this process's OpenBLAS runs :data:`KERNEL` on one thread (set at import).
PINNED = pin()
