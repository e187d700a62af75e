"""The options every running command shares, declared once: ``--integrator``, ``--model``,
``-o``/``--output`` and ``--force`` (their help texts then match across subcommands)."""
from ..choices import INTEGRATORS, MODELS

INTEGRATOR_HELP = ("legacy: ArtSim's scheme (the default); newmark: average-acceleration "
                   "Newmark, unconditionally stable for the OBR chain")
MODEL_HELP = "4-mass: ArtSim (the default); rigid: the previous rigid-body model"
#: The help of every subcommand's positional shot workbook.
SHOT_HELP = "the shot's workbook, in the report's layout (.xlsx, .xlsm or .xls)"


def add_integrator(p):
    p.add_argument("--integrator", choices=sorted(INTEGRATORS), default="legacy",
                   help=INTEGRATOR_HELP)


def add_model(p):
    p.add_argument("--model", choices=MODELS, default="4-mass", help=MODEL_HELP)


def add_output(p, what, default, metavar="OUT.xlsx"):
    """``-o``/``--output``: ``what`` the file holds, and its ``default`` name."""
    p.add_argument("-o", "--output", metavar=metavar, help=f"{what} (default: {default})")


def add_force(p, metavar="OUT.xlsx"):
    p.add_argument("--force", action="store_true", help=f"overwrite {metavar} if it exists")


def add_run_options(p, model=True):
    """``--integrator`` and (unless ``model`` is false) ``--model``."""
    add_integrator(p)
    if model:
        add_model(p)
