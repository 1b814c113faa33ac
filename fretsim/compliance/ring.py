"""Ring bending of a tube wall: the compliance C_b added to the contact compliance (paper Eq. 23, Appendix A).

Derived here (Castigliano / unit-load method), not copied from the appendix.  The tube's cross-section is a
thin ring of mean radius R and wall t, in plane strain: flexural rigidity per unit length D = E t³/(12(1 − ν²)),
bending energy only (the appendix's Eq. A1).  As in the appendix, the tube is symmetric about its horizontal
diameter: pressed between the flat and an identical support opposite (the quarter ring of Fig. A1).  The
elementary load is then a pair of equal and opposite vertical unit forces on the vertical chord at x_j — up at
the contact, down at its mirror — which is self-equilibrated, so the closed ring needs no other support.

With ψ the angle from the contact point (ψ = 0 at the bottom), the released structure (the ring cut at the top)
carries the moment M_s(ψ) of the forces on one side of the section.  The closed ring's three redundants follow
from compatibility across the cut, which for constant D reads ∮M dψ = ∮M x dψ = ∮M y dψ = 0 (the elastic
centre); on a circle, with x = R sin ψ and y = −R cos ψ, M is M_s minus its projection on {1, sin ψ, cos ψ}.
By the unit-load method the shortening of the chord at x_i under the pair at x_j is
    δ_ij = (R/D) ∮ M_i(ψ) M_j(ψ) dψ,
symmetric (Maxwell), evaluated in closed form: M is piecewise a combination of 1, sin ψ, cos ψ between the
load points.  By the symmetry the contact point moves half the chord's shortening: C_b = δ/2 per unit length
of tube, between forces per unit length.  For the pair at the very bottom and top this is the classical thin
ring under diametral load: δ = (π/4 − 2/π) P R³/D (Roark; checked in the tests, along with a numerical
quadrature of the strain energy).

Loads on the contact surface (outer radius R_o) at x act on the wall's centre line at ψ = asin(x/R_o).  The
operator applies the same matrix along x in every row of the grid: each row is a slice of tube dy long.
"""
from __future__ import annotations

import numpy as np

from fretsim.compliance.operator import window_grid
from fretsim.grid import Grid

# basis of each piece: (1, sin ψ, cos ψ)


