"""The tube's pressure field against an independent elastic solution: a finite-element model of the tube wall.

fretsim models the steam-generator tube (paper section 4.3) as an elastic half-plane for the wall's local
deformation plus the ring-bending compliance C_b of the whole cross-section (Eq. 23, Appendix A, derived in
``fretsim.compliance.ring``).  This script replaces both by a plane-strain finite-element model of the tube's
cross-section (scikit-fem, quadratic quadrilaterals; an optional comparator, not a dependency of fretsim) and
compares the contact pressure each gives, on the same grid, gap and load, at the start (Hertz) and at the end
of the RT and 90 °C runs, and full wear runs with each compliance (the FE tube enters fretsim as the tube's
extra compliance operator, so the run is fretsim's own loop with only the elastic model swapped).

The FE model is the bottom half of the ring, loaded as fretsim's model assumes: the tube pressed between the
flat and an identical support opposite, so the horizontal diameter is a plane of symmetry (u_y = 0 there; one
u_x fixed against translation).  Column j of the FE compliance is the outer surface's vertical displacement at
the element centres x_i under a unit pressure on the projected strip of element j (a vertical traction p·|n_y|
on the arc), read at mesh vertices placed exactly at the grid's edges and centres.  The flat stays a
half-plane (it is one: a bar much larger than the contact).  Both pressure fields come from the same small
active-set contact solver written here, so the comparison isolates the compliance.  The FE's own
discretisation error is shown by solving on two meshes (each grid element split in 2 and in 4 along the arc,
the radial layers halved with them).  The FE matrices are cached in scripts/out/ (a rerun takes seconds).

    pip install scikit-fem
    python scripts/verify_tube_fe.py          # table on stdout, scripts/out/verify_tube_fe.{txt,png}
"""
from __future__ import annotations

import sys
import time

from _study import ROOT, Report, have_comparator  # first: it pins the BLAS threads before numpy loads

import numpy as np  # noqa: E402
import scipy.sparse.linalg as spla  # noqa: E402

from fretsim.case import load_case  # noqa: E402
from fretsim.compliance.halfspace import strip_plane_strain  # noqa: E402
from fretsim.plan import prepare  # noqa: E402
from fretsim.simulate import simulate  # noqa: E402
from fretsim.wear import gap_wear  # noqa: E402

OUT = ROOT / "scripts" / "out"


# ---------------------------------------------------------------------------------------------------------- FE
def _graded(h0: float, growth: float, cap: float, length: float) -> np.ndarray:
    """Spacings from h0 growing geometrically to at most cap, summing exactly to length."""
    steps, total, h = [], 0.0, h0
    while total + h < length:
        steps.append(h)
        total += h
        h = min(h * growth, cap)
    steps[-1] += length - total  # the remainder joins the last step (never smaller than it)
    return np.array(steps)


