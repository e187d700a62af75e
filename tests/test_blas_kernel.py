"""Issue 59: the same inputs give the same workbook on an Intel AVX-512 machine and an AMD
one. OpenBLAS picks its kernels by CPU, and they round differently (SkylakeX gave other bytes
than Haswell or Zen for every workbook); airgun-xl pins one kernel and one thread before numpy
loads (airgun_xl/blas.py). Here: whatever OPENBLAS_CORETYPE a machine sets, a process of
airgun-xl runs the pinned kernel, and a fill writes the same bytes."""
import hashlib
import os
import subprocess
import sys

import pytest
from conftest import TEMPLATE

from airgun_xl import blas

threadpoolctl = pytest.importorskip("threadpoolctl")

#: The kernels a machine may pick or be told to: AVX-512 Intel, AVX2 (and AMD Zen's), AVX.
KERNELS = ("SkylakeX", "Haswell", "Sandybridge")


def test_this_test_process_runs_the_pinned_kernel():
    """conftest imports airgun_xl first, so the in-process tests run the pinned kernel too."""
    import numpy  # noqa: F401
    import scipy.linalg  # noqa: F401

    found = {(i["architecture"], i["num_threads"]) for i in threadpoolctl.threadpool_info()
             if i["internal_api"] == "openblas"}
    assert blas.PINNED and found == {(blas.KERNEL, 1)}


PROBE = """
import json, sys
import airgun_xl, numpy, scipy.linalg, threadpoolctl
print(json.dumps(sorted({(i["architecture"], i["num_threads"])
                         for i in threadpoolctl.threadpool_info()
                         if i["internal_api"] == "openblas"})))
"""


@pytest.mark.parametrize("kernel", KERNELS)
def test_a_process_told_another_kernel_runs_the_pinned_one(kernel):
    import json

    env = {**os.environ, "OPENBLAS_CORETYPE": kernel, "OPENBLAS_NUM_THREADS": "2"}
    out = subprocess.run([sys.executable, "-c", PROBE], env=env, capture_output=True,
                         text=True, check=True).stdout
    assert json.loads(out) == [[blas.KERNEL, 1]]


@pytest.mark.slow
def test_a_reproducible_fill_writes_the_same_bytes_whatever_kernel_the_machine_picks(
        tmp_path):
    """The fill's Summary holds the critical time steps, eigenvalues through LAPACK: their
    last digits moved with the kernel before."""
    digests = set()
    for kernel in KERNELS:
        out = tmp_path / f"{kernel}.xlsx"
        env = {**os.environ, "OPENBLAS_CORETYPE": kernel}
        subprocess.run([sys.executable, "-m", "airgun_xl", "fill", str(TEMPLATE), "-o",
                        str(out), "--reproducible"], env=env, check=True,
                       capture_output=True)
        digests.add(hashlib.sha256(out.read_bytes()).hexdigest())
    assert len(digests) == 1
