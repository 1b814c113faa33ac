"""Analytic reference solutions used to validate the numerics."""
from fretsim.reference.hertz import HertzLine, HertzPoint, effective_modulus, hertz_line, hertz_point

__all__ = ["HertzLine", "HertzPoint", "effective_modulus", "hertz_line", "hertz_point"]
