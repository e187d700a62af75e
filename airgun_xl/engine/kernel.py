"""The time-stepping kernel in use: the compiled extension (``_artsim.c``), or the pure-Python
reference stepper (``_reference.py``) that gives the same numbers bit for bit.

The extension is optional: an install without a C compiler (or a platform without a wheel)
gets the reference stepper, 100-200 times slower. ``AIRGUN_XL_PURE=1`` forces it, to check
one against the other. :data:`COMPILED` says which is in use.
"""
import os

PURE = os.environ.get("AIRGUN_XL_PURE", "").strip() not in ("", "0")

try:
    if PURE:
        raise ImportError("AIRGUN_XL_PURE is set")
    from ._artsim import batch_kernel, legacy_kernel, newmark_kernel
    COMPILED = True
except ImportError:
    from ._reference import batch_kernel, legacy_kernel, newmark_kernel
    COMPILED = False

__all__ = ["COMPILED", "PURE", "batch_kernel", "legacy_kernel", "newmark_kernel"]
