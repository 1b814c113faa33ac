"""What the flat's free faces change on the McColl geometry, from an independent elastic solution (issue #8).

The paper (section 2.1, Fig. 2) treats the McColl flat, whose length L along the cylinder's axis equals the
cylinder's, as a finite space: its faces at y = ±L/2 are free, where a half-space would have material beyond.
This study measures what that changes from an independent elastic solution, without the paper's approximation
(overlapping half-spaces with the shear on the overlaps neglected): the flat's compliance is computed for a
prismatic block (infinite along x, the sliding direction; cross-section L wide and D = 10 mm deep, the depth
of the paper's own FEA; bottom fixed) by finite elements, one 2D problem per Fourier mode cos(kx) along x
(scikit-fem, quadratic quadrilaterals; an optional comparator, not a dependency).  The same block made three
times wider, loaded only where the contact is, is the control: the difference of the two is the free faces'
effect alone (the finite depth and the fixed bottom are common to both and cancel to first order), and it is
added to fretsim's half-space compliance as one more operator.  Then the 185 N case runs in 3D with and
without it, through fretsim's own loop.

Then the paper's approximation itself is solved the same way: planes at the faces that carry shear but no
normal stress (material beyond them kept), to show how much of the faces' effect the shear carries.  Last,
fretsim's own model (model.corrections: [free_faces], fretsim/compliance/free_faces.py: the same block by its
own bilinear elements) against all of the above.

Checks of the comparator itself: the block under p = cos(kx) over its whole width against the half-space's
exact 2(1 − ν²)/(E k) far from its faces, and the correction's convergence in the number of Fourier modes and
under mesh refinement.

    pip install scikit-fem
    python scripts/study_free_faces_fe.py      # table on stdout; scripts/out/free_faces_fe.{txt,png}
"""
from __future__ import annotations

import sys
import time

from _study import ROOT, Report, have_comparator  # first: it pins the BLAS threads before numpy loads

import numpy as np  # noqa: E402
import scipy.sparse.linalg as spla  # noqa: E402

OUT = ROOT / "scripts" / "out"
CASE = ROOT / "cases" / "mccoll_185N.yaml"
DEPTH = 10.0  # mm, the flat's depth in the paper's FEA (section 2.1)
WIDE = 3.0  # the control block is this many times the flat's length L wide


def _graded(h0: float, growth: float, cap: float, length: float) -> np.ndarray:
    steps, total, h = [], 0.0, h0
    while total + h < length:
        steps.append(h)
        total += h
        h = min(h * growth, cap)
    steps[-1] += length - total
    return np.array(steps)