def _released_moment(psi_a: float, psi_b: float, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Breakpoints and coefficients of M_s for +1 (up) at ψ_a and −1 (down) at ψ_b, ring cut at ψ = ±π.

    Section at ψ, part from the free end ψ = −π up to ψ: a vertical force F at (x_k, y_k) gives the moment
    F·(x_k − x(ψ)) about the section, x(ψ) = R sin ψ.  Pieces: (−π, lo), (lo, hi), (hi, π).
    """
    lo, hi = sorted((psi_a, psi_b))
    pieces = []
    for a, b in ((-np.pi, lo), (lo, hi), (hi, np.pi)):
        mid = 0.5 * (a + b)
        coef = np.zeros(3)
        for psi_k, f in ((psi_a, 1.0), (psi_b, -1.0)):
            if psi_k < mid:
                coef += f * np.array([radius * np.sin(psi_k), -radius, 0.0])
        pieces.append(coef)
    return np.array([-np.pi, lo, hi, np.pi]), np.array(pieces)


def _basis_integrals(a, b) -> np.ndarray:
    """∫_a^b f g dψ for f, g in (1, sin, cos): a 3 × 3 matrix (of arrays, for array bounds)."""
    s, c = np.sin, np.cos
    one = b - a
    i_s, i_c = -(c(b) - c(a)), s(b) - s(a)
    i_ss = 0.5 * one - 0.25 * (s(2 * b) - s(2 * a))
    i_cc = 0.5 * one + 0.25 * (s(2 * b) - s(2 * a))
    i_sc = 0.5 * (s(b) ** 2 - s(a) ** 2)
    return np.array([[one, i_s, i_c], [i_s, i_ss, i_sc], [i_c, i_sc, i_cc]])


def _pieces(psi: float, radius: float):
    """The closed ring's moment for the pair on the chord through ψ: breakpoints and (1, sin, cos) coefficients."""
    bounds, coefs = _released_moment(psi, np.pi - psi if psi >= 0 else -np.pi - psi, radius)
    # subtract the projection on {1, sin, cos} (orthogonal on the full circle, norms 2π, π, π)
    proj = np.zeros(3)
    for k in range(3):
        gram = _basis_integrals(bounds[k], bounds[k + 1])
        proj += gram @ coefs[k]
    proj /= np.array([2 * np.pi, np.pi, np.pi])
    return bounds, coefs - proj


def chord_flexibility(psi: np.ndarray, radius: float, rigidity: float) -> np.ndarray:
    """δ_ij (mm per N/mm): shortening of the chord through ψ_i under a unit pair on the chord through ψ_j.

    All pairs at once: the product M_i·M_j is piecewise over the union of their breakpoints (six, five pieces),
    each piece integrated in closed form on the basis (1, sin, cos).
    """
    psi = np.asarray(psi, dtype=float)
    n = psi.size
    bounds = np.empty((n, 4))
    coefs = np.empty((n, 3, 3))
    for k, p in enumerate(psi):
        bounds[k], coefs[k] = _pieces(p, radius)
    out = np.empty((n, n))
    block = max(1, 200_000 // n)  # rows at a time: temporaries of ~100 values per pair stay under ~200 MB
    for start in range(0, n, block):
        rows = slice(start, min(n, start + block))
        m = rows.stop - rows.start
        bi = bounds[rows]
        edges = np.sort(np.concatenate([np.broadcast_to(bi[:, None, :], (m, n, 4)),
                                        np.broadcast_to(bounds[None, :, 1:3], (m, n, 2))], axis=2), axis=2)
        a, b = edges[..., :-1], edges[..., 1:]
        mid = 0.5 * (a + b)
        # which piece of M_i and of M_j each interval lies in
        piece_i = (mid[..., None] > bi[:, None, None, 1:3]).sum(-1)  # (m, n, 5)
        piece_j = (mid[..., None] > bounds[None, :, None, 1:3]).sum(-1)
        fi = np.take_along_axis(np.broadcast_to(coefs[rows, None, :, :], (m, n, 3, 3)), piece_i[..., None], axis=2)
        fj = np.take_along_axis(np.broadcast_to(coefs[None, :, :, :], (m, n, 3, 3)), piece_j[..., None], axis=2)
        gram = _basis_integrals(a, b)  # (3, 3, m, n, 5)
        out[rows] = np.einsum("ijkp,pqijk,ijkq->ij", fi, gram, fj)
    return radius * out / rigidity


def ring_rigidity(outer_radius: float, inner_radius: float, youngs_modulus: float, poissons_ratio: float) -> float:
    """D = E t³ / (12 (1 − ν²)) per unit length (N·mm), plane strain."""
    t = outer_radius - inner_radius
    return youngs_modulus * t**3 / (12.0 * (1.0 - poissons_ratio**2))


class RingBending:
    """u = C_b p on a grid: the ring-bending compliance of a tube along x, the same in every row (paper Eq. 23).

    Rows are slices of tube dy long: the force per unit length of element j is p_j·dx, so the operator's matrix
    along x is ½δ·dx.  Not translation invariant: applied as a dense matrix per row (cheap: M_x² per row).
    """

    convolution = None

    def __init__(self, grid: Grid, outer_radius: float, inner_radius: float, youngs_modulus: float,
                 poissons_ratio: float, _matrix: np.ndarray | None = None):
        self.grid = grid
        self.outer_radius, self.inner_radius = outer_radius, inner_radius
        self.youngs_modulus, self.poissons_ratio = youngs_modulus, poissons_ratio
        if _matrix is None:
            psi = np.arcsin(np.clip(grid.x / outer_radius, -1.0, 1.0))
            mean = 0.5 * (outer_radius + inner_radius)
            d = ring_rigidity(outer_radius, inner_radius, youngs_modulus, poissons_ratio)
            _matrix = 0.5 * chord_flexibility(psi, mean, d) * grid.dx
        self.matrix = _matrix  # along x, (Mx, Mx)

    @property
    def shape(self) -> tuple[int, int]:
        return self.grid.shape

    def __call__(self, p: np.ndarray) -> np.ndarray:
        return p @ self.matrix.T

    def dense(self) -> np.ndarray:
        return np.kron(np.eye(self.grid.shape[0]), self.matrix)

    def restrict(self, rows: slice, cols: slice) -> "RingBending":
        return RingBending(window_grid(self.grid, rows, cols), self.outer_radius, self.inner_radius,
                           self.youngs_modulus, self.poissons_ratio, _matrix=self.matrix[cols, cols])

    window = restrict
