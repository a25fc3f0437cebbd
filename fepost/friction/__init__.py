"""Friction resultants of a pressure map: exact Coulomb integrals and the paper's closed forms."""
