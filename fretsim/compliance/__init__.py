"""Influence operators: the normal surface displacement due to element pressures, as a family.

Every operator has one small interface (see :mod:`fretsim.compliance.operator`): apply, ``dense()``,
``restrict(rows, cols)``, ``grid`` and its translation-invariant part ``convolution``.  Models add:
the half-space of both bodies (:mod:`.halfspace`), and the geometry- or body-specific corrections added to it:
the tube wall's ring bending (:mod:`.ring`) and the free faces of bodies that end across the contact
(:mod:`.free_faces`).
"""
from fretsim.compliance.halfspace import HalfSpace, influence_kernel, love_rectangle, strip_plane_strain
from fretsim.compliance.operator import DENSE_LIMIT, Convolution, Matrix, Sum, add, scaled, window_grid

__all__ = ["HalfSpace", "Convolution", "Matrix", "Sum", "add", "scaled", "window_grid", "DENSE_LIMIT", "influence_kernel",
           "love_rectangle", "strip_plane_strain"]
