"""The report's stiffness and damping formulas, with units.

Pure functions in SI unless a name says otherwise. The report derives the OBR's stiffness
from its geometry (section 4.1), from a measured resonance (Eq. 19), and the dampers from a
damping ratio (Eq. 18).
"""
import math

LBF = 4.4482216152605  # N per pound-force
INCH = 0.0254  # m per inch
PSI = LBF / INCH ** 2  # Pa per psi
LB_PER_IN = LBF / INCH  # N/m per lbf/in (175.13)


def axial_stiffness(area, modulus, length):
    """Stiffness of a bar in tension or compression, k = A E / L.

    Parameters
    ----------
    area : float
        Cross-section [m^2].
    modulus : float
        Elastic modulus [Pa].
    length : float
        Length [m].

    Returns
    -------
    float
        Stiffness [N/m] (positive; the legacy sheet stores it negative).
    """
    return area * modulus / length


def axial_stiffness_inch(area_in2, modulus_psi, length_in):
    """k = A E / L from inches and psi, as the report computes k2 (section 4.1).

    Returns
    -------
    (float, float)
        Stiffness in lbf/in and in N/m.
    """
    k_lb_in = area_in2 * modulus_psi / length_in
    return k_lb_in, axial_stiffness(area_in2 * INCH ** 2, modulus_psi * PSI, length_in * INCH)


def stiffness_from_frequency(mass, omega=None, frequency=None):
    """k = omega^2 M / 4 from a measured resonance, Eq. (19).

    Parameters
    ----------
    mass : float
        Mass of the object [kg].
    omega : float, optional
        Angular frequency [rad/s].
    frequency : float, optional
        Frequency [Hz], when ``omega`` is not given.

    Returns
    -------
    float
        Stiffness [N/m].
    """
    if omega is None:
        if frequency is None:
            raise ValueError("give omega or frequency")
        omega = 2 * math.pi * frequency
    return omega * omega * mass / 4


def damping_coefficient(stiffness, mass, zeta):
    """c = 2 zeta sqrt(k m), Eq. (18).

    Parameters
    ----------
    stiffness : float
        Spring stiffness [N/m], positive (the sheet's negative value is taken as its size).
    mass : float
        Mass assigned to the node [kg]; the macro uses the sum of the two masses.
    zeta : float
        Damping ratio [-].

    Returns
    -------
    float
        Damping coefficient [N s/m].
    """
    return 2 * zeta * math.sqrt(abs(stiffness) * mass)