class Block:
    """A prismatic elastic block, infinite along x: cross-section y_nodes × [−depth, 0], bottom fixed, sides free.

    A surface pressure q(y)·cos(kx) gives u = (U sin kx, V cos kx, W cos kx) with (U, V, W) functions of (y, z):
    one 2D problem per k, whose stiffness is K0 + k K1 + k² K2 (assembled once).
    """

    def __init__(self, y_nodes: np.ndarray, depth: float, h0: float, youngs: float, poisson: float,
                 growth: float = 1.3, release: tuple[float, float] | None = None, keep_shear: bool = True):
        from skfem import Basis, BilinearForm, ElementQuad2, ElementVector, MeshQuad, asm

        z = -np.concatenate([[0.0], np.cumsum(_graded(h0, growth, depth / 8, depth))])[::-1]
        self.mesh = MeshQuad.init_tensor(np.asarray(y_nodes, float), z)
        self.basis = b = Basis(self.mesh, ElementVector(ElementQuad2(), dim=3), intorder=4)
        lam = youngs * poisson / ((1 + poisson) * (1 - 2 * poisson))
        mu = youngs / (2 * (1 + poisson))

        def form_at(k):
            @BilinearForm
            def form(u, v, w):
                # components 0: U (along x, sin kx), 1: V (y), 2: W (z); grad[c][0] = ∂/∂y, grad[c][1] = ∂/∂z
                gu, gv = u.grad, v.grad
                su, sv = u.value, v.value
                e = (k * su[0], gu[1][0], gu[2][1], gu[1][1] + gu[2][0], gu[0][0] - k * su[1], gu[0][1] - k * su[2])
                f = (k * sv[0], gv[1][0], gv[2][1], gv[1][1] + gv[2][0], gv[0][0] - k * sv[1], gv[0][1] - k * sv[2])
                # strains: εxx, εyy, εzz, γyz (cos kx) and γxy, γxz (sin kx); a period averages both alike
                full = (lam * (e[0] + e[1] + e[2]) * (f[0] + f[1] + f[2])
                        + 2 * mu * (e[0] * f[0] + e[1] * f[1] + e[2] * f[2])
                        + mu * (e[3] * f[3] + e[4] * f[4] + e[5] * f[5]))
                if release is None:
                    return full
                # a layer across y (release[0] < |y| < release[1]) that carries the shears γyz, γxy across it
                # but no normal stress σyy: the paper's approximation (a stiffness 1e-6 of the rest keeps the
                # layer's other modes from being free)
                layer = (np.abs(w.x[0]) > release[0]) & (np.abs(w.x[0]) < release[1])
                shear = mu * (e[3] * f[3] + e[4] * f[4]) if keep_shear else 0.0
                return np.where(layer, shear + 1e-6 * full, full)
            return asm(form, b)

        k0, kp, km = form_at(0.0), form_at(1.0), form_at(-1.0)
        self.k0, self.k1, self.k2 = k0, 0.5 * (kp - km), 0.5 * (kp + km) - k0
        bottom = b.get_dofs(lambda p: p[1] < z[0] + 1e-9 * depth).all()
        self.free = np.setdiff1d(np.arange(b.N), bottom)
        p, f = self.mesh.p, self.mesh.facets
        top = np.flatnonzero(np.abs(p[1]) < 1e-12)
        self.top = top[np.argsort(p[0, top])]
        self.top_y = p[0, self.top]
        on_top = np.flatnonzero((np.abs(p[1, f[0]]) < 1e-12) & (np.abs(p[1, f[1]]) < 1e-12))
        self._facet = {tuple(sorted(f[:, i])): i for i in on_top}

    def loads(self, edges: np.ndarray) -> np.ndarray:
        """One column per row [edges[j], edges[j+1]]: a unit downward pressure on it (consistent nodal loads)."""
        b, y = self.basis, self.top_y
        out = np.zeros((b.N, edges.size - 1))
        for j in range(edges.size - 1):
            for a in np.flatnonzero((y[:-1] >= edges[j] - 1e-12) & (y[1:] <= edges[j + 1] + 1e-12)):
                h = y[a + 1] - y[a]
                out[b.nodal_dofs[2, [self.top[a], self.top[a + 1]]], j] -= h / 6
                out[b.facet_dofs[2, self._facet[tuple(sorted((self.top[a], self.top[a + 1])))]], j] -= 2 * h / 3
        return out

    def settlement(self, k: float, loads: np.ndarray, y_points: np.ndarray) -> np.ndarray:
        """Downward surface displacement amplitude at y_points (mesh vertices) per load column, under cos(kx)."""
        a = (self.k0 + k * self.k1 + k * k * self.k2)[self.free][:, self.free].tocsc()
        u = np.zeros((self.basis.N, loads.shape[1]))
        u[self.free] = spla.splu(a).solve(loads[self.free])
        nodes = self.top[[int(np.argmin(np.abs(self.top_y - yp))) for yp in y_points]]
        return -u[self.basis.nodal_dofs[2, nodes]]


def check_against_the_half_space(youngs: float, poisson: float) -> list[tuple[float, float]]:
    """A 4 mm wide block loaded by cos(kx) over its whole top: mid-width settlement against 2(1 − ν²)/(E k)."""
    out = []
    for k in (20.0, 100.0, 400.0):
        blk = Block(np.linspace(-2.0, 2.0, 81), 3.0, 0.1 / k, youngs, poisson)
        w = blk.settlement(k, blk.loads(np.array([-2.0, 2.0])), np.array([0.0]))[0, 0]
        out.append((k, w / (2 * (1 - poisson**2) / (youngs * k)) - 1))
    return out


