"""The contact geometries, one small object each: initial separation, Hertz estimate, 2D model, limits.

Every geometry knows

* ``separation(grid)`` — the initial gap ε between the undeformed bodies at mid-stroke (paper Eqs. 9–10),
  +inf where they cannot touch (beyond a cylinder's ends);
* ``hertz(load, e_star)`` — the Hertz contact it starts from (half-widths along x and y, peak pressure),
  which sizes the grid;
* ``line_length`` — the contact length of a line contact (its 2D model carries load per unit length),
  None for a point contact, which has no 2D model;
* ``limits`` — where the geometry stops describing the body (worn through, the paraboloid of Eqs. 9–10 no
  longer the circle);
* ``body_corrections`` and ``extra_compliance(grid, E, ν)`` — the corrections the moving body's own shape adds
  to the half-space's compliance (the tube's ring bending), and the operator of them;
* ``free_faces`` — the bodies that end in free faces across the contact (y = ±length/2), as (body, length)
  pairs: a cylinder's own ends, and the flat's when the case gives its length (paper §2.1, Fig. 2).

``from_case(values, fail)`` builds one from the validated keys of its case section (``fretsim.case``), reporting
any contradiction between them with ``fail(key, message)``; the reader knows no geometry by name.

x is the sliding direction, y across it; the moving body is the one that slides.  All lengths in mm.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar, Optional

import numpy as np

from fretsim.grid import Grid
from fretsim.reference import hertz_elliptical, hertz_line


@dataclass(frozen=True)
class HertzEstimate:
    """The unworn contact: half-widths along x and y (mm), peak pressure (MPa); ``line`` for line contacts."""

    half_width_x: float
    half_width_y: float
    peak_pressure: float
    line: bool


@dataclass(frozen=True)
class Limits:
    """Where the geometry stops meaning anything: the moving body worn through ``wear_depth`` (mm), or the
    contact reaching ``reach_x`` from the centre along x (and ``reach_y`` along y, None for a line contact)."""

    wear_depth: float
    reach_x: float
    reach_y: Optional[float]
    wear_what: str  # what "worn through" means for this body, for the message


class Geometry:
    """Base of the family; subclasses are frozen dataclasses registered in :data:`GEOMETRIES`."""

    kind: ClassVar[str]
    line_length: Optional[float] = None

    @classmethod
    def from_case(cls, values: dict, fail) -> Optional["Geometry"]:
        """The geometry of a case section's validated values (mm; absent options None), or None after reporting
        with ``fail(key, message)`` why the values do not make one."""
        return cls(**values)

    def separation(self, grid: Grid) -> np.ndarray:
        raise NotImplementedError

    def hertz(self, load: float, e_star: float) -> HertzEstimate:
        raise NotImplementedError

    @property
    def limits(self) -> Limits:
        raise NotImplementedError

    @property
    def has_2d(self) -> bool:
        return self.line_length is not None

    @property
    def y_edges_free(self) -> bool:
        """True when the contact may end at the grid's y edges (the ends of a line contact)."""
        return self.line_length is not None

    body_corrections: ClassVar[tuple[str, ...]] = ()  # compliance corrections of the body's own shape
    axial_profile: ClassVar[bool] = False  # a shape along the line (y) that a 2D section cannot carry

    def extra_compliance(self, grid: Grid, youngs_modulus: float, poissons_ratio: float):
        return None

    def tangential_shapes(self, strip_half_width: float) -> tuple:
        """Each body's shape for its tangential compliance ((moving, stationary): None, a half-space) and the
        loaded strip's half-width (mm)."""
        return (None, None), strip_half_width

    def shape_sizes(self) -> list:
        return []

    @property
    def free_faces(self) -> tuple[tuple[str, float], ...]:
        return ()

    def scar_half_widths(self, volume: float) -> tuple[float, float]:
        """Half-widths (mm) along x and y of a scar holding the worn ``volume`` (mm³) of both bodies (sizing).

        A cylinder worn to a circular segment of half-width b holds V ≈ 2b³L/(3R); the paraboloid
        x²/(2Rx) + y²/(2Ry) cut at depth h holds V = πh²√(RxRy), over half-widths √(2Rx·h), √(2Ry·h).
        """
        raise NotImplementedError


def _cap_half_widths(volume: float, rx: float, ry: float) -> tuple[float, float]:
    depth = math.sqrt(volume / (math.pi * math.sqrt(rx * ry)))
    return math.sqrt(2 * rx * depth), math.sqrt(2 * ry * depth)


