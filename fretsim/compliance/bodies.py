"""The bodies' share of the stroke from their shapes: the flat as a block whose far face carries the stroke, the
moving cylinder held at a height above the contact (``geometry.flat_width``, ``flat_thickness``, ``moving_height``).

A half-plane takes up a tangential load with a displacement defined only up to a constant (the 2D datum of
:mod:`fretsim.compliance.tangential`); a finite body held at a face fixes that constant.  Near the contact the
finite body's displacement is the half-plane's (the log term, which sets stick and slip); the rest of the body
adds a displacement that is nearly uniform over a contact much smaller than the body.  So each body keeps the
half-plane kernel and gets its own datum distance d, chosen so that the mean displacement of the loaded strip
equals the finite body's, which a one-off plane-strain solve of the body gives: bilinear quadrilaterals on a
mesh graded from the strip (elements a/16 there, growing by 1.1 at most), the held face fixed, the strip under a
uniform shear traction.  For the half-plane with datum d, a unit force per unit length spread over |x| ≤ a has
the mean displacement (2/πE')·[ln(d/2a) + 3/2] (E' = E/(1 − ν²); the strip kernel's mean over the strip), so

    d = 2a·exp(πE'·ū/2 − 3/2).

The strip's width changes d by less than 1 % while 2a stays below a tenth of the body (the test), so it is taken
as the unworn contact's.  In 3D (a line contact of length L) the half-space is already referred to infinity:
the same plane-strain d turns into a constant added to the tangential kernel, (2/πE'L)·ln(d/d_L) per unit force
(d_L: the 2D datum equivalent to the 3D half-space), which assumes the body long compared with its section, as
the 2D model does (README: the bodies' share of the stroke).

Shapes (mm, plane strain, the contact at y = 0):
  * the flat: the block |x| ≤ W/2, 0 ≤ y ≤ T, held (both components) at y = T;
  * the moving cylinder of radius R: the circular segment 0 ≤ y ≤ h ≤ R, half-width √(c² + 2Ry − y²) (the
    circle, widened at its tip to c = 2a so that the strip has a face to act on), held at y = h.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
import numpy as np

STRIP_ELEMENTS = 16  # elements across each half of the loaded strip
GROWTH = 1.1  # largest ratio of neighbouring element sizes away from the strip


@dataclass(frozen=True)
class Body:
    """A body's shape for its tangential compliance, held at y = ``height`` above the contact (mm): a block of
    half-width ``half``, or a cylinder of radius ``radius`` whose tip is widened to ``half``."""
    kind: str  # "block" or "cylinder"
    height: float
    half: float
    radius: float = 0.0

    def half_width(self, y) -> np.ndarray:
        """The section's half-width at height y above the contact (mm)."""
        y = np.asarray(y, dtype=float)
        if self.kind == "block":
            return np.full(y.shape, self.half)
        return np.sqrt(self.half ** 2 + 2.0 * self.radius * y - y ** 2)

    @property
    def name(self) -> str:
        return (f"block {2 * self.half:g} × {self.height:g} mm" if self.kind == "block" else
                f"cylinder R {self.radius:g} mm held {self.height:g} mm above the contact")


def block(width: float, thickness: float) -> Body:
    return Body("block", float(thickness), width / 2.0)


def cylinder(radius: float, height: float, strip_half_width: float) -> Body:
    return Body("cylinder", float(height), 2.0 * strip_half_width, float(radius))


def _graded(start: float, stop: float, first: float) -> np.ndarray:
    """Points from ``start`` to ``stop`` whose spacing starts at ``first`` and grows by GROWTH at most."""
    pts, h = [start], first
    while pts[-1] + h < stop - 0.5 * h:
        pts.append(pts[-1] + h)
        h *= GROWTH
    pts.append(stop)
    return np.array(pts)


def _mesh(body: Body, a: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
    """Nodes (n, 2), Q4 elements (m, 4), the strip's bottom-row node indices, and the row length.

    The columns are graded from the strip out to the held face's half-width; a narrower section (a cylinder near
    its tip) squeezes the columns outside the strip into its own width, row by row, and leaves the strip's
    columns upright: mapping every column by the section's width (x = ξ·w(y)) sheared the elements next to the
    loaded face by 15:1 on a cylinder, and its displacement converged only to first order in the element size."""
    y = _graded(0.0, body.height, a / STRIP_ELEMENTS)
    widths = body.half_width(y)
    if widths.min() < a * (1 - 1e-12):
        raise ValueError(f"the {body.name} is narrower ({widths.min():g} mm) than the loaded strip ({a:g} mm)")
    top = float(widths.max())
    inside = np.linspace(0.0, a, STRIP_ELEMENTS + 1)
    outside = _graded(a, top, a / STRIP_ELEMENTS)[1:] if top > a * (1 + 1e-9) else np.zeros(0)
    half = np.concatenate([inside, outside])
    x0 = np.concatenate([-half[:0:-1], half])
    nx = x0.size
    squeeze = (widths[:, None] - a) / max(top - a, 1e-300)
    X = np.where(np.abs(x0)[None, :] <= a, x0[None, :], np.sign(x0)[None, :] * (a + (np.abs(x0)[None, :] - a) * squeeze))
    Y = np.broadcast_to(y[:, None], X.shape)
    nodes = np.column_stack([X.ravel(), Y.ravel()])
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(y.size - 1))
    n0 = (j * nx + i).ravel()
    elements = np.column_stack([n0, n0 + 1, n0 + nx + 1, n0 + nx])
    strip = np.flatnonzero(np.abs(x0) <= a * (1 + 1e-9))
    return nodes, elements, strip, nx


