"""An independent model of the resolved stroke, written apart from fretsim's code (issue 30: an independent look
at the resolved stroke before auto's choice is trusted).  Compare it with fretsim run with model.slip=uniform,
model.stroke=resolved on the same grid: scripts/results/resolved_independent.txt has the commands and the table.

    python scripts/verify_resolved_independent.py --ninc 37 --cycles 1000 [--hertz] [--freeze --seen avg]

Independent 2D plane-strain fretting-wear model: rigid uniform slip, stroke resolved.

Cylinder (moving, radius R) on flat (stationary), both elastic half-spaces for the normal contact,
rigid tangentially.  Units: mm, N, MPa.

Contact solver: dense influence matrix of uniform pressure on elements (plane strain, log kernel,
exact integral over the element, collocation at element centres), solved by a primal active-set
method on the bordered system [K_CC  -1; dx*1^T 0] [p; approach] = [-f_C; W] (W load per unit length),
dropping negative pressures and adding penetrating elements until the complementarity holds exactly.

Wear: U goes -delta -> +delta -> -delta in n increments per half-stroke, |dU| = 2 delta / n.
The pressure of an increment is solved at its midpoint position (pos="mid") or at its end (pos="end").
Moving body: dh_m(xi) = k_m p(xi) |dU|.
Flat: the deposit k_s * int_{U_a}^{U_b} p(x-U) dU, averaged exactly over each flat element
(p piecewise constant => double integral of p is piecewise quadratic, evaluated exactly).
The flat's wear seen by the moving element xi at position U is the exact average of the piecewise-constant
h_s over [xi_l+U, xi_r+U].
"""
import numpy as np, sys, time, json

R = 6.0; Lz = 10.0; P = 185.0; W = P / Lz
E = 200e3; nu = 0.3
Estar = 1.0 / (2 * (1 - nu**2) / E)          # Johnson's E* for two identical bodies = E/(2(1-nu^2))
delta = 25e-3; k_m = 2.0e-8; k_s = 3.0e-8


def influence(xc, dx):
    b = dx / 2
    y = xc[:, None] - xc[None, :]
    F = lambda t: t * np.log(np.abs(t)) - t
    # u(x) = -(2/(pi E*)) * int_{-b}^{b} ln|y - s| ds * p ; add a constant (2/(pi E*))*2b*(ln(L0)) for conditioning
    K = -(2 / (np.pi * Estar)) * (F(y + b) - F(y - b))
    K += (2 / (np.pi * Estar)) * dx * np.log(10.0)      # arbitrary datum (irrelevant at fixed load)
    return K


