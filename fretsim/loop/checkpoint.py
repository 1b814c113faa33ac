"""The loop's checkpoint: its whole state as a flat dict of arrays and numbers.

Every emitted step carries one (``Step.state``); the results writer stores the last in ``/checkpoint`` and
``fretsim run --resume`` restores it, so a resumed run produces the same steps as the uninterrupted one, bit for
bit.  The keys are part of the results file's layout (format 1.2 on), so they are only ever added to.
"""
from __future__ import annotations

import time

import numpy as np

from fretsim.loop import fatigue
from fretsim.stability import GrowthWatch

# the loop's own attributes, written as they are
STATE = ("n", "h_m", "h_s", "p", "r_m", "r_s", "rate_work", "work", "jump", "rejected", "elapsed", "lag", "err_abs_m",
         "err_abs_s", "p_prev", "d_prev", "block", "block_start", "work_bound", "rate_energy", "energy",
         "energy_known")


def state(loop) -> dict:
    """The loop's state after its current step."""
    st = {k: getattr(loop, k) for k in STATE}
    st["retakes"] = loop.landing.retakes
    st["elapsed"] = loop.elapsed + time.perf_counter() - loop.t0
    st["batch"] = [a for b in loop.batch for a in b[:2]]  # flat list of arrays: m0, s0, m1, s1, ...
    st["batch_work"] = np.array([b[2] for b in loop.batch], dtype=float)
    st["batch_energy"] = np.array([b[3] for b in loop.batch], dtype=float)
    st["history_n"] = np.array([h[0] for h in loop.history], dtype=np.int64)
    st["history"] = [a for h in loop.history for a in h[1:4]]  # φ_m, φ_s, p per point
    st["history_work"] = np.array([h[4] for h in loop.history], dtype=float)
    st["history_energy"] = np.array([h[5] for h in loop.history], dtype=float)
    st["watch"] = np.array(loop.watch.history, dtype=float)
    st["scheme"] = loop.s.scheme
    if loop.s.wear_limits:
        st["limit_stops"] = np.array(sorted(set(loop.stops) - set(loop.base_stops)), dtype=np.int64)
        st["track_n"] = np.array([t[0] for t in loop.landing.track], dtype=float)
        for key in loop.s.wear_limits:
            st["track_" + key] = np.array([t[1][key] for t in loop.landing.track], dtype=float)
    if loop.reached is not None:  # the run ended at a wear limit: a resume must not step past it
        st["limit_key"], st["limit_cycle"], st["limit_spread"], st["limit_exponent"] = loop.reached
    for k, v in loop.memory.items():
        st["memory_" + k] = v
    st.update(fatigue.to_state(loop))
    return st


def restore(loop, st: dict) -> None:
    """Set the loop to a checkpoint (of a run of the same setup)."""
    if st.get("scheme") != loop.s.scheme:
        raise ValueError(f"the checkpoint is of scheme {st.get('scheme')!r}, the case of {loop.s.scheme!r}")
    for k in STATE:
        if k in st:
            setattr(loop, k, st[k])
    loop.n, loop.rejected, loop.d_prev = int(loop.n), int(loop.rejected), int(loop.d_prev)
    loop.jump, loop.elapsed, loop.lag = float(loop.jump), float(loop.elapsed), float(loop.lag)
    loop.err_abs_m, loop.err_abs_s = float(loop.err_abs_m), float(loop.err_abs_s)
    loop.work, loop.rate_work = float(loop.work), float(loop.rate_work)
    loop.energy, loop.rate_energy = float(loop.energy), float(loop.rate_energy)
    loop.energy_known = int(loop.energy_known)
    loop.memory = {k[len("memory_"):]: v for k, v in st.items() if k.startswith("memory_")}
    loop.block, loop.block_start = int(loop.block), int(loop.block_start)
    loop.work_bound = float(loop.work_bound)
    if loop.s.block_cycles:
        loop.model = loop.s.block_cycles[loop.block]
    loop.landing.retakes = int(st.get("retakes", loop.landing.retakes))
    loop.reached = ((str(st["limit_key"]), float(st["limit_cycle"]), float(st["limit_spread"]),
                     float(st["limit_exponent"])) if "limit_key" in st else None)
    loop.last_state = st  # a checkpoint is the state of the step written last: a retake goes back to it
    _restore_limits(loop, st)
    _restore_memory(loop, st)
    fatigue.restore(loop, st)
    loop.watch = GrowthWatch(np.atleast_1d(st.get("watch", [])))
    loop.cyc = None  # rebuilt only if needed (a run resumed at its end)
    if "r_m" not in st:  # a checkpoint of format 1.2, which only had uniform slip: the rates follow from p
        cyc = loop.restored_cycle()
        loop.r_m, loop.r_s, loop.rate_work = cyc.rate_moving, cyc.rate_stationary, cyc.work
    loop.t0 = time.perf_counter()


def _restore_limits(loop, st: dict) -> None:
    """The landing's stops and the wear limits' recent values."""
    limits = loop.s.wear_limits
    if limits and "limit_stops" in st:
        loop.stops = sorted(set(loop.base_stops) | {int(v) for v in np.atleast_1d(st["limit_stops"])})
    if limits and "track_n" in st:
        ns = list(np.atleast_1d(st["track_n"]))
        loop.landing.track = [(float(n), {key: float(np.atleast_1d(st["track_" + key])[i]) for key in limits})
                              for i, n in enumerate(ns)]


def _restore_memory(loop, st: dict) -> None:
    """The stepping schemes' memory: the adaptive batch and the implicit schemes' history."""
    flat = list(st.get("batch", []))
    works = list(np.atleast_1d(st.get("batch_work", np.zeros(len(flat) // 2))))
    energies = list(np.atleast_1d(st.get("batch_energy", np.zeros(len(flat) // 2))))
    loop.batch = [(flat[i], flat[i + 1], float(works[i // 2]), float(energies[i // 2])) for i in range(0, len(flat), 2)]
    ns = [int(v) for v in np.atleast_1d(st.get("history_n", []))]
    arrays = list(st.get("history", []))
    hw = list(np.atleast_1d(st.get("history_work", np.zeros(len(ns)))))
    he = list(np.atleast_1d(st.get("history_energy", np.zeros(len(ns)))))
    loop.history = [(ns[i], arrays[3 * i], arrays[3 * i + 1], arrays[3 * i + 2], float(hw[i]), float(he[i]))
                    for i in range(len(ns))]