def face_correction(rows: np.ndarray, dy: float, youngs: float, poisson: float, ks: np.ndarray, split: int,
                    h0: float, depth: float = DEPTH, released: bool = False, keep_shear: bool = True) -> np.ndarray:
    """ΔG[m, i, j]: settlement at row i's centre per unit cos(k_m x) pressure on row j, faces minus wide block.

    ``released``: instead of free faces, planes at the faces that carry shear but no normal stress (what the
    paper's overlapping half-spaces model, shear on the overlaps neglected), minus the same mesh without them;
    with ``keep_shear`` False the planes carry nothing, which must reproduce the free faces (a check)."""
    half = rows.size * dy / 2
    edges = -half + dy * np.arange(rows.size + 1)
    inner = np.linspace(-half, half, rows.size * split + 1)
    outside = half + np.cumsum(_graded(dy / split, 1.3, 1.0, (WIDE - 1) * half))
    wide = np.concatenate([-outside[::-1], inner, outside])
    blocks = {"faces": Block(inner, depth, h0, youngs, poisson), "wide": Block(wide, depth, h0, youngs, poisson)}
    if released:  # the wide block with a 20 µm layer just beyond each face that carries shear only
        t = 0.02
        nodes = np.sort(np.concatenate([wide, [-half - t, half + t]]))
        blocks = {"faces": Block(nodes, depth, h0, youngs, poisson, release=(half, half + t), keep_shear=keep_shear),
                  "wide": Block(nodes, depth, h0, youngs, poisson)}
    loads = {name: blk.loads(edges) for name, blk in blocks.items()}
    out = np.empty((ks.size, rows.size, rows.size))
    for m, k in enumerate(ks):
        g = {name: blk.settlement(k, loads[name], rows) for name, blk in blocks.items()}
        out[m] = g["faces"] - g["wide"]
    return out


def correction_matrix(delta: np.ndarray, ks: np.ndarray, x: np.ndarray, dx: float) -> np.ndarray:
    """The dense operator on the grid (row-major, rows along y), by the Fourier integral along x:
    ΔK_ab(s) = (1/π) ∫ ΔG_ab(k) B(k) cos(ks) dk, B(k) = 2 sin(k dx/2)/k the transform of one element's box.
    ΔG is interpolated between the sampled k (monotone cubic) and taken as 0 beyond the last (its decay there is
    below the FE's own resolution)."""
    from scipy.interpolate import PchipInterpolator

    k = np.linspace(0.0, ks[-1], 8001)
    weights = np.full(k.size, k[1] - k[0])
    weights[[0, -1]] *= 0.5
    box = np.where(k > 0, 2 * np.sin(k * dx / 2) / np.where(k > 0, k, 1.0), dx)
    dg = PchipInterpolator(ks, delta, axis=0)(k)  # (k, a, b)
    s = (np.arange(2 * x.size - 1) - (x.size - 1)) * dx
    kernel = np.einsum("kab,ks->abs", dg * (weights * box)[:, None, None], np.cos(np.outer(k, s))) / np.pi
    ny, nx = delta.shape[1], x.size
    lag = np.arange(nx)[:, None] - np.arange(nx)[None, :] + nx - 1  # (i, l) → index of x_i − x_l
    return kernel[:, :, lag].transpose(0, 2, 1, 3).reshape(ny * nx, ny * nx)


def run_mccoll(correction: np.ndarray | None, grid_shape: tuple[int, int]):
    """The 185 N case in 3D at its defaults; with ``correction`` the flat's compliance gains the free faces."""
    import fretsim.plan as plan
    from fretsim.case import load_case
    from fretsim.compliance import HalfSpace, add
    from fretsim.compliance.operator import Matrix
    from fretsim.simulate import simulate, summarize

    def half_space_with_faces(on, e_star):
        base = HalfSpace(on, e_star)
        return add(base, Matrix(on, correction)) if on.shape == grid_shape else base

    original = plan.HalfSpace
    if correction is not None:
        plan.HalfSpace = half_space_with_faces
    try:
        setup, _, _ = plan.prepare(load_case(CASE))
    finally:
        plan.HalfSpace = original
    steps = []

    class Keep:
        def on_step(self, s, step):
            steps.append(step)

    t = time.perf_counter()
    simulate(setup, (Keep(),))
    return setup, steps, summarize(setup, steps[-1], len(steps), time.perf_counter() - t)


SHORT = {"centre_wear_depth_stationary_um": "flat's centre-line depth", "max_wear_depth_stationary_um":
         "flat's maximum depth", "max_wear_depth_moving_um": "cylinder's maximum depth"}
REPORTED = ("centre_wear_depth_stationary_um", "max_wear_depth_stationary_um", "max_wear_depth_moving_um",
            "scar_width_stationary_mm", "wear_volume_stationary_mm3")