class Contact:
    def __init__(self, K, dx):
        self.K = K; self.dx = dx; self.active = None

    def solve(self, f, W):
        n = len(f); dx = self.dx; K = self.K
        if self.active is None:
            act = np.zeros(n, bool); act[np.argsort(f)[: max(3, n // 20)]] = True
        else:
            act = self.active.copy()
        for it in range(500):
            idx = np.nonzero(act)[0]; m = len(idx)
            A = np.zeros((m + 1, m + 1))
            A[:m, :m] = K[np.ix_(idx, idx)]; A[:m, m] = -1.0; A[m, :m] = dx
            rhs = np.concatenate([-f[idx], [W]])
            sol = np.linalg.solve(A, rhs)
            pc, alpha = sol[:m], sol[m]
            if (pc < 0).any():
                # drop the negative ones (all of them; if that would empty the set, keep the best)
                neg = pc < 0
                act[idx[neg]] = False
                continue
            p = np.zeros(n); p[idx] = pc
            g = f + K @ p - alpha
            pen = (~act) & (g < -1e-12 * max(1.0, np.abs(f).max()))
            if not pen.any():
                self.active = act; self.iters = it + 1
                return p, alpha, g
            # add the penetrating ones
            act |= pen
        raise RuntimeError("active set did not converge")


def cum_edges(v, dx):
    """P1 at edges (integral of piecewise constant v), P2 at edges (integral of P1)."""
    P1 = np.concatenate([[0.0], np.cumsum(v) * dx])
    P2 = np.concatenate([[0.0], np.cumsum(0.5 * (P1[:-1] + P1[1:]) * dx)])
    return P1, P2


def eval_P2(y, edges, v, P1, P2, dx):
    n = len(v)
    k = np.floor((y - edges[0]) / dx).astype(int)
    out = np.empty_like(y)
    left = k < 0; right = k >= n; mid = ~(left | right)
    out[left] = 0.0
    out[right] = P2[-1] + P1[-1] * (y[right] - edges[-1])
    km = k[mid]; t = y[mid] - edges[km]
    out[mid] = P2[km] + P1[km] * t + 0.5 * v[km] * t * t
    return out


def eval_P1(y, edges, v, P1, dx):
    n = len(v)
    k = np.floor((y - edges[0]) / dx).astype(int)
    out = np.empty_like(y)
    left = k < 0; right = k >= n; mid = ~(left | right)
    out[left] = 0.0; out[right] = P1[-1]
    km = k[mid]; t = y[mid] - edges[km]
    out[mid] = P1[km] + v[km] * t
    return out


def hertz_check(nx, dom):
    dx = dom / nx
    edges = -dom / 2 + dx * np.arange(nx + 1); xc = 0.5 * (edges[:-1] + edges[1:])
    K = influence(xc, dx); c = Contact(K, dx)
    p, alpha, g = c.solve(xc**2 / (2 * R), W)
    a_h = np.sqrt(4 * P * R / (np.pi * Estar * Lz)); p0_h = 2 * P / (np.pi * a_h * Lz)
    # contact half-width: count of loaded elements, and a fit through p^2 = p0^2 (1 - x^2/a^2)
    nc = (p > 0).sum(); a_count = nc * dx / 2
    sel = p > 0.3 * p.max()
    A = np.vstack([np.ones(sel.sum()), -xc[sel] ** 2]).T
    c0, c1 = np.linalg.lstsq(A, p[sel] ** 2, rcond=None)[0]
    a_fit = np.sqrt(c0 / c1); p0_fit = np.sqrt(c0)
    return dict(a_hertz_um=a_h * 1e3, p0_hertz=p0_h, a_count_um=a_count * 1e3, a_fit_um=a_fit * 1e3,
                p_max=p.max(), p0_fit=p0_fit, err_a_count=a_count / a_h - 1, err_a_fit=a_fit / a_h - 1,
                err_p0_max=p.max() / p0_h - 1, err_p0_fit=p0_fit / p0_h - 1,
                load_err=p.sum() * dx / W - 1, n_contact=int(nc), dx_um=dx * 1e3,
                max_abs_p_err_over_p0=np.abs(p - np.where(np.abs(xc) < a_h, p0_h * np.sqrt(np.clip(1 - (xc / a_h) ** 2, 0, None)), 0)).max() / p0_h)


def scar_width(h, xc, dx, frac=1e-3):
    thr = frac * h.max(); idx = np.nonzero(h > thr)[0]
    w_cells = (idx[-1] - idx[0] + 1) * dx
    # interpolated crossings between element centres
    def cross(i, j):
        return xc[i] + (thr - h[i]) / (h[j] - h[i]) * (xc[j] - xc[i])
    i0, i1 = idx[0], idx[-1]
    xl = cross(i0 - 1, i0) if i0 > 0 else xc[0]
    xr = cross(i1, i1 + 1) if i1 < len(h) - 1 else xc[-1]
    return w_cells, xr - xl


def simulate(nx=427, dom=0.7018, ninc=9, cycles=1000, pos="mid", snap=(100, 1000), verbose=True, freeze=False, seen="point"):
    """freeze: the geometry (both bodies' wear) held at its start-of-cycle state for all the cycle's contact solves,
    the cycle's wear applied at its end (default: applied after every increment)."""
    dx = dom / nx
    edges = -dom / 2 + dx * np.arange(nx + 1); xc = 0.5 * (edges[:-1] + edges[1:])
    K = influence(xc, dx); c = Contact(K, dx)
    hm = np.zeros(nx); hs = np.zeros(nx)
    dU = 2 * delta / ninc
    # one cycle: list of (U_a, U_b)
    segs = []
    for i in range(ninc):
        segs.append((-delta + i * dU, -delta + (i + 1) * dU))
    for i in range(ninc):
        segs.append((delta - i * dU, delta - (i + 1) * dU))
    out = {}; t0 = time.time(); its = 0
    for N in range(1, cycles + 1):
        hm0, hs0 = hm.copy(), hs.copy()
        for Ua, Ub in segs:
            Uc = 0.5 * (Ua + Ub) if pos == "mid" else Ub
            # flat's wear seen by moving element xi: exact average of hs over [xi_l+U, xi_r+U]
            hsg, hmg = (hs0, hm0) if freeze else (hs, hm)
            H1 = np.concatenate([[0.0], np.cumsum(hsg) * dx])
            if seen == "point":   # flat seen at the increment's solve position Uc
                hs_seen = (eval_P1(edges[1:] + Uc, edges, hsg, H1, dx) - eval_P1(edges[:-1] + Uc, edges, hsg, H1, dx)) / dx
            else:                 # flat seen averaged over the increment's travel (adjoint of the spread deposit)
                H2 = np.concatenate([[0.0], np.cumsum(0.5 * (H1[:-1] + H1[1:]) * dx)])
                Q = lambda y: eval_P2(y, edges, hsg, H1, H2, dx)
                lo_, hi_ = min(Ua, Ub), max(Ua, Ub)
                hs_seen = (Q(edges[1:] + hi_) - Q(edges[1:] + lo_) - Q(edges[:-1] + hi_) + Q(edges[:-1] + lo_)) / (dx * (hi_ - lo_))
            f = xc**2 / (2 * R) + hmg + hs_seen
            p, alpha, g = c.solve(f, W); its += c.iters
            hm += k_m * p * abs(Ub - Ua)
            lo, hi = min(Ua, Ub), max(Ua, Ub)
            P1, P2 = cum_edges(p, dx)
            G = lambda y: eval_P2(y, edges, p, P1, P2, dx)
            dep = (G(edges[1:] - lo) - G(edges[:-1] - lo) - G(edges[1:] - hi) + G(edges[:-1] - hi)) / dx
            hs += k_s * dep
        if N in snap:
            out[N] = dict(hs=hs.copy(), hm=hm.copy())
            if verbose:
                print(f"cycle {N}: hs max {hs.max()*1e3:.5f} um, hm max {hm.max()*1e3:.5f} um, "
                      f"{time.time()-t0:.1f}s, mean AS iters {its/(N*len(segs)):.2f}", flush=True)
    return xc, dx, out


def summarise(xc, dx, hs, hm, N):
    ic = np.argmin(np.abs(xc))
    wc, wi = scar_width(hs, xc, dx)
    Vs = hs.sum() * dx * Lz; Vm = hm.sum() * dx * Lz
    return dict(centre_um=hs[ic] * 1e3, max_s_um=hs.max() * 1e3, max_m_um=hm.max() * 1e3,
                Vs_mm3=Vs, Vm_mm3=Vm, Vs_rel_err=Vs / (k_s * P * 4 * delta * N) - 1,
                Vm_rel_err=Vm / (k_m * P * 4 * delta * N) - 1, width_cells_mm=wc, width_interp_mm=wi)


if __name__ == "__main__":
    import argparse
    ap = argparse.ArgumentParser()
    ap.add_argument("--nx", type=int, default=427); ap.add_argument("--dom", type=float, default=0.7018)
    ap.add_argument("--ninc", type=int, default=9); ap.add_argument("--cycles", type=int, default=1000)
    ap.add_argument("--pos", default="mid"); ap.add_argument("--hertz", action="store_true")
    ap.add_argument("--save", default=None); ap.add_argument("--freeze", action="store_true"); ap.add_argument("--seen", default="point")
    a = ap.parse_args()
    if a.hertz:
        print(json.dumps(hertz_check(a.nx, a.dom), indent=1)); sys.exit()
    snaps = tuple(s for s in (100, a.cycles) if s <= a.cycles)
    xc, dx, out = simulate(a.nx, a.dom, a.ninc, a.cycles, a.pos, snaps, freeze=a.freeze, seen=a.seen)
    res = {}
    for N, d in out.items():
        res[N] = summarise(xc, dx, d["hs"], d["hm"], N)
        print(N, json.dumps(res[N], indent=1))
    if a.save:
        np.savez(a.save, x=xc, **{f"hs_{N}": d["hs"] for N, d in out.items()}, **{f"hm_{N}": d["hm"] for N, d in out.items()})
