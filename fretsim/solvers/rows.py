"""Many normal contacts on one grid at once: the resolved stroke's positions, solved together.

A resolved fretting cycle solves the same contact at a score of positions along the stroke.  On a small grid each
solve is a few hundred elements, where numpy's cost per call, not the arithmetic, is the time; stacked as the
layers of one array (the FFT transforms a stack's layers in one call), all the positions cost about what two or
three solves did.  :func:`solve_rows` is :func:`fretsim.solvers.cg.solve_cg` layer by layer: the same
Polonsky–Keer iteration, preconditioner, stopping rule and result; each layer stops when it converges.  On the
union of the warm starts' windows, then verified on the whole grid as :func:`fretsim.solvers.solve` does; a
layer whose contact outgrew the window, or that did not converge, is left to be solved alone by the caller's
own solve (which has the fallbacks).
"""
from __future__ import annotations

import numpy as np

from fretsim.solvers import WINDOW_MARGIN, PENETRATION as WINDOW_PENETRATION
from fretsim.solvers.cg import PENETRATION, RECOMPUTE_EVERY, _admit, _preconditioner
from fretsim.solvers.result import ContactResult

A = (1, 2)  # a stack's layer axes (My, Mx): each layer's sums, maxima and tests
STACK_ELEMENTS = 32_000  # elements of the windows solved in one stack: beyond, the arrays leave the cache and a 3D
#                          stack of McColl's 19 positions (27 × 200) was 8 % slower than in chunks of 4-6 (a 2D one,
#                          19 × 255, stays whole)