def tube_fe_compliance(x: np.ndarray, dx: float, outer: float, inner: float, youngs: float, poisson: float,
                       split: int) -> tuple[np.ndarray, int]:
    """C_FE[i, j]: vertical displacement (mm, into the tube) at x_i per MPa of pressure on strip j (plane strain)."""
    from skfem import Basis, ElementQuad2, ElementVector, MeshQuad, asm
    from skfem.models.elasticity import lame_parameters, linear_elasticity

    half = x[-1] + dx / 2
    # arc breakpoints: grid edges and centres (and `split` sub-intervals per element) inside, graded outside
    xin = np.linspace(-half, half, x.size * split + 1)
    psi_in = np.arcsin(xin / outer)
    d0 = psi_in[-1] - psi_in[-2]
    out_steps = _graded(d0, 1.15, 0.01, np.pi / 2 - psi_in[-1])
    psi_out = psi_in[-1] + np.cumsum(out_steps)
    psi = np.concatenate([-psi_out[::-1], psi_in, psi_out])
    radial = _graded(dx / split, 1.2, 0.04, outer - inner)
    r = outer - np.concatenate([[0.0], np.cumsum(radial)])
    r[-1] = inner
    nr, npsi = r.size, psi.size
    R, P = np.meshgrid(r, psi, indexing="ij")  # node (k, m) → k·npsi + m
    pts = np.vstack([(R * np.sin(P)).ravel(), (-R * np.cos(P)).ravel()])
    k, m = np.meshgrid(np.arange(nr - 1), np.arange(npsi - 1), indexing="ij")
    a = (k * npsi + m).ravel()
    # counter-clockwise: outer radius is lower y near the bottom; (k, m) → (k, m+1) → (k+1, m+1) → (k+1, m)
    quads = np.vstack([a, a + 1, a + npsi + 1, a + npsi])
    e1, e3 = pts[:, quads[1]] - pts[:, quads[0]], pts[:, quads[3]] - pts[:, quads[0]]
    if np.any(e1[0] * e3[1] - e1[1] * e3[0] < 0):
        quads = quads[::-1]
    mesh = MeshQuad(pts, quads)
    element = ElementVector(ElementQuad2())
    basis = Basis(mesh, element, intorder=4)
    stiffness = asm(linear_elasticity(*lame_parameters(youngs, poisson)), basis)

    cut = basis.get_dofs(lambda p: np.abs(p[1]) < 1e-9 * outer)
    fixed = np.unique(np.concatenate([cut.all("u^2"), basis.nodal_dofs[0, [npsi * (nr - 1)]]]))
    free = np.setdiff1d(np.arange(basis.N), fixed)
    lu = spla.splu(stiffness[free][:, free].tocsc())

    # consistent loads of a uniform vertical traction |n_y| (unit pressure per projected length) on each straight
    # outer edge of a quadratic element: Δx/6 at each vertex, 2Δx/3 at the midside (exact for a straight edge)
    facet_of = {tuple(sorted(f)): i for i, f in enumerate(mesh.facets.T)}
    first = out_steps.size  # arc index of the first inner breakpoint, outer ring k = 0
    loads = np.zeros((basis.N, x.size))
    for j in range(x.size):
        for q in range(split):
            n0, n1 = first + split * j + q, first + split * j + q + 1
            width = abs(pts[0, n1] - pts[0, n0])
            loads[basis.nodal_dofs[1, [n0, n1]], j] += width / 6
            loads[basis.facet_dofs[1, facet_of[(n0, n1)]], j] += 2 * width / 3
    u = np.zeros_like(loads)
    u[free] = lu.solve(loads[free])
    centre_nodes = first + split * np.arange(x.size) + split // 2
    return u[basis.nodal_dofs[1, centre_nodes]], basis.N


# -------------------------------------------------------------------------------------------- contact solve
def contact(c: np.ndarray, gap: np.ndarray, load: float, dx: float) -> np.ndarray:
    """Frictionless contact under load control by active sets (Kalker): g + C p − α ≥ 0, p ≥ 0, Σ p dx = load."""
    n = gap.size
    active = np.zeros(n, bool)
    active[np.argsort(gap)[:3]] = True
    for _ in range(4 * n):
        s = np.flatnonzero(active)
        a = np.zeros((s.size + 1, s.size + 1))
        a[:-1, :-1] = c[np.ix_(s, s)]
        a[:-1, -1] = -1.0
        a[-1, :-1] = dx
        sol = np.linalg.solve(a, np.concatenate([-gap[s], [load]]))
        p = np.zeros(n)
        p[s] = sol[:-1]
        if p.min() < 0:
            active[s[p[s] < 0]] = False
            continue
        h = gap + c @ p - sol[-1]
        scale = max(np.abs(gap[s]).max(), 1e-12)
        outside = ~active & (h < -1e-12 * scale)
        if not outside.any():
            return p
        active |= outside
    raise RuntimeError("active-set contact did not settle")


