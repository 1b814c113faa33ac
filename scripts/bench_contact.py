"""Race the contact solvers (and, where installed, the peers tamaas and ContactMechanics) on identical problems.

Problems: Hertz ball on flat (R = 6 mm, P = 185 N, E = 200 GPa, ν = 0.3) on N × N grids spanning ±1.5 a,
and the finite cylinder (R = 6 mm, L = 10 mm, P = 185 N) at 40 × 27, 80 × 54, 160 × 108 spanning ±3.5 a.
Columns: cold time, warm time after a small wear-like gap change, iterations, error of the peak pressure
against Hertz (ball) or against the finest cylinder grid (cylinder), and the largest pressure difference to
fretsim's cg on the same grid (same discrete problem → small).  One thread everywhere.

In the loop (issue #9): the cost of a contact solve inside a default run (185 N, 18 000 cycles, and Kirk,
10⁶ cycles, both 3D), where each solve starts from the previous pressure and solves only a window around the
contact: time and CG iterations per solve, beside a cold solve of the first step's problem on the same grid.

    python scripts/bench_contact.py [--quick] [--out scripts/out]

``--few`` instead: the cost model of Convolution.of_few (a solver step's few clipped or admitted elements applied
by their kernel columns, not a transform) against its measurements — a 9-layer stack on 27 × 395, 27 × 120 and
1 × 300 windows, the transform's time and the columns' at 1, 10, 50 and 300 elements, and which the model picks.

``--single`` instead: the normal solver's single-precision phase (solvers/cg.py, SINGLE_UNTIL and
SINGLE_PRECONDITIONER) against double throughout, in this process, alternately, medians of 5: single solves on
3D grids, then whole runs (McColl 185 N 3D under the defaults and on the paper's grid without estimates, Kirk
450 N 3D, the partial-slip ball, McColl 185 N 3D in Coulomb slip), with the largest relative difference of the
summary's depths, widths and estimates.  Writes scripts/results/bench_contact_single.txt.
"""
import os

for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "TBB_NUM_THREADS"):
    os.environ.setdefault(var, "1")

import argparse  # noqa: E402
import csv  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from fretsim.compliance import HalfSpace as Compliance  # noqa: E402
from fretsim.grid import Grid  # noqa: E402
from fretsim.reference import effective_modulus, hertz_line, hertz_point  # noqa: E402
from fretsim.solvers import solve  # noqa: E402

E_STAR = effective_modulus(2e5, 0.3, 2e5, 0.3)
TOL = 1e-8
WEAR_STEP = 1e-4


def peak(p):
    return p.max()