def solve_rows(op, gaps: np.ndarray, load: float, p0: np.ndarray, tol: float) -> list:
    """The contacts of the layers of ``gaps`` (m, My, Mx) on the grid of ``op`` (a convolution), warm-started from
    ``p0`` (m, My, Mx), each carrying ``load``: a ContactResult per layer, or None where the layer must be solved
    alone (it did not converge on the window, or its contact outgrew it, or its gap is one the single solve refuses:
    NaN, −inf, or infinite everywhere it may touch)."""
    m, ny, nx = gaps.shape
    on = p0 > 0
    if not on.any():
        return [None] * m
    rows, cols = _span(on.any(axis=(0, 2)), ny), _span(on.any(axis=(0, 1)), nx)
    usable = ~(np.isnan(gaps) | np.isneginf(gaps)).any(axis=(1, 2)) & np.isfinite(gaps[:, rows, cols]).any(axis=(1, 2))
    if not usable.all():  # a NaN or −inf gap, or none finite on the window: the single solve says what is wrong
        rest = iter(solve_rows(op, gaps[usable], load, p0[usable], tol) if usable.any() else ())
        return [next(rest) if u else None for u in usable]
    size = (rows.stop - rows.start) * (cols.stop - cols.start)
    if m > 1 and m * size > STACK_ELEMENTS:  # in chunks that stay in the cache (and whose windows are narrower)
        k = max(1, STACK_ELEMENTS // size)
        return [r for i in range(0, m, k) for r in solve_rows(op, gaps[i:i + k], load, p0[i:i + k], tol)]
    whole = rows.stop - rows.start == ny and cols.stop - cols.start == nx
    win = op if whole else op.window(rows, cols)
    found = cg_rows(win, gaps[:, rows, cols], load, p0[:, rows, cols], tol)
    p = np.zeros(gaps.shape)
    p[:, rows, cols] = found[0]
    u = op(p)  # the whole grid: nothing outside the window may penetrate
    approach, ok, its, err = found[1:]
    finite = np.isfinite(gaps)
    y = np.where(finite, u + gaps - approach[:, None, None], np.inf)
    on = p > 0
    scale = np.maximum(np.where(on, np.abs(u), 0.0).max(axis=(1, 2)), 1e-300)
    inside = np.zeros((ny, nx), bool)
    inside[rows, cols] = True
    ok = ok & ~(~inside & (y < -WINDOW_PENETRATION * scale[:, None, None])).any(axis=(1, 2))
    # complementarity_residual, layer by layer: max(|Y| in contact, −Y outside) over the spread of u
    worst = np.maximum(np.where(on, np.abs(y), 0.0).max(axis=(1, 2)),
                       np.where(~on & finite, np.clip(-y, 0.0, None), 0.0).max(axis=(1, 2)))
    spread = u.max(axis=(1, 2)) - u.min(axis=(1, 2))
    residual = worst / np.where(spread > 0, spread, 1.0)
    note = f"solved with {m - 1} other positions"
    return [ContactResult(p[k], float(approach[k]), on[k], int(its[k]), True,
                          f"cg converged in {its[k]} iterations (relative pressure change {err[k]:.1e} < {tol:.0e}, "
                          f"gap complementary; {note})", float(residual[k])) if ok[k] else None
            for k in range(m)]


MIRROR_SHARE = 0.01  # of the solver's tolerance: a gap this much off its mirror image (on the scale of one element's
#                      own compliance at the peak pressure) is the same contact mirrored.  The solver stops at a 1e-5
#                      relative pressure change, so two layers solved apart differ by about that much, and the wear
#                      they deposit is that much asymmetric: noise the mirror must not refuse, far below what moves a
#                      pressure by what the solver itself leaves


def even_along_x(kernel) -> bool:
    """Whether an influence kernel is its own mirror image along x, to round-off (1e-12 of its largest value: the
    3D half-space's rectangles are even to ~7e-15, not bit for bit)."""
    if kernel is None:
        return False
    return bool(np.abs(kernel - kernel[:, ::-1]).max() <= 1e-12 * np.abs(kernel).max())


def mirror_tolerance(op, tol: float, peak: float) -> float:
    """The largest difference of a gap from its mirror image (mm) under which its contact is taken as the mirrored
    contact: MIRROR_SHARE of the solver's relative tolerance, at the peak pressure, over the stiffness of one
    element against its neighbour (K₀ − K₁ along x, the kernel's additive constant aside); 0 where the operator
    is not itself symmetric along x (an even kernel: every half-space's; checked, not assumed)."""
    kernel = getattr(op, "kernel", None)
    if kernel is None or kernel.shape[1] < 3 or not even_along_x(kernel):
        return 0.0
    cy, cx = kernel.shape[0] // 2, kernel.shape[1] // 2
    return max(MIRROR_SHARE * tol * peak * float(kernel[cy, cx] - kernel[cy, cx + 1]), 0.0)


def mirrored_layers(op, gaps: np.ndarray, pairs, tol: float, peak: float) -> dict:
    """{j: i} for the pairs (i, j) whose gaps are mirror images along x to :func:`mirror_tolerance`.  The contact
    of a mirrored gap is the mirrored contact (the problem, the load and the solver's rule are all symmetric), so
    it is taken, not solved again: a symmetric fretting cycle's down-stroke is its up-stroke mirrored."""
    within = mirror_tolerance(op, tol, peak)
    copies = {}
    for i, j in pairs if within > 0 else ():
        a, b = gaps[i], gaps[j][:, ::-1]
        finite = np.isfinite(a)
        if i in copies or j in copies or not np.array_equal(finite, np.isfinite(b)) or not finite.any():
            continue
        if np.abs(a[finite] - b[finite]).max() <= within:
            copies[j] = i
    return copies


def solve_mirrored_rows(op, gaps: np.ndarray, load: float, p0: np.ndarray, tol: float, mirrors, alone) -> list:
    """:func:`solve_rows` with ``mirrors``, pairs (i, j) of layers that may be mirror images along x (a symmetric
    cycle's up- and down-stroke at the same |U|): where the gaps are (:func:`mirrored_layers`), layer j is layer
    i's contact mirrored, not solved.  ``alone(k)`` solves layer k by itself (the single solve, with its fallbacks)
    where the stack could not; a mirrored layer is then that solve mirrored, so the pair stays one contact."""
    m = gaps.shape[0]
    copies = mirrored_layers(op, gaps, mirrors, tol, float(p0.max())) if len(mirrors) else {}
    keep = [k for k in range(m) if k not in copies]
    found = dict(zip(keep, solve_rows(op, gaps[keep], load, p0[keep], tol)))
    found = {k: res if res is not None else alone(k) for k, res in found.items()}
    for j, i in copies.items():
        found[j] = mirror_result(found[i])
    return [found[k] for k in range(m)]


def mirror_symmetric(op, gap: np.ndarray, x: np.ndarray) -> bool:
    """Whether a contact problem is itself symmetric along x, to round-off: a centred grid, an even kernel and an
    unworn gap that is its own mirror image (1e-12 of its largest finite value)."""
    kernel = getattr(op, "kernel", None)
    if not even_along_x(kernel) or not np.array_equal(x, -x[::-1]):
        return False
    finite = np.isfinite(gap)
    if not np.array_equal(finite, finite[:, ::-1]) or not finite.any():
        return False
    return bool(np.abs(gap[finite] - gap[:, ::-1][finite]).max() <= 1e-12 * np.abs(gap[finite]).max())


def mirror_result(res):
    """A ContactResult mirrored along x."""
    return ContactResult(res.pressure[:, ::-1].copy(), res.approach, res.contact[:, ::-1].copy(), 0, res.success,
                         res.message + "; the mirror image of its pair's", res.residual)


# the coupled solve's margin round its warm starts (elements, share of their extent): they are the last step's
# positions grown by a few elements (fretsim.cycle.resolved.grown_start), the contact widening 1-7 elements a step;
# a quarter (the single solve's, whose warm start may be a prediction far off) made McColl 185 N 3D's window half
# as wide again as its contact and its coupled solves 1.25x as long.  A contact that outgrows it is solved again
# over the whole grid (solve_coupled), so the margin buys time, not answers.
COUPLED_MARGIN = (6, 0.1)


def _span(mask: np.ndarray, n: int, margins: tuple = WINDOW_MARGIN) -> slice:
    """The warm starts' extent along one axis and a margin round it (the single solve's, solvers.WINDOW_MARGIN)."""
    idx = np.flatnonzero(mask)
    margin = max(margins[0], int(margins[1] * (idx[-1] - idx[0] + 1)))
    return slice(max(0, idx[0] - margin), min(n, idx[-1] + margin + 1))


def cg_rows(op, gaps: np.ndarray, load: float, p0: np.ndarray, tol: float):
    """Preconditioned constrained CG on every layer of the stack (m, My, Mx): (pressures, approaches, converged,
    iterations, last relative changes).  Each row follows :func:`fretsim.solvers.cg.solve_cg`'s iteration; a converged row is
    set aside and the others go on."""
    m, n = gaps.shape[0], gaps[0].size
    total = load / op.grid.area
    allowed = np.isfinite(gaps)
    h = np.where(allowed, gaps, 0.0)
    max_iter = max(1000, 5 * int(np.sqrt(n)) + 200)
    precond = _preconditioner(op)
    p = np.where(allowed, np.clip(p0, 0.0, None), 0.0)
    empty = ~(p > 0).any(axis=A)
    if empty.any():  # (a warm start without contact on the window: start near the closest points, as solve_cg)
        for k in np.flatnonzero(empty):
            hk = h[k][allowed[k]]
            p[k] = allowed[k] & (h[k] <= hk.min() + 0.5 * (np.percentile(hk, 10) - hk.min()) + 1e-300)
    p *= (total / p.sum(axis=A))[:, None, None]
    pressures, approach = np.zeros(gaps.shape), np.zeros(m)
    ok, iterations, errors = np.zeros(m, bool), np.zeros(m, int), np.full(m, np.inf)
    live = np.arange(m)
    h_all, hl, al = h, h, allowed  # the live rows' gaps and masks
    u = op(p)
    t = np.zeros_like(p)
    gz_old, delta, err = np.ones(m), np.zeros(m), np.full(m, np.inf)
    for it in range(1, max_iter + 1):
        mask = p > 0
        w = mask.astype(float)
        count = w.sum(axis=A)
        g = u + hl
        g -= ((g * w).sum(axis=A) / count)[:, None, None]
        z = precond(g * w) * w
        z -= w * (z.sum(axis=A) / count)[:, None, None]
        gz = (g * z).sum(axis=A)
        beta = np.where(delta > 0, delta * gz / np.where(gz_old != 0.0, gz_old, 1.0), 0.0)  # (0 after a still row)
        t = (z + beta[:, None, None] * t) * w
        gz_old = gz
        r_raw = op(t)
        denom = (r_raw * t).sum(axis=A) - (r_raw * w).sum(axis=A) / count * t.sum(axis=A)
        penetrating = ~mask & al & (g < 0.0)
        pen = penetrating.any(axis=A)
        still = (denom <= 0.0) | (gz == 0.0)
        done = still & ~pen  # nothing left to do on the set, and nothing outside it penetrates
        err = np.where(done, 0.0, err)
        p_old = p
        tau = np.where(still, 0.0, (g * t).sum(axis=A) / np.where(still, 1.0, denom))
        p, clipped, scale, _ = _steps(p_old, tau, t, g, penetrating, total)
        for k in np.flatnonzero(still & pen):  # put pressure on the penetrating elements (rare)
            p[k] = _admit(p_old[k], g[k], penetrating[k], total)
        delta = np.where(pen, 0.0, 1.0)
        recompute = clipped | pen | still | (it % RECOMPUTE_EVERY == 0)
        u = scale[:, None, None] * (u - tau[:, None, None] * r_raw)
        if recompute.any():
            u[recompute] = op(p[recompute])
        change = np.abs(p - p_old).sum(axis=A) / total
        bad = ~still & ~np.isfinite(change)  # (a row that took no step keeps its last change, inf before its first)
        err = np.where(still, err, change)
        fin = done | bad | ((err < tol) & ~pen & _complementary_rows(u, hl, p, al) & ~still)  # (as solve_cg)
        if fin.any() or it == max_iter:
            if it == max_iter:
                fin = np.ones(live.size, bool)
            rows = live[fin]
            pressures[rows] = np.where(bad[fin, None, None], p_old[fin], p[fin])
            ok[rows] = ~bad[fin] & (err[fin] < tol) & (done[fin] | _complementary_rows(u[fin], hl[fin], p[fin],
                                                                                        al[fin]))
            iterations[rows], errors[rows] = it, err[fin]
            keep = ~fin
            live, p, u, t, gz_old, delta, err = live[keep], p[keep], u[keep], t[keep], gz_old[keep], delta[keep], err[keep]
            hl, al = hl[keep], al[keep]
            if not live.size:
                break
    u_all = op(pressures)
    on = pressures > 0
    approach = np.where(on.any(axis=A), ((u_all + h_all) * on).sum(axis=A) / np.maximum(on.sum(axis=A), 1), 0.0)
    return pressures, approach, ok, iterations, errors


def _steps(p_old, tau, t, g, penetrating, total):
    """Each row's step p − τt clipped to p ≥ 0, penetrating elements added, rescaled to the load (cg._step, row
    by row: a step that lifted a row off entirely is halved for that row): (pressures, which rows clipped, their
    rescaling, the steps τ taken)."""
    tau = tau.copy()
    for _ in range(60):
        trial = p_old - tau[:, None, None] * t
        clipped = (trial < 0.0).any(axis=A)
        p = np.clip(trial, 0.0, None)
        p = np.where(penetrating, p - tau[:, None, None] * g, p)
        sums = p.sum(axis=A)
        lifted = sums <= 0.0
        if not lifted.any():
            break
        tau = np.where(lifted, 0.5 * tau, tau)
    scale = total / p.sum(axis=A)
    return p * scale[:, None, None], clipped, scale, tau


def _complementary_rows(u, h, p, allowed) -> np.ndarray:
    """cg._complementary, row by row: nothing outside the contact set penetrates beyond PENETRATION."""
    on = p > 0
    g = u + h
    alpha = (g * on).sum(axis=A) / np.maximum(on.sum(axis=A), 1)
    outside = ~on & allowed
    scale = np.maximum(np.where(on, np.abs(u), 0.0).max(axis=A), 1e-300)
    worst = np.where(outside, g - alpha[:, None, None], np.inf).min(axis=A)
    return worst >= -PENETRATION * scale


def solve_coupled(op, gaps: np.ndarray, load: float, p0: np.ndarray, tol: float, couple) -> list:
    """The contacts of the layers of ``gaps`` (m, My, Mx) solved as one problem, each layer carrying ``load``, where
    each layer's gap also grows by ``couple(p)`` — a linear map of the whole stack (a resolved implicit step's
    wear, which every position deposits and every position reads) such that Ω(C + couple) is symmetric and
    positive on each layer's load-keeping changes, Ω the layers' weights ``couple.layer_weights`` (1 without).  The
    stack minimises Σ_k ω_k(½p_kᵀC p_k + p_kᵀg_k) + ½pᵀΩ(couple p) over p ≥ 0 with each layer's Σp·A = W: one
    convex problem, so Polonsky–Keer's iteration carries over with one step length for the stack and each layer's
    load kept by its own mean gap (its approach).  On the window of the warm starts, verified on the whole grid as
    :func:`solve_rows` verifies; ``couple`` acts on whole-grid stacks.  A ContactResult per layer, or None if the
    stack did not converge (the caller then solves it another way); a stack whose contact outgrew the warm starts'
    window is solved again over the whole grid."""
    m, ny, nx = gaps.shape
    on = p0 > 0
    if not on.any(axis=A).all() or (np.isnan(gaps) | np.isneginf(gaps)).any():
        return None
    if getattr(couple, "mirrored", False):  # (a symmetric cycle's half: its preconditioner mirrors in the window)
        on = on | on[..., ::-1]
    found, outgrew = _coupled_window(op, gaps, load, p0, tol, couple, on)
    if outgrew:  # (a load block's first step, from a contact a few elements wide): once more over the whole grid
        found, _ = _coupled_window(op, gaps, load, p0, tol, couple, np.ones(on.shape, bool))
    return found


def _coupled_window(op, gaps, load, p0, tol, couple, on) -> tuple:
    """solve_coupled on the window of ``on`` (and its margin): (a ContactResult per layer or None, whether the
    contact outgrew a window smaller than the grid)."""
    m, ny, nx = gaps.shape
    rows, cols = _span(on.any(axis=(0, 2)), ny, COUPLED_MARGIN), _span(on.any(axis=(0, 1)), nx, COUPLED_MARGIN)
    whole = rows.stop - rows.start == ny and cols.stop - cols.start == nx
    win = op if whole else op.window(rows, cols)

    # (the coupling's own, cut to the window, where it has one: no whole-grid stacks an iteration)
    couple_win = couple.window(rows, cols, gaps.shape) if hasattr(couple, "window") else None
    if couple_win is None:
        def couple_win(p):
            full = np.zeros(gaps.shape)
            full[:, rows, cols] = p
            return couple(full)[:, rows, cols]

    precond = couple.preconditioner(win, rows, cols) if hasattr(couple, "preconditioner") else _preconditioner(win)
    found = cg_coupled(win, gaps[:, rows, cols], load, p0[:, rows, cols], tol, couple_win, precond,
                       getattr(couple, "layer_weights", None))
    if found is None:
        return None, False
    p = np.zeros(gaps.shape)
    p[:, rows, cols] = found[0]
    its, err = found[1], found[2]
    u = op(p) + couple(p)  # the whole grid: nothing outside the window may penetrate
    finite = np.isfinite(gaps)
    on = p > 0
    approach = ((u + np.where(finite, gaps, 0.0)) * on).sum(axis=A) / np.maximum(on.sum(axis=A), 1)
    y = np.where(finite, u + gaps - approach[:, None, None], np.inf)
    scale = np.maximum(np.where(on, np.abs(u), 0.0).max(axis=A), 1e-300)
    inside = np.zeros((ny, nx), bool)
    inside[rows, cols] = True
    if (~inside & (y < -WINDOW_PENETRATION * scale[:, None, None])).any():
        return None, not whole
    worst = np.maximum(np.where(on, np.abs(y), 0.0).max(axis=A),
                       np.where(~on & finite, np.clip(-y, 0.0, None), 0.0).max(axis=A))
    spread = u.max(axis=A) - u.min(axis=A)
    residual = worst / np.where(spread > 0, spread, 1.0)
    return [ContactResult(p[k], float(approach[k]), on[k], its, True,
                          f"cg converged in {its} iterations (relative pressure change {err:.1e} < {tol:.0e}, gap "
                          f"complementary; coupled with {m - 1} other positions by the step's wear)",
                          float(residual[k])) for k in range(m)], False


def _level(uc, h, g, w, mask, p, allowed) -> bool:
    """cg_coupled's exit where its step found no descent: converged only if the gap ``g`` (displacement ``uc``) is
    level over every layer's contact and complementary outside it (without this the solver said "converged" with
    a residual of 0.67 of the gap's spread)."""
    scale = np.maximum(np.where(mask, np.abs(uc), 0.0).max(axis=A), 1e-300)
    return bool((np.abs(g * w).max(axis=A) <= PENETRATION * scale).all() and _complementary_rows(uc, h, p, allowed).all())


def cg_coupled(op, gaps: np.ndarray, load: float, p0: np.ndarray, tol: float, couple, precond, layer_weights=None):
    """Preconditioned constrained CG on the coupled stack (:func:`solve_coupled`): (pressures, iterations, last
    relative change), or None where it did not converge.  :func:`cg_rows`'s iteration with the inner products,
    the step and the conjugacy taken over the whole stack; ``precond`` approximates the coupled operator's
    inverse.  ``layer_weights`` ω_k: the operator is symmetric in the inner product Σ_k ω_k⟨·,·⟩_k (a coupling
    K = s·GΩ with G symmetric: Ω(C + K) is), which the iteration then uses."""
    n = gaps[0].size
    total = load / op.grid.area
    allowed = np.isfinite(gaps)
    h = np.where(allowed, gaps, 0.0)
    max_iter = max(1000, 5 * int(np.sqrt(n)) + 200)
    p = np.where(allowed, np.clip(p0, 0.0, None), 0.0)
    if not (p.sum(axis=A) > 0).all():
        return None
    p *= (total / p.sum(axis=A))[:, None, None]
    u, c = op(p), couple(p)
    # the search directions' images in single precision (a 3D window's double transforms cost 4-6 times): the
    # displacement they update drifts by about 1e-7 of itself an iteration, so it is recomputed in double every
    # RECOMPUTE_EVERY iterations and before convergence is judged (PENETRATION is 1e-6)
    fast = op.single() if hasattr(op, "single") else op
    t = np.zeros_like(p)
    lw = (np.ones(p.shape[0]) if layer_weights is None else np.asarray(layer_weights, float))[:, None, None]
    gz_old, delta = 1.0, 0.0
    for it in range(1, max_iter + 1):
        mask = p > 0
        w = mask.astype(float)
        count = w.sum(axis=A)
        g = u + c + h
        g -= ((g * w).sum(axis=A) / count)[:, None, None]
        z = precond(g * w) * w
        z -= w * (z.sum(axis=A) / count)[:, None, None]
        gz = float((lw * g * z).sum())
        beta = delta * gz / gz_old if delta > 0 and gz_old != 0.0 else 0.0
        t = (z + beta * t) * w
        gz_old = gz
        r_op, r_c = fast(t), couple(t)
        r = r_op + r_c
        denom = float((lw * r * t).sum() - (lw[:, 0, 0] * (r * w).sum(axis=A) / count * t.sum(axis=A)).sum())
        penetrating = ~mask & allowed & (g < 0.0)
        pen = penetrating.any(axis=A)
        p_old = p
        if denom <= 0.0 or gz == 0.0:
            if not pen.any():  # converged only where the gap is also level (a coupling whose symmetric part is
                #                 not positive: denom <= 0 is negative curvature, not the minimum; see _level)
                if fast is not op:  # (judged on the displacement in double)
                    u, c = op(p), couple(p)
                    g = u + c + h - (((u + c + h) * w).sum(axis=A) / count)[:, None, None]
                return (p, it, 0.0) if _level(u + c, h, g, w, mask, p, allowed) else None
            p = p.copy()
            for k in np.flatnonzero(pen):
                p[k] = _admit(p_old[k], g[k], penetrating[k], total)
            u, c, delta = op(p), couple(p), 0.0
            continue
        tau = float((lw * g * t).sum()) / denom
        p, clipped, scale, taus = _steps(p_old, np.full(p.shape[0], tau), t, g, penetrating, total)
        delta = 0.0 if pen.any() else 1.0  # (a restart where elements enter: without, 1.7 times the iterations)
        if it % RECOMPUTE_EVERY == 0:
            u, c = op(p), couple(p)
        elif clipped.any() or pen.any() or np.abs(scale - 1.0).max() > 1e-12:
            # the coupling mixes the layers' rescalings: again; C acts layer by layer, so its displacement is the
            # step's, rescaled, plus what clipping and admitting changed at a few edge elements, by their columns
            # where that is cheaper (most steps at a growing contact's edges: a 3D step's transform a time)
            step = taus[:, None, None]
            trial = p_old - step * t
            few = op.of_few(np.clip(-trial, 0.0, None) + np.where(penetrating, -step * g, 0.0)) if hasattr(
                op, "of_few") else None
            u = op(p) if few is None else scale[:, None, None] * (u - step * r_op + few)
            c = couple(p)
        else:  # (the step kept every layer's load)
            u = u - tau * r_op
            c = c - tau * r_c
        change = float((np.abs(p - p_old).sum(axis=A) / total).max())
        if not np.isfinite(change):
            return None
        if change < tol and not pen.any():
            if fast is not op:  # (judged on the displacement in double)
                u, c = op(p), couple(p)
            if _complementary_rows(u + c, h, p, allowed).all():  # (as solve_cg)
                return p, it, change
    return None
