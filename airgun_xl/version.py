"""The package's version: one place, at the ground floor, that every layer may import."""

__version__ = "0.1.0"