def _line_gap(grid: Grid, radius: float, length: float, drop: Optional[np.ndarray] = None) -> np.ndarray:
    X, Y = grid.mesh()
    gap = X**2 / (2.0 * radius)  # Eq. 9
    if grid.plane_strain:
        return gap
    if drop is not None:
        gap = gap + drop[:, None]
    return np.where(np.abs(Y) <= length / 2.0 + 1e-12 * length, gap, np.inf)


MAX_BLOCK_ASPECT = 2.0  # the bodies' solve checked against an independent one over this range (tests/test_bodies.py)
MAX_CYLINDER_RATIO = 10.0


@dataclass(frozen=True)
class CylinderOnFlat(Geometry):
    """A cylinder of radius R and length L, axis along y, on a flat (paper Eq. 9)."""

    kind: ClassVar[str] = "cylinder_on_flat"
    radius: float
    length: float
    block_length: Optional[float] = None  # the flat's length along y when it ends in free faces (mm)
    flat_width: Optional[float] = None  # the flat as a block W × T whose far face carries the stroke (mm)
    flat_thickness: Optional[float] = None
    moving_height: Optional[float] = None  # where the cylinder is held, above the contact (mm)

    @classmethod
    def from_case(cls, values: dict, fail) -> Optional["CylinderOnFlat"]:
        block, length = values.get("block_length"), values["length"]
        if block is not None and block < length * (1 - 1e-9):
            fail("block_length", f"the flat ({block!r} mm) is shorter than the {cls.kind.split('_')[0]} "
                                 f"({length!r} mm): its edges would cut into the contact, which fretsim does not "
                                 f"model; expected at least geometry.length")
            return None
        width, thickness = values.get("flat_width"), values.get("flat_thickness")
        if (width is None) != (thickness is None):
            given, missing = ("flat_width", "flat_thickness") if thickness is None else ("flat_thickness", "flat_width")
            fail(missing, f"missing: geometry.{given} makes the flat a block, which needs both its width and its "
                          f"thickness (or neither: a half-space)")
            return None
        if width is not None and thickness > MAX_BLOCK_ASPECT * width * (1 + 1e-9):
            fail("flat_thickness", f"{thickness!r} mm is more than {MAX_BLOCK_ASPECT:g}× the block's width {width!r} "
                                   f"mm: a block that slender bends under the shear, which the bodies' solve "
                                   f"(bilinear elements) models too stiffly; verified up to thickness "
                                   f"{MAX_BLOCK_ASPECT:g}× the width (README: the bodies' share of the stroke)")
            return None
        height, radius = values.get("moving_height"), values["radius"]
        if height is not None and height < radius / MAX_CYLINDER_RATIO * (1 - 1e-9):
            fail("moving_height", f"{height!r} mm is less than a {MAX_CYLINDER_RATIO:g}th of the radius {radius!r} mm: "
                                  f"a cylinder held that close to its contact is a thin slice, which the bodies' "
                                  f"solve models too stiffly; verified from R/{MAX_CYLINDER_RATIO:g} to R")
            return None
        if height is not None and height > radius * (1 + 1e-9):
            fail("moving_height", f"{height!r} mm is above the cylinder's radius {radius!r} mm: fretsim models the "
                                  f"moving body as the cylinder's segment up to where it is held; expected at most "
                                  f"geometry.radius (a half-cylinder held at its flat face: the radius)")
            return None
        return cls(**values)

    def shape_sizes(self) -> list:
        """(case key, mm) of each given size of the bodies' shapes."""
        return [(f"geometry.{k}", getattr(self, k)) for k in ("flat_width", "flat_thickness", "moving_height")
                if getattr(self, k) is not None]

    def tangential_shapes(self, strip_half_width: float) -> tuple:
        """Each body's shape for its tangential compliance ((moving, stationary), None for a half-space) and the
        loaded strip's half-width (mm)."""
        from fretsim.compliance import bodies
        moving = bodies.cylinder(self.radius, self.moving_height, strip_half_width) if self.moving_height else None
        flat = bodies.block(self.flat_width, self.flat_thickness) if self.flat_width else None
        return (moving, flat), strip_half_width

    @property
    def line_length(self) -> float:
        return self.length

    @property
    def free_faces(self) -> tuple[tuple[str, float], ...]:
        return (("moving", self.length),) + ((("stationary", self.block_length),) if self.block_length else ())

    def separation(self, grid: Grid) -> np.ndarray:
        return _line_gap(grid, self.radius, self.length)

    def hertz(self, load: float, e_star: float) -> HertzEstimate:
        h = hertz_line(load / self.length, self.radius, e_star)
        return HertzEstimate(h.half_width, self.length / 2, h.peak_pressure, True)

    @property
    def limits(self) -> Limits:
        return Limits(self.radius, self.radius / 2, None, f"its radius {self.radius:.4g} mm")

    def scar_half_widths(self, volume: float) -> tuple[float, float]:
        return (1.5 * self.radius * volume / self.length) ** (1 / 3), self.length / 2


