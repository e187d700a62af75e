"""Model variants, for comparison as in the report's Fig. 13.

``4-mass`` is ArtSim. ``rigid`` is the previous rigid-body model: the bird is one rigid mass,
m31 + m32 + m33, against the same mitigator force law and mass transfer, with no internal
springs, so it shows no high-frequency content. It runs as the one-mass reduced model.
"""
from . import choices
from .errors import OptionError

MODELS = choices.MODELS


def apply_model(p, model="4-mass"):
    """The parameters ``p`` as the chosen model sees them."""
    if model == "4-mass":
        return p
    if model == "rigid":
        return p.replace(m31=p.m31 + p.m32 + p.m33, m32=0.0, m33=0.0, k2=0.0, k3=0.0,
                         v32=p.v31, v33=p.v31)
    raise OptionError(f"model: found {model!r}, expected one of {', '.join(MODELS)}")