def _stiffness(nodes: np.ndarray, elements: np.ndarray, youngs_modulus: float, poissons_ratio: float):
    """The plane-strain stiffness matrix of bilinear quadrilaterals (2 × 2 Gauss points)."""
    import scipy.sparse as sp  # here, not at the top: planning a case without shapes must not load scipy.linalg
    e, nu = youngs_modulus, poissons_ratio
    d = e / ((1 + nu) * (1 - 2 * nu)) * np.array([[1 - nu, nu, 0], [nu, 1 - nu, 0], [0, 0, (1 - 2 * nu) / 2]])
    g = 1.0 / math.sqrt(3.0)
    xy = nodes[elements]  # (m, 4, 2)
    ke = np.zeros((len(elements), 8, 8))
    for s, t in ((-g, -g), (g, -g), (g, g), (-g, g)):
        dn = 0.25 * np.array([[-(1 - t), (1 - t), (1 + t), -(1 + t)], [-(1 - s), -(1 + s), (1 + s), (1 - s)]])
        jac = np.einsum("an,mnb->mab", dn, xy)  # (m, 2, 2)
        det = jac[:, 0, 0] * jac[:, 1, 1] - jac[:, 0, 1] * jac[:, 1, 0]
        if np.any(det <= 0):
            raise ValueError("a degenerate element in the body's mesh")
        dxy = np.linalg.solve(jac, np.broadcast_to(dn, (len(elements), 2, 4)))  # (m, 2, 4): dN/dx, dN/dy
        b = np.zeros((len(elements), 3, 8))
        b[:, 0, 0::2], b[:, 1, 1::2] = dxy[:, 0], dxy[:, 1]
        b[:, 2, 0::2], b[:, 2, 1::2] = dxy[:, 1], dxy[:, 0]
        ke += np.einsum("mia,ij,mjb,m->mab", b, d, b, det)
    dofs = np.repeat(2 * elements, 2, axis=1) + np.tile([0, 1], 4)
    rows = np.repeat(dofs, 8, axis=1).ravel()
    cols = np.tile(dofs, (1, 8)).ravel()
    n = 2 * len(nodes)
    return sp.csr_matrix((ke.ravel(), (rows, cols)), shape=(n, n))


def strip_displacement(body: Body, youngs_modulus: float, poissons_ratio: float, strip_half_width: float) -> float:
    """ū (mm per N/mm): the mean x-displacement of the strip |x| ≤ a at y = 0 under a unit tangential force per
    unit length spread evenly over it, relative to the held face."""
    import scipy.sparse.linalg as spla
    a = strip_half_width
    nodes, elements, strip, nx = _mesh(body, a)
    k = _stiffness(nodes, elements, youngs_modulus, poissons_ratio)
    n = len(nodes)
    held = np.arange(n - nx, n)  # the last row
    fixed = np.concatenate([2 * held, 2 * held + 1])
    f = np.zeros(2 * n)
    xs = nodes[strip, 0]
    tau = 1.0 / (2.0 * a)
    for left, right, (x0, x1) in zip(strip[:-1], strip[1:], zip(xs[:-1], xs[1:])):  # edge loads, linear shapes
        f[2 * left] += tau * (x1 - x0) / 2
        f[2 * right] += tau * (x1 - x0) / 2
    free = np.setdiff1d(np.arange(2 * n), fixed)
    u = np.zeros(2 * n)
    u[free] = spla.spsolve(k[free][:, free].tocsc(), f[free])
    ux = u[2 * strip]
    return float(np.sum(0.5 * (ux[1:] + ux[:-1]) * np.diff(xs)) / (2.0 * a))


@lru_cache(maxsize=64)
def strip_compliance(body: Body, youngs_modulus: float, poissons_ratio: float, strip_half_width: float) -> float:
    """:func:`strip_displacement`, kept per process (a sweep's points share their bodies)."""
    return strip_displacement(body, youngs_modulus, poissons_ratio, strip_half_width)


def log_datum(body: Body, youngs_modulus: float, poissons_ratio: float, strip_half_width: float) -> float:
    """ln of the 2D datum distance d (mm) at which the half-plane takes up the stroke as the finite ``body`` does.
    The kernel needs only ln d, and d itself overflows for a block that bends (a thickness several times its
    width: ū grows as the cube of the ratio)."""
    e_plane = youngs_modulus / (1.0 - poissons_ratio ** 2)
    u = strip_compliance(body, youngs_modulus, poissons_ratio, strip_half_width)
    return math.log(2.0 * strip_half_width) + math.pi * e_plane * u / 2.0 - 1.5


def datum(body: Body, youngs_modulus: float, poissons_ratio: float, strip_half_width: float) -> float:
    """The 2D datum distance d (mm): exp(:func:`log_datum`)."""
    return math.exp(log_datum(body, youngs_modulus, poissons_ratio, strip_half_width))