@dataclass(frozen=True)
class BallOnFlat(Geometry):
    """A ball of radius R on a flat (paper Eq. 10)."""

    kind: ClassVar[str] = "ball_on_flat"
    radius: float

    def separation(self, grid: Grid) -> np.ndarray:
        X, Y = grid.mesh()
        return (X**2 + Y**2) / (2.0 * self.radius)  # Eq. 10

    def hertz(self, load: float, e_star: float) -> HertzEstimate:
        h = hertz_elliptical(load, self.radius, self.radius, e_star)
        return HertzEstimate(h.ax, h.ay, h.peak_pressure, False)

    @property
    def limits(self) -> Limits:
        return Limits(self.radius, self.radius / 2, self.radius / 2, f"its radius {self.radius:.4g} mm")

    def scar_half_widths(self, volume: float) -> tuple[float, float]:
        return _cap_half_widths(volume, self.radius, self.radius)


@dataclass(frozen=True)
class CrossedCylinders(Geometry):
    """Two cylinders crossed at right angles (wire ropes, paper section 4.1, Fig. 20).

    The moving cylinder (radius R₁) slides ``across`` its axis (axis along y) or ``along`` it (axis along x);
    the stationary one (radius R₂) lies at right angles.  The gap is x²/(2Rx) + y²/(2Ry) with (Rx, Ry) =
    (R₁, R₂) or (R₂, R₁): with R₁ = R₂ it is the ball's (Eq. 10), otherwise the contact is elliptical.
    """

    kind: ClassVar[str] = "crossed_cylinders"
    radius: float  # moving cylinder R₁
    radius_stationary: float  # R₂
    sliding: str = "across"

    @classmethod
    def from_case(cls, values: dict, fail) -> "CrossedCylinders":
        return cls(values["radius"], values.get("radius_stationary") or values["radius"], values["sliding"])

    @property
    def radii_xy(self) -> tuple[float, float]:
        r1, r2 = self.radius, self.radius_stationary
        return (r1, r2) if self.sliding == "across" else (r2, r1)

    def separation(self, grid: Grid) -> np.ndarray:
        rx, ry = self.radii_xy
        X, Y = grid.mesh()
        return X**2 / (2.0 * rx) + Y**2 / (2.0 * ry)

    def hertz(self, load: float, e_star: float) -> HertzEstimate:
        rx, ry = self.radii_xy
        h = hertz_elliptical(load, rx, ry, e_star)
        return HertzEstimate(h.ax, h.ay, h.peak_pressure, False)

    @property
    def limits(self) -> Limits:
        rx, ry = self.radii_xy
        return Limits(min(self.radius, self.radius_stationary), rx / 2, ry / 2,
                      f"the smaller radius {min(self.radius, self.radius_stationary):.4g} mm")

    def scar_half_widths(self, volume: float) -> tuple[float, float]:
        return _cap_half_widths(volume, *self.radii_xy)


@dataclass(frozen=True)
class TubeOnFlat(Geometry):
    """A tube (outer radius R_o, inner R_i), axis along y, on a flat of length L (steam-generator tube and its
    support, paper section 4.3, Fig. 26).  The gap is the cylinder's (Eq. 9) with R_o over the flat's length; the
    tube wall also bends as a ring (:class:`~fretsim.compliance.ring.RingBending`, Eq. 23), and is worn through
    at the wall thickness."""

    kind: ClassVar[str] = "tube_on_flat"
    body_corrections: ClassVar[tuple[str, ...]] = ("ring_bending",)
    outer_radius: float
    inner_radius: float
    length: float

    @classmethod
    def from_case(cls, values: dict, fail) -> Optional["TubeOnFlat"]:
        if values["inner_radius"] >= values["outer_radius"]:
            fail("inner_radius", "must be smaller than geometry.outer_radius")
            return None
        return cls(**values)

    @property
    def line_length(self) -> float:
        return self.length

    @property
    def wall(self) -> float:
        return self.outer_radius - self.inner_radius

    def separation(self, grid: Grid) -> np.ndarray:
        return _line_gap(grid, self.outer_radius, self.length)

    def hertz(self, load: float, e_star: float) -> HertzEstimate:
        h = hertz_line(load / self.length, self.outer_radius, e_star)
        return HertzEstimate(h.half_width, self.length / 2, h.peak_pressure, True)

    @property
    def limits(self) -> Limits:
        return Limits(self.wall, self.outer_radius / 2, None, f"the tube's wall thickness {self.wall:.4g} mm "
                                                              f"(the tube leaks)")

    def scar_half_widths(self, volume: float) -> tuple[float, float]:
        return (1.5 * self.outer_radius * volume / self.length) ** (1 / 3), self.length / 2

    @property
    def free_faces(self) -> tuple[tuple[str, float], ...]:
        return (("stationary", self.length),)  # the support (a flat bar) is as long as the contact; the tube goes on

    def extra_compliance(self, grid: Grid, youngs_modulus: float, poissons_ratio: float):
        from fretsim.compliance.ring import RingBending
        return RingBending(grid, self.outer_radius, self.inner_radius, youngs_modulus, poissons_ratio)


