"""The kernels' interface, declared once: the parameters they take, in order, and the figures a
run returns, in order.

The compiled kernel's enum (``P_*`` in ``_artsim.c``) and its ``finish_run``, the Python twin
(``_reference.py``) and the callers (:mod:`~airgun_xl.engine.integrators`,
:mod:`~airgun_xl.engine.batch`) take their names and positions from here;
``tests/test_kernel_interface.py`` parses the C source and checks it against this declaration.
"""

#: Each parameter: (name, the C enum's name), in the kernels' order: the shot's fields
#: (:class:`~airgun_xl.params.ShotParams`), the crush law's seven coefficients (constant term
#: first), the unloading variant (0 the macro's, 1 continuous), and the displacement bound.
PARAMS = (
    ("m1", "P_M1"), ("m31", "P_M31"), ("m32", "P_M32"), ("m33", "P_M33"), ("k2", "P_K2"),
    ("k3", "P_K3"), ("delta", "P_DELTA"), ("rho", "P_RHO"), ("rcone", "P_RCONE"),
    ("hcone", "P_HCONE"), ("hcylinder", "P_HCYL"), ("mmitigator", "P_MMIT"),
    ("vcone", "P_VCONE"), ("E", "P_E"), ("ec", "P_EC"), ("sigmay", "P_SIGMAY"),
    ("zeta", "P_ZETA"), ("v1", "P_V1"), ("v31", "P_V31"), ("v32", "P_V32"), ("v33", "P_V33"),
    ("law0", "P_LAW0"), ("law1", "P_LAW1"), ("law2", "P_LAW2"), ("law3", "P_LAW3"),
    ("law4", "P_LAW4"), ("law5", "P_LAW5"), ("law6", "P_LAW6"), ("unloading", "P_UNLOAD"),
    ("bound", "P_BOUND"),
)

#: The parameters that are a shot's fields, by name, in order.
SHOT_FIELDS = tuple(name for name, _ in PARAMS[:PARAMS.index(("law0", "P_LAW0"))])

#: Each figure a run returns: (name, the C Mitigator's field ``finish_run`` copies), in order.
FINALS = (
    ("final_m1", "M1"), ("final_m31", "m31"), ("bad_row", "bad"), ("x_plastic", "xPlastic"),
    ("max_relative_velocity", "max_Vobr"), ("min_relative_velocity", "min_Vobr"),
    ("max_crushed_mass", "max_temp"), ("max_crush", "maxmitdef"),
    ("unloading_onsets", "onsets"), ("second_onset", "second_onset"),
)

PARAM_COUNT = len(PARAMS)
FINAL_COUNT = len(FINALS)
_FINAL_INDEX = {name: i for i, (name, _) in enumerate(FINALS)}
_PARAM_INDEX = {name: i for i, (name, _) in enumerate(PARAMS)}


def final(name: str) -> int:
    """The column of figure ``name`` in a run's finals (a batch's ``finals[:, final(...)]``)."""
    return _FINAL_INDEX[name]


def param(name: str) -> int:
    """The position of parameter ``name`` in the kernels' parameter list."""
    return _PARAM_INDEX[name]