def centre_line_peak(p):
    """Pressure peak along y = 0 (the two middle rows when My is even): away from the end peaks."""
    ny = p.shape[0]
    return p[(ny - 1) // 2:ny // 2 + 1].max()


def best_time(fn, repeats):
    best, out = np.inf, None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def run_tamaas(grid, gap, load):
    """tamaas is periodic: embed the problem in a 2N × 2N cell so the images are one domain apart."""
    import tamaas as tm
    ny, nx = grid.shape
    model = tm.ModelFactory.createModel(tm.model_type.basic_2d, [2 * nx * grid.dx, 2 * ny * grid.dy], [2 * nx, 2 * ny])
    model.E, model.nu = E_STAR, 0.0  # tamaas's "Hertz modulus" E/(1-ν²) is our E*
    big = np.full((2 * nx, 2 * ny), gap.max() * 4 + 1.0)
    big[nx // 2:nx // 2 + nx, ny // 2:ny // 2 + ny] = gap.T
    surface = np.ascontiguousarray(-big)
    solver = tm.PolonskyKeerRey(model, surface, TOL, tm.PolonskyKeerRey.pressure, tm.PolonskyKeerRey.pressure)
    solver.max_iter = 10000
    mean_pressure = load / (4 * nx * ny * grid.area)
    tm.set_log_level(tm.LogLevel.error)
    solver.solve(mean_pressure)
    p = np.array(model.traction, copy=True).reshape(2 * nx, 2 * ny)[nx // 2:nx // 2 + nx, ny // 2:ny // 2 + ny].T
    return p, -1


def run_contactmechanics(grid, gap, load):
    """ContactMechanics' FreeFFTElasticHalfSpace: the same Love kernel (Johnson p. 54), non-periodic."""
    from ContactMechanics import FreeFFTElasticHalfSpace
    from ContactMechanics.Optimization import constrained_conjugate_gradients
    from SurfaceTopography import Topography
    ny, nx = grid.shape
    size = (nx * grid.dx, ny * grid.dy)
    substrate = FreeFFTElasticHalfSpace((nx, ny), E_STAR, size, fft="serial")
    topo = Topography(np.ascontiguousarray(-gap.T), size)
    res = constrained_conjugate_gradients(substrate, topo, external_force=load, pentol=TOL * gap.max(),
                                          forcetol=TOL, maxiter=10000)
    return np.asarray(res.jac).T / grid.area, int(res.nit)


PEERS = {"tamaas": run_tamaas, "ContactMechanics": run_contactmechanics}


def peers_available():
    found = {}
    for name, mod in (("tamaas", "tamaas"), ("ContactMechanics", "ContactMechanics")):
        try:
            __import__(mod)
            found[name] = PEERS[name]
        except Exception as exc:  # an optional comparator: absent or broken is reported, not fatal
            print(f"# {name} not available ({type(exc).__name__}: {exc})")
    return found


def race(label, grid, gap, load, reference, metric, msm_limit, peers, repeats, rows):
    op = Compliance(grid, E_STAR)
    cg_cold_t, cg = best_time(lambda: solve(op, gap, load, method="cg", tol=TOL), repeats)
    # a wear-like change: Archard wear is proportional to pressure; 1e-4 of the approach, about one wear step
    wear = WEAR_STEP * cg.approach * cg.pressure / cg.pressure.max()
    entries = [("cg", cg_cold_t, cg.pressure, cg.iterations)]
    warm_t, warm = best_time(lambda: solve(op, gap + wear, load, method="cg", tol=TOL, p0=cg.pressure), repeats)
    cold_w_t, cold_w = best_time(lambda: solve(op, gap + wear, load, method="cg", tol=TOL), repeats)
    for m in ("active_set", "msm"):
        if grid.size <= msm_limit:
            t, r = best_time(lambda: solve(op, gap, load, method=m, tol=TOL), 1)
            entries.append((m, t, r.pressure if r.success else None, r.iterations))
    for name, fn in peers.items():
        try:
            t, (p, it) = best_time(lambda: fn(grid, gap, load), repeats)
            entries.append((name, t, p, it))
        except Exception as exc:
            print(f"# {name} failed on {label}: {type(exc).__name__}: {exc}")
    for name, t, p, it in entries:
        err = abs(metric(p) / reference - 1) if p is not None else float("nan")
        diff = float(np.abs(p - cg.pressure).max() / cg.pressure.max()) if p is not None else float("nan")
        row = dict(problem=label, grid=f"{grid.shape[1]}x{grid.shape[0]}", solver=name, cold_s=t,
                   warm_s=warm_t if name == "cg" else float("nan"),
                   warm_speedup=cold_w_t / warm_t if name == "cg" else float("nan"),
                   iterations=it, warm_iterations=warm.iterations if name == "cg" else -1,
                   peak_error=err, diff_to_cg=diff)
        rows.append(row)
        print(f"{label:9s} {row['grid']:>9s} {name:17s} {t:9.4f} {row['warm_s']:9.4f} {row['warm_speedup']:6.1f}x "
              f"{it:6d} {row['warm_iterations']:6d} {err:10.2e} {diff:10.2e}", flush=True)


def few() -> None:
    """Convolution.of_few's choice against the measured times (ms): the columns where they are the cheaper."""
    import timeit
    from fretsim.compliance.halfspace import HalfSpace
    from fretsim.heap import keep_warm
    keep_warm()
    rng = np.random.default_rng(0)
    print(f"{'window':>9s} {'transform':>10s} {'elements':>9s} {'columns':>9s} {'model picks':>12s}  right?")
    for ny, nx in ((27, 395), (27, 120), (1, 300)):
        op = HalfSpace(Grid.centred(nx, ny, 0.0016, 1.0 if ny == 1 else 0.05, plane_strain=ny == 1), 1e5)
        full = rng.random((9, ny, nx))
        op(full)
        t_fft = timeit.timeit(lambda: op(full), number=30) / 30
        for nnz in (1, 10, 50, 300):
            q = np.zeros(full.shape)
            q.reshape(-1)[rng.choice(q.size, nnz, replace=False)] = 1.0
            t = timeit.timeit(lambda: op.of_few(q, budget=1e9), number=30) / 30
            picks = op.of_few(q) is not None
            print(f"{ny:>3d} × {nx:<3d} {t_fft * 1e3:>10.3f} {nnz:>9d} {t * 1e3:>9.3f} "
                  f"{'columns' if picks else 'transform':>12s}  {'yes' if picks == (t < t_fft) else 'no'}")


def single() -> None:
    import fretsim.solvers.cg as cg
    from fretsim.api import load_case, run
    modes = {"double": (0.0, False), "single": (cg.SINGLE_UNTIL, cg.SINGLE_PRECONDITIONER)}  # (0: no single phase)
    lines = []

    def say(text=""):
        print(text, flush=True)
        lines.append(text)

    def paired(fn, reps=5):
        times, outs = {m: [] for m in modes}, {}
        for _ in range(reps):
            for m, (until, pre) in modes.items():
                cg.SINGLE_UNTIL, cg.SINGLE_PRECONDITIONER = until, pre
                t = time.perf_counter()
                outs[m] = fn()
                times[m].append(time.perf_counter() - t)
        cg.SINGLE_UNTIL, cg.SINGLE_PRECONDITIONER = modes["single"]
        return {m: float(np.median(v)) for m, v in times.items()}, outs

    say("single-precision phase of the normal CG against double throughout (medians of 5, alternately)")
    say(f"{'problem':34s} {'double s':>9s} {'single s':>9s} {'ratio':>6s} {'iter d/s':>9s} {'max diff':>9s}")
    ball = hertz_point(185.0, 6.0, E_STAR)
    line = hertz_line(18.5, 6.0, E_STAR)
    for name, grid, gap in [
            *[(f"ball {n} × {n}", g, (g.mesh()[0] ** 2 + g.mesh()[1] ** 2) / 12.0) for n in (64, 128, 256)
              for g in [Grid.centred(n, n, 3 * ball.radius / n, 3 * ball.radius / n)]],
            *[(f"finite cylinder {nx} × {ny}", g, g.mesh()[0] ** 2 / 12.0) for nx, ny in ((117, 27), (427, 27))
              for g in [Grid.centred(nx, ny, 7 * line.half_width / nx * 3, 10.0 / ny)]]]:
        op = Compliance(grid, E_STAR)
        t, outs = paired(lambda: solve(op, gap, 185.0))
        diff = np.abs(outs["single"].pressure - outs["double"].pressure).max() / outs["double"].pressure.max()
        say(f"{name:34s} {t['double']:9.4f} {t['single']:9.4f} {t['single'] / t['double']:6.3f} "
            f"{outs['double'].iterations:4d}/{outs['single'].iterations:<4d} {diff:9.1e}")
    say()
    say(f"{'whole run (in process)':34s} {'double s':>9s} {'single s':>9s} {'ratio':>6s} {'solves':>9s} {'max diff':>9s}")
    root = Path(__file__).resolve().parent.parent / "cases"
    for name, file, sets in [("McColl 185 N 3D, defaults", "mccoll_185N.yaml", []),
                             ("McColl 185 N 3D, paper grid, no est.", "mccoll_185N.yaml",
                              ["grid.rule=paper", "grid.error_estimate=none"]),
                             ("Kirk 450 N 3D, defaults", "kirk_450N_20Hz.yaml", []),
                             ("ball in partial slip, defaults", "ball_partial_slip.yaml", []),
                             ("McColl 185 N 3D, Coulomb", "mccoll_185N.yaml", ["loading.friction_coefficient=0.9"])]:
        case = load_case(root / file, sets)
        t, outs = paired(lambda: run(case))
        s0, s1 = outs["double"].summary, outs["single"].summary
        keys = [k for k, v in s0.items() if k.startswith(("centre_wear_depth", "max_wear_depth", "scar_width",
                                                           "wear_volume", "estimated_error"))
                and isinstance(v, float) and v == v and v != 0]
        diff = max(abs(s1[k] - s0[k]) / abs(s0[k]) for k in keys)
        say(f"{name:34s} {t['double']:9.3f} {t['single']:9.3f} {t['single'] / t['double']:6.3f} "
            f"{s0['contact_solves']:4d}/{s1['contact_solves']:<4d} {diff:9.1e}")
    out = Path(__file__).resolve().parent / "results" / "bench_contact_single.txt"
    out.write_text("Command: python scripts/bench_contact.py --single\n\n" + "\n".join(lines) + "\n")
    print(f"# wrote {out}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="small grids only (a smoke run)")
    ap.add_argument("--few", action="store_true", help="Convolution.of_few's cost model against its times")
    ap.add_argument("--single", action="store_true", help="the CG's single-precision phase against double")
    ap.add_argument("--out", default=str(Path(__file__).resolve().parent / "out"))
    args = ap.parse_args()
    if args.few:
        return few()
    if args.single:
        return single()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    peers = peers_available()
    rows = []
    print(f"{'problem':9s} {'grid':>9s} {'solver':17s} {'cold s':>9s} {'warm s':>9s} {'warm×':>7s} "
          f"{'iter':>6s} {'w.iter':>6s} {'peak err':>10s} {'Δp vs cg':>10s}")
    ball = hertz_point(185.0, 6.0, E_STAR)
    sizes = (32, 64) if args.quick else (32, 64, 128, 256, 512)
    for n in sizes:
        grid = Grid.centred(n, n, 3 * ball.radius / n, 3 * ball.radius / n)
        X, Y = grid.mesh()
        race("ball", grid, (X**2 + Y**2) / 12.0, 185.0, ball.peak_pressure, peak, 48 * 48, peers,
             3 if n <= 128 else 1, rows)
    line = hertz_line(18.5, 6.0, E_STAR)
    cyl_grids = ((40, 27), (80, 54)) if args.quick else ((40, 27), (80, 54), (160, 108))
    finest = cyl_grids[-1]
    g = Grid.centred(finest[0], finest[1], 7 * line.half_width / finest[0], 10.0 / finest[1])
    ref = solve(Compliance(g, E_STAR), g.mesh()[0] ** 2 / 12.0, 185.0, tol=1e-12).pressure
    ref_centre = centre_line_peak(ref)
    for nx, ny in cyl_grids:
        grid = Grid.centred(nx, ny, 7 * line.half_width / nx, 10.0 / ny)
        race("cylinder", grid, grid.mesh()[0] ** 2 / 12.0, 185.0, ref_centre, centre_line_peak, 40 * 27, peers, 3,
             rows)
    with open(out / "bench_contact.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    chart(rows, out / "bench_contact.png")
    loop_rows = [in_loop(case) for case in (("mccoll_185N",) if args.quick else ("mccoll_185N", "kirk_450N_20Hz"))]
    with open(out / "bench_contact_in_loop.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(loop_rows[0]))
        w.writeheader()
        w.writerows(loop_rows)
    print(f"# wrote {out / 'bench_contact.csv'}, {out / 'bench_contact_in_loop.csv'} and {out / 'bench_contact.png'}")


def in_loop(name: str) -> dict:
    """Time every contact solve of a default 3D run (the loop's own calls) against a cold solve."""
    import fretsim.simulate as sim
    from fretsim.case import load_case
    from fretsim.plan import prepare
    setup, _, _ = prepare(load_case(Path(__file__).resolve().parent.parent / "cases" / f"{name}.yaml"))
    calls = []
    real = sim.solve

    def timed(op, gap, load, **kw):
        t = time.perf_counter()
        res = real(op, gap, load, **kw)
        calls.append((time.perf_counter() - t, res.iterations, op, gap, load, kw))
        return res

    sim.solve = timed
    try:
        t = time.perf_counter()
        sim.simulate(setup, ())
        loop = time.perf_counter() - t
    finally:
        sim.solve = real
    _, _, op, gap, load, kw = calls[1]  # the first wear step's problem, solved from nothing
    cold_t, cold = best_time(lambda: real(op, gap, load, method=kw.get("method", "cg"), tol=kw.get("tol", TOL)), 3)
    per = sum(c[0] for c in calls) / len(calls)
    row = {"case": name, "grid": f"{setup.grid.shape[1]}x{setup.grid.shape[0]}", "loop_s": round(loop, 3), "solves": len(calls),
           "solve_share": round(sum(c[0] for c in calls) / loop, 3), "in_loop_ms": round(1e3 * per, 2),
           "in_loop_iterations": round(sum(c[1] for c in calls) / len(calls), 1), "cold_ms": round(1e3 * cold_t, 2),
           "cold_iterations": cold.iterations}
    print(f"in the loop, {name} 3D ({row['grid']}): {row['solves']} solves in {loop:.2f} s ({row['solve_share']:.0%} "
          f"of the loop); {row['in_loop_ms']:.2f} ms and {row['in_loop_iterations']} CG iterations a solve, "
          f"against {row['cold_ms']:.2f} ms and {cold.iterations} iterations cold")
    return row


def chart(rows, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
    for ax, problem in zip(axes, ("ball", "cylinder")):
        for solver in sorted({r["solver"] for r in rows}):
            pts = [(r["cold_s"], r["peak_error"], r["grid"]) for r in rows
                   if r["problem"] == problem and r["solver"] == solver and np.isfinite(r["peak_error"])]
            if pts:
                ax.loglog([p[0] for p in pts], [max(p[1], 1e-7) for p in pts], "o-", label=solver)
                for t, e, gname in pts:
                    ax.annotate(gname, (t, max(e, 1e-7)), fontsize=6)
        ax.set_xlabel("wall time of one cold solve (s)")
        ax.set_ylabel("relative error of peak pressure (–)")
        ax.set_title("Hertz ball on flat" if problem == "ball" else "finite cylinder (vs finest grid)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)


if __name__ == "__main__":
    main()
