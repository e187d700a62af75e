"""The names a user can choose, in one light module (no numpy, no workbook libraries).

The CLI builds its parser from these before anything heavy loads, so ``airgun-xl history``
or ``--help`` starts without the engine and the workbook libraries. The modules that implement
each choice import their names from here (and a test checks that they implement all of them).
"""
from .cells import address

#: Integrators (``airgun_xl.engine.integrators.INTEGRATORS``).
INTEGRATORS = ("legacy", "newmark")

#: Models (``airgun_xl.models``).
MODELS = ("4-mass", "rigid")

#: The mitigator's unloading force (``ShotParams.unloading``): the macro's, whose offset is
#: set at the first unloading only (a force jump at any later one), or continuous, where
#: each unloading starts from the force of the step before it.
UNLOADINGS = ("macro", "continuous")

#: Whose Offset rounding the filtered column reproduces (``airgun_xl.engine.filtered``).
HOSTS = ("excel", "calc")

#: Step values an integrator can record, in ``History`` order.
TRACKED = ("crush_factor", "m31", "deflection", "x_plastic", "force", "m1", "v1", "v31")

#: When a fill writes the full history beside the workbook.
SIDECAR_MODES = ("auto", "always", "never")

#: Parameters ``design`` can solve for (``airgun_xl.studies.design.VARIABLES``): the bird's
#: velocity (A28, A29 and A30 together), the mitigator's radius and wedge, the lot's crush
#: stress, the MEM's mass.
DESIGN_VARIABLES = tuple(address(name) for name in ("v31", "rcone", "hcone", "sigmay", "m1"))

#: The environment variable that names the default archive folder.
ARCHIVE_ENV = "AIRGUN_XL_ARCHIVE"

#: The environment variable that names the PostgreSQL server of a new archive's index.
INDEX_ENV = "AIRGUN_XL_INDEX"