def main() -> int:
    if not have_comparator("skfem", "pip install scikit-fem"):
        return 1
    from fretsim.case import load_case
    from fretsim.plan import prepare

    OUT.mkdir(parents=True, exist_ok=True)
    say = Report()

    case = load_case(CASE)
    youngs, poisson = case.stationary.youngs_modulus, case.stationary.poissons_ratio
    setup, _, _ = prepare(case)
    grid = setup.grid
    ny, nx = grid.shape
    rows = grid.y
    say(f"McColl 185 N, 3D grid {nx} x {ny} of {grid.dx * 1e3:.2f} x {grid.dy * 1e3:.1f} µm; the flat "
        f"(E {youngs / 1e3:g} GPa, ν {poisson}) {ny * grid.dy:.3g} mm long with free faces at its ends, "
        f"{DEPTH:g} mm deep, bottom fixed")
    say()
    say("1. The comparator: a block under p = cos(kx) over its whole width, mid-width settlement against the "
        "half-space's 2(1 − ν²)/(E k)")
    for k, err in check_against_the_half_space(youngs, poisson):
        say(f"   k = {k:5.0f} /mm: relative difference {err:+.1e}")

    t = time.perf_counter()
    ks = np.concatenate([[0.0], np.geomspace(0.25, 48.0, 19)])
    delta = face_correction(rows, grid.dy, youngs, poisson, ks, split=4, h0=0.004)
    say(f"\n2. Free faces minus the wide block, {ks.size} wavenumbers 0…{ks[-1]:g} /mm ({time.perf_counter() - t:.0f} s)")
    self_end = delta[:, -1, -1]
    say("   end row's own settlement added by the faces, per unit pressure (mm/MPa), at k = "
        + ", ".join(f"{k:.3g}: {d:.2e}" for k, d in zip(ks[::4], self_end[::4])))
    say(f"   centre row: at most {np.abs(delta[:, ny // 2, :]).max():.1e} (the faces are 5 mm away)")
    ref = face_correction(rows, grid.dy, youngs, poisson, ks[[0, 4, 8, 12]], split=8, h0=0.002)
    change = np.abs(ref - delta[[0, 4, 8, 12]]).max() / np.abs(delta).max()
    say(f"   mesh refined (8 instead of 4 elements a row, surface layer halved): largest change {change:.1e} of "
        f"the largest entry")

    corr = correction_matrix(delta, ks, grid.x, grid.dx)
    corr_coarse = correction_matrix(delta[::2], ks[::2], grid.x, grid.dx)
    asym = np.abs(corr - corr.T).max() / np.abs(corr).max()
    say(f"   operator on the grid: {corr.shape[0]} x {corr.shape[1]}; asymmetry {asym:.1e} of its largest entry")

    say()
    say("3. The 185 N case at its defaults, with and without the flat's free faces (fretsim's own loop)")
    runs = {"half-space flat (no correction)": run_mccoll(None, grid.shape),
            "flat with free faces (FE)": run_mccoll(corr, grid.shape),
            "free faces, half the wavenumbers": run_mccoll(corr_coarse, grid.shape)}
    base = runs["half-space flat (no correction)"][2]
    head = "".join(f"{k.replace('_um', ' µm').replace('_mm3', ' mm³').replace('_mm', ' mm'):>36}" for k in REPORTED)
    say(f"{'':<34}{head}{'loop s':>8}")
    for label, (_, steps, summ) in runs.items():
        vals = "".join(f"{summ[k]:>26.4g} ({summ[k] / base[k] - 1:+6.2%})" for k in REPORTED)
        say(f"{label:<34}{vals}{summ['wall_time_s']:>8.2f}")

    def along_y(field):  # the centre column (x = 0) along the contact
        return field[:, nx // 2]

    say()
    say("   along the contact (x = 0): end row / centre row")
    for label, (_, steps, _) in runs.items():
        p0, p1 = along_y(steps[0].pressure), along_y(steps[-1].pressure)
        h = along_y(steps[-1].wear_stationary)
        say(f"   {label:<34} pressure N = 0: {p0[-1] / p0[ny // 2]:.3f}   final: {p1[-1] / p1[ny // 2]:.3f}   "
            f"flat's wear final: {h[-1] / h[ny // 2]:.3f}")

    say()
    say("4. The flat's depth (both blocks keep a fixed bottom; 10 wavenumbers): what the faces change")
    for depth in (5.0, 20.0):
        d = face_correction(rows, grid.dy, youngs, poisson, ks[::2], split=4, h0=0.004, depth=depth)
        _, steps, summ = run_mccoll(correction_matrix(d, ks[::2], grid.x, grid.dx), grid.shape)
        p0 = along_y(steps[0].pressure)
        say(f"   depth {depth:4.0f} mm: " + ", ".join(f"{SHORT[k]} {summ[k] / base[k] - 1:+.2%}" for k in SHORT)
            + f"; end/centre pressure at N = 0 {p0[-1] / p0[ny // 2]:.3f}")

    say()
    say("5. The paper's approximation solved by FE: instead of free faces, a 20 µm layer just beyond each face that")
    say("   carries shear but no normal stress (10 wavenumbers); compare scripts/prototype_paper_free_faces.py")
    for keep, label in ((True, "shear kept (the approximation)"), (False, "nothing kept (check: = free faces)")):
        d = face_correction(rows, grid.dy, youngs, poisson, ks[::2], split=4, h0=0.004, released=True,
                            keep_shear=keep)
        _, steps, summ = run_mccoll(correction_matrix(d, ks[::2], grid.x, grid.dx), grid.shape)
        p0 = along_y(steps[0].pressure)
        say(f"   {label:<36}" + ", ".join(f"{SHORT[k]} {summ[k] / base[k] - 1:+.2%}" for k in SHORT)
            + f"; end/centre pressure at N = 0 {p0[-1] / p0[ny // 2]:.3f}")

    say()
    from fretsim.compliance.free_faces import K_SAMPLES, SPLIT, face_settlement
    say(f"6. fretsim's own model of the faces (fretsim/compliance/free_faces.py: bilinear elements, {SPLIT} a row, "
        f"{len(K_SAMPLES)} wavenumbers,")
    say("   blocks 2B = 20 mm deep) against the FE above")
    for depth in (DEPTH, 20.0):
        ks6 = np.asarray(K_SAMPLES) / (ny * grid.dy)
        ref6 = face_correction(rows, grid.dy, youngs, poisson, ks6, split=4, h0=0.004, depth=depth)
        mine6 = face_settlement(rows, grid.dy, ny * grid.dy, youngs, poisson, ks6, depth=depth)
        say(f"   depth {depth:4.0f} mm: ΔG at fretsim's wavenumbers differs from the FE by at most "
            f"{np.abs(mine6 - ref6).max() / np.abs(ref6).max():.1%} of its largest entry")
    from fretsim.api import load_case as _load, run as _run

    def profiles(*overrides):
        """The run's summary, and along the contact (x = 0): pressure at N = 0 and at the end, final wear."""
        kept = []

        class Keep:
            def on_step(self, s, step):
                kept.append(step)

        res = _run(_load(CASE, list(overrides)), observers=(Keep(),))
        return res.summary, (along_y(kept[0].pressure), along_y(kept[-1].pressure),
                             along_y(kept[-1].wear_stationary))

    half, _ = profiles("model.corrections=none")
    ours = {}
    for label, extra in (("one body's faces (the cylinder's ends)", ()),
                         ("both bodies' faces (block_length 10 mm)", ("geometry.block_length=10 mm",))):
        summ, ours[label] = profiles(*extra, "model.corrections=[free_faces]")
        p0 = ours[label][0]
        say(f"   {label:<40}" + ", ".join(f"{SHORT[k]} {summ[k] / half[k] - 1:+.2%}" for k in SHORT)
            + f"; end/centre pressure at N = 0 {p0[-1] / p0[ny // 2]:.3f}")
    say("   (one body's faces of the same steel and length are the FE's correction: compare section 3)")
    say.write(OUT / "free_faces_fe.txt")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 3, figsize=(14, 3.8))
    styles = {"half-space flat (no correction)": ("C0", "-"), "flat with free faces (FE)": ("C3", "-"),
              "free faces, half the wavenumbers": ("k", ":")}
    for label, (_, steps, _) in runs.items():
        c, ls = styles[label]
        axes[0].plot(rows, along_y(steps[0].pressure), color=c, ls=ls, label=label)
        axes[1].plot(rows, along_y(steps[-1].pressure), color=c, ls=ls, label=label)
        axes[2].plot(rows, along_y(steps[-1].wear_stationary) * 1e3, color=c, ls=ls, label=label)
    p0, p1, h = ours["one body's faces (the cylinder's ends)"]
    for ax, f in zip(axes, (p0, p1, h * 1e3)):
        ax.plot(rows, f, color="C2", ls="--", marker=".", ms=3, label="fretsim, model.corrections: [free_faces]")
    axes[0].set_title("pressure along the contact, N = 0", fontsize=9)
    axes[1].set_title(f"pressure along the contact, N = {runs['flat with free faces (FE)'][1][-1].cycle}", fontsize=9)
    axes[2].set_title("flat's wear depth along the contact, final", fontsize=9)
    for ax, lab in zip(axes, ("contact pressure (MPa)", "contact pressure (MPa)", "wear depth (µm)")):
        ax.set_xlabel("y, along the cylinder (mm)")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(OUT / "free_faces_fe.png", dpi=150)
    say(f"\nwritten: {OUT / 'free_faces_fe.txt'}, {OUT / 'free_faces_fe.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