@dataclass(frozen=True)
class RollerOnFlat(CylinderOnFlat):
    """A roller of radius R and length L whose axial profile drops by d(y) from the middle: crowned (a crown
    radius: d = y²/2R_c), edge-rounded (flat over a middle length, then circular: d = (|y| − l/2)²/2r_e), or
    tabulated (d at points along y, interpolated linearly, read as given — an asymmetric profile is asymmetric —
    and mirrored if given for y ≥ 0 only; it must cover the whole length) — what designers
    optimise against the finite cylinder's end peaks.  Gap: x²/2R + d(y) (Eq. 9 plus the profile)."""

    kind: ClassVar[str] = "roller_on_flat"
    axial_profile: ClassVar[bool] = True
    radius: float
    length: float
    crown_radius: Optional[float] = None
    edge_radius: Optional[float] = None
    flat_length: Optional[float] = None
    profile_y: Optional[tuple] = None  # mm
    profile_drop: Optional[tuple] = None  # mm

    @classmethod
    def from_case(cls, values: dict, fail) -> Optional["RollerOnFlat"]:
        values = dict(values)
        table = values.pop("profile", None) or (None, None)
        if not (values["crown_radius"] or values["edge_radius"] or table[0] is not None):
            fail("", "a roller_on_flat needs a profile: crown_radius, edge_radius (with flat_length) or profile (a "
                     "CSV file)")
            return None
        if values["edge_radius"] and values["flat_length"] is None:
            fail("flat_length", "an edge-rounded roller needs the length of its straight middle")
            return None
        cylinder = CylinderOnFlat.from_case({k: values[k] for k in ("radius", "length", "block_length")}, fail)
        if cylinder is None:
            return None
        roller = cls(**values, profile_y=table[0], profile_drop=table[1])
        if table[0] is not None:
            py, _ = roller.table()
            half = 0.5 * values["length"]
            slack = 1e-9 * half  # a table written to the end in rounded millimetres covers it
            if py[0] > -half + slack or py[-1] < half - slack:
                fail("profile", f"the profile covers y from {py[0]:.4g} to {py[-1]:.4g} mm (mirrored where given for "
                                f"y ≥ 0 only), but the roller reaches ±{half:.4g} mm: give the drop over the whole "
                                f"length, so that none of it is guessed")
                return None
        return roller

    # a cylinder's Hertz estimate, limits and scar estimate: the profile only relieves its ends

    def drop(self, y: np.ndarray) -> np.ndarray:
        y = np.asarray(y, dtype=float)
        a = np.abs(y)  # the crown and the edge rounding are symmetric by definition; a table is read as given
        d = np.zeros_like(y)
        if self.crown_radius:
            d = d + a**2 / (2 * self.crown_radius)
        if self.edge_radius:
            flat = 0.5 * (self.flat_length if self.flat_length is not None else 0.0)
            d = d + np.clip(a - flat, 0.0, None) ** 2 / (2 * self.edge_radius)
        if self.profile_y is not None:
            py, pd = self.table()
            d = d + np.interp(y, py, pd)
        return d

    def table(self) -> tuple[np.ndarray, np.ndarray]:
        """The tabulated profile over the whole roller: as given, or mirrored when given for y ≥ 0 only."""
        py, pd = np.asarray(self.profile_y, dtype=float), np.asarray(self.profile_drop, dtype=float)
        if py.min() >= 0:
            keep = py > 0  # y = 0 once
            py, pd = np.concatenate([-py[keep][::-1], py]), np.concatenate([pd[keep][::-1], pd])
        return py, pd

    def separation(self, grid: Grid) -> np.ndarray:
        return _line_gap(grid, self.radius, self.length, None if grid.plane_strain else self.drop(grid.y))


GEOMETRIES: dict[str, type] = {g.kind: g for g in (CylinderOnFlat, BallOnFlat, CrossedCylinders, TubeOnFlat,
                                                    RollerOnFlat)}
