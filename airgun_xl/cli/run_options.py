"""The options every running command shares, declared once: ``--integrator``, ``--model``,
``-o``/``--output`` and ``--force`` (their help texts then match across subcommands)."""
import argparse

from ..app.declared import INTEGRATOR_HELP, MODEL_HELP, SHOT_HELP
from ..choices import INTEGRATORS, MODELS

__all__ = ["INTEGRATOR_HELP", "MODEL_HELP", "SHOT_HELP"]


def add_integrator(p, repeated=False):
    """``--integrator``: one choice; ``repeated``, given once for each integrator a command
    runs side by side (convergence), into a list."""
    if not repeated:
        p.add_argument("--integrator", choices=sorted(INTEGRATORS), default="legacy",
                       help=INTEGRATOR_HELP)
        return
    p.add_argument("--integrator", action=Integrators, default=["legacy"],
                   metavar="{" + ",".join(sorted(INTEGRATORS)) + "}",
                   help=INTEGRATOR_HELP + "; give it again to run another side by side: "
                        "--integrator legacy --integrator newmark")


class Integrators(argparse.Action):
    """A repeated ``--integrator``, one choice each time, into a list (the default's list
    replaced by the first one given). ``legacy,newmark`` is the old spelling of two, noted."""

    def __call__(self, parser, namespace, values, option_string=None):
        from .messages import later
        from .vocabulary import old_spelling_note

        names = [n.strip() for n in str(values).split(",")]
        if any(n not in INTEGRATORS for n in names):
            raise argparse.ArgumentError(self, f"found {values!r}, expected one of "
                                               f"{', '.join(sorted(INTEGRATORS))}")
        if len(names) > 1:
            later([old_spelling_note(f"{option_string} {values}", " ".join(
                f"{option_string} {n}" for n in names))])
        given = getattr(namespace, "integrators_given", False)
        chosen = (getattr(namespace, self.dest) if given else []) + names
        setattr(namespace, self.dest, list(dict.fromkeys(chosen)))  # each once, in order
        namespace.integrators_given = True


def add_model(p):
    p.add_argument("--model", choices=MODELS, default="4-mass", help=MODEL_HELP)


def add_output(p, what, default, metavar="OUT.xlsx"):
    """``-o``/``--output``: ``what`` the file holds, and its ``default`` name."""
    from .vocabulary import One

    p.add_argument("-o", "--output", metavar=metavar, action=One,
                   help=f"{what} (default: {default})")


def add_pdf(p, what):
    """``--pdf FILE.pdf``: ``what`` the report holds (it needs matplotlib)."""
    from .vocabulary import One

    p.add_argument("--pdf", metavar="FILE.pdf", action=One,
                   help=f"also write {what} as a PDF (needs matplotlib: pip install "
                        "'airgun-xl[plots]')")


def add_crush_law(p, archive=True):
    """``--crush-law``, for every command that runs a shot; with ``archive``, the
    ``--archive DIR`` its library laws are read from (a command whose ``--archive`` already
    says more, fill's and accept's, gives False)."""
    from .vocabulary import One

    p.add_argument("--crush-law", metavar="LAW", default="workbook",
                   help="workbook: the law the workbook's Crush law sheet names (a calibrated "
                        "workbook's fitted law), else the macro's (default); legacy: the "
                        "macro's polynomial, Eq. (8), whatever the workbook says; NAME or "
                        "NAME@N: a law of the --archive's library (calibrate --archive "
                        "--name)")
    if archive:
        p.add_argument("--archive", metavar="DIR", action=One,
                       help="the archive whose library --crush-law NAME is read from "
                            "(default: $AIRGUN_XL_ARCHIVE when set)")


def add_json(p, what="the outcome"):
    """``--json``: the command's outcome as one JSON document on stdout instead of its
    lines (for a LIMS); its warnings still on stderr, its exit status the same; no
    progress bar."""
    p.add_argument("--json", action="store_true",
                   help=f"print {what} as one JSON document instead of its lines; the exit "
                        "status and the warnings on stderr are the same")


def add_force(p, metavar="OUT.xlsx"):
    p.add_argument("--force", action="store_true", help=f"overwrite {metavar} if it exists")


def add_run_options(p, model=True):
    """``--integrator`` and (unless ``model`` is false) ``--model``."""
    add_integrator(p)
    if model:
        add_model(p)