def pressure_difference(p: np.ndarray, ref: np.ndarray) -> dict:
    def width(q):  # contact width in elements: from the first to the last carrying over 1 % of the peak
        idx = np.flatnonzero(q > 0.01 * q.max())
        return float(idx[-1] - idx[0] + 1)
    return {"l2": float(np.linalg.norm(p - ref) / np.linalg.norm(ref)),
            "peak": float(p.max() / ref.max() - 1),
            "centre": float(p[p.size // 2] / ref[ref.size // 2] - 1),
            "width": width(p) - width(ref)}


MODELS = {  # label → model.corrections override (the FE tube enters through the tube's extra compliance)
    "FE tube + half-plane flat": "[ring_bending]",
    "fretsim: half-planes + ring bending": "[ring_bending]",
    "half-planes only": "none",
}
REPORTED = ("max_wear_depth_moving_um", "max_wear_depth_stationary_um", "scar_width_moving_mm",
            "scar_width_stationary_mm")


def run(name: str, model: str, extra_grid: list[str], fe: np.ndarray | None):
    """One 2D wear run of a shipped tube case with the given compliance; the FE tube replaces half-plane + C_b."""
    from fretsim.compliance.halfspace import HalfSpace
    from fretsim.compliance.operator import Matrix
    from fretsim.geometry import TubeOnFlat
    from fretsim.simulate import summarize

    original = TubeOnFlat.extra_compliance

    def fe_tube(self, grid, youngs, poisson):  # total = half-plane(E*) − half-plane(tube) + FE tube
        tube = HalfSpace(grid, youngs / (1 - poisson**2)).dense()
        return Matrix(grid, fe - tube)

    case = load_case(ROOT / "cases" / f"{name}.yaml",
                     ["model.dimension=2D", f"model.corrections={MODELS[model]}"] + extra_grid)
    if fe is not None:
        TubeOnFlat.extra_compliance = fe_tube
    try:
        setup, _, _ = prepare(case)
    finally:
        TubeOnFlat.extra_compliance = original
    last, solves = None, 0

    class Last:
        def on_step(self, s, step):
            nonlocal last, solves
            last, solves = step, solves + 1

    t = time.perf_counter()
    simulate(setup, (Last(),))
    return setup, last, summarize(setup, last, solves, time.perf_counter() - t)


def main() -> int:
    if not have_comparator("skfem", "pip install scikit-fem"):
        return 1
    OUT.mkdir(parents=True, exist_ok=True)
    say = Report()

    # one grid for both temperatures: the 90 °C case's (same element size, the wider scar's domain)
    setup90, _, _ = prepare(load_case(ROOT / "cases" / "tube_90C.yaml", ["model.dimension=2D"]))
    grid = setup90.grid
    x, dx = grid.x, grid.dx
    same_grid = [f"grid.domain=[{x.size * dx!r} mm]", f"grid.elements=[{x.size}]"]
    geom = dict(outer=8.75, inner=7.75, youngs=211000.0, poisson=0.29)  # the tube (cases/tube_*.yaml)
    e_flat = 200000.0 / (1 - 0.28**2)  # the 405 SS bar's plane-strain modulus E/(1 − ν²)
    e_tube = geom["youngs"] / (1 - geom["poisson"] ** 2)
    ox = (np.arange(x.size)[:, None] - np.arange(x.size)[None, :]) * dx
    c_flat = strip_plane_strain(ox, dx / 2, e_flat)

    say(f"tube {geom['outer']} / {geom['inner']} mm (Inconel 690, E {geom['youngs'] / 1e3:g} GPa), 405 SS flat; "
        f"2D grid of {x.size} elements of {dx * 1e3:.2f} µm; load {setup90.cycle.load:.4g} N/mm")
    say("FE: plane strain, quadratic quadrilaterals, the bottom half of the ring, symmetric about the horizontal "
        "diameter")
    fe = {}
    for split in (2, 4):
        cache = OUT / f"verify_tube_fe_{x.size}_{split}.npy"
        t = time.perf_counter()
        if cache.exists():
            fe[split] = np.load(cache)
            say(f"  FE mesh, {split} arc intervals per grid element: read from {cache.name}")
            continue
        fe[split], ndof = tube_fe_compliance(x, dx, split=split, **geom)
        np.save(cache, fe[split])
        say(f"  FE mesh, {split} arc intervals per grid element: {ndof} DOFs, {time.perf_counter() - t:.0f} s")

    say()
    say("1. Unworn contact (N = 0), one solve on the same gap: pressure against the FE tube's (fine mesh)")
    say(f"{'model':<38}{'L2':>9}{'peak':>9}{'width':>8}")
    gap0 = setup90.gap.ravel()
    ref0 = contact(c_flat + fe[4], gap0, setup90.cycle.load, dx)
    c_fretsim_bending = None
    for label, c in (("FE tube, coarse mesh (its own error)", c_flat + fe[2]),):
        d = pressure_difference(contact(c, gap0, setup90.cycle.load, dx), ref0)
        say(f"{label:<38}{d['l2']:>9.2%}{d['peak']:>+9.2%}{d['width']:>+8.0f}")
    results = {}
    for name in ("tube_RT", "tube_90C"):
        for model in MODELS:
            results[name, model] = run(name, model, same_grid if name == "tube_RT" else [],
                                       fe[4] if model.startswith("FE") else None)
    for model in list(MODELS)[1:]:
        c = results["tube_RT", model][0].compliance.dense()
        if "bending" in model:
            c_fretsim_bending = c
        d = pressure_difference(contact(c, gap0, setup90.cycle.load, dx), ref0)
        say(f"{model:<38}{d['l2']:>9.2%}{d['peak']:>+9.2%}{d['width']:>+8.0f}")

    say()
    say("2. Wear runs (2D, defaults), each with its own compliance: reported values against the FE-tube run")
    head = "".join(f"{k.replace('_um', ' µm').replace('_mm', ' mm'):>32}" for k in REPORTED)
    say(f"{'case':<10}{'model':<38}{head}{'final p L2':>12}{'loop s':>8}")
    fields = {}
    for name in ("tube_RT", "tube_90C"):
        _, ref_last, ref = results[name, "FE tube + half-plane flat"]
        for model in MODELS:
            _, last, summ = results[name, model]
            vals = "".join(f"{summ[k]:>20.4g} ({summ[k] / ref[k] - 1:+7.2%})" if model[:2] != "FE" else
                           f"{summ[k]:>20.4g}{'':>11}" + " " for k in REPORTED)
            l2 = np.linalg.norm(last.pressure - ref_last.pressure) / np.linalg.norm(ref_last.pressure)
            say(f"{name:<10}{model:<38}{vals}{l2:>12.2%}{summ['wall_time_s']:>8.2f}")
            fields[name, model] = last.pressure.ravel()
    ratio = {m: {k: results["tube_90C", m][2][k] / results["tube_RT", m][2][k] for k in REPORTED[::2]}
             for m in MODELS}
    say()
    say("3. 90 °C over RT (paper: maximum tube depth ×1.76, scar width ×1.59)")
    for m, r in ratio.items():
        say(f"   {m:<38} depth ×{r['max_wear_depth_moving_um']:.3f}, width ×{r['scar_width_moving_mm']:.3f}")

    say()
    say("4. The worn state of the FE-tube run (RT), one solve on its gap with each compliance: a conforming contact's")
    say("   pressure is sensitive to the compliance, which is why the runs' own pressures (2.) are the comparison")
    _, ref_last, _ = results["tube_RT", "FE tube + half-plane flat"]
    setup_fe = results["tube_RT", "FE tube + half-plane flat"][0]
    gap_w = gap0 + gap_wear(ref_last.wear_moving, ref_last.wear_stationary, dx, setup_fe.cycle.stroke,
                            setup_fe.cycle.gap_model).ravel()
    ref_w = contact(c_flat + fe[4], gap_w, setup90.cycle.load, dx)
    say(f"   FE re-solve against the run's own pressure: L2 "
        f"{np.linalg.norm(ref_w - ref_last.pressure.ravel()) / np.linalg.norm(ref_w):.2%}")
    for label, c in (("FE tube, coarse mesh (its own error)", c_flat + fe[2]),
                     ("fretsim: half-planes + ring bending", c_fretsim_bending)):
        d = pressure_difference(contact(c, gap_w, setup90.cycle.load, dx), ref_w)
        say(f"   {label:<38}{d['l2']:>9.2%}{d['peak']:>+9.2%}{d['width']:>+8.0f}")
    say.write(OUT / "verify_tube_fe.txt")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6))
    ax = axes[0]
    nz = np.flatnonzero(ref0 > 0)
    sl = slice(max(0, nz[0] - 8), min(x.size, nz[-1] + 9))
    ax.plot(x[sl] * 1e3, ref0[sl], "k-", lw=1.6, label="FE tube + half-plane flat")
    ax.plot(x[sl] * 1e3, contact(c_fretsim_bending, gap0, setup90.cycle.load, dx)[sl], "C1--", label="fretsim (+ C_b)")
    ax.set_title("unworn (N = 0)", fontsize=9)
    for ax, name in zip(axes[1:], ("tube_RT", "tube_90C")):
        for (n, model), p in fields.items():
            if n == name:
                style = {"FE": ("k-", 1.6), "fr": ("C1--", 1.2), "ha": ("C0:", 1.2)}[model[:2]]
                ax.plot(x * 1e3, p, style[0], lw=style[1], label=model)
        nz = np.flatnonzero(fields[name, "FE tube + half-plane flat"] > 0)
        ax.set_xlim(x[max(0, nz[0] - 20)] * 1e3, x[min(x.size - 1, nz[-1] + 20)] * 1e3)
        ax.set_title(f"{name}, N = {results[name, 'FE tube + half-plane flat'][1].cycle} (each run's own wear)",
                     fontsize=9)
    for ax in axes:
        ax.set_xlabel("x (µm)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("contact pressure (MPa)")
    axes[0].legend(fontsize=7)
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(OUT / "verify_tube_fe.png", dpi=150)
    say(f"\nwritten: {OUT / 'verify_tube_fe.txt'}, {OUT / 'verify_tube_fe.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
