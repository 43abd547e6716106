"""Parameter names and SI units of the plant models, as plain data.

The design loader checks each parameter of a design file against these
units before any model is built, so reading (or rejecting) a design needs
no symbolic model; each plant module re-exports its table as
``PARAMETER_UNITS``.
"""
from __future__ import annotations

#: Quarter-train adhesion model of paper 003 (:mod:`workbench.plants.adhesion`).
ADHESION_003: dict[str, str] = {
    "a": "1", "b": "1", "c": "1",
    "J": "kg m^2", "r": "m", "m": "kg", "zeta": "N m s/rad",
    "c0": "N", "c1": "N s/m", "c2": "N s^2/m^2", "g": "m/s^2",
}
