"""Analytic reference solutions used to validate the numerics."""
from fretsim.reference.hertz import (HertzElliptical, HertzLine, HertzPoint, effective_modulus, hertz_elliptical,
                                     hertz_line, hertz_point)

__all__ = ["HertzElliptical", "HertzLine", "HertzPoint", "effective_modulus", "hertz_elliptical", "hertz_line",
           "hertz_point"]
