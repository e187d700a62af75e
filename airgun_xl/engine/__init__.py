"""The simulation engine: integrators, the macro's derived columns, and its filter."""
from .derived import test_item_derivatives
from .filtered import filtered_acceleration
from .integrators import INTEGRATORS, History, get_integrator

__all__ = ["INTEGRATORS", "History", "filtered_acceleration", "get_integrator",
           "test_item_derivatives"]
