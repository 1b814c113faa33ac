"""The runs a run makes besides its own — auto's proxies, a wear limit's pilot, the grid-error companions — and
who hears of them.

They can take a minute, so whoever owns the run (the CLI, a sweep worker, a notebook) may pass a
:class:`SideRuns` that says what each is (``announce``) and shows its progress (``progress``: a context manager
for a setup that yields a progress callback, as :func:`fretsim.simulate.simulate` takes one).  It also keeps the
proxies and pilots already run, so that planning the same case again in its keeping (``check`` then ``run``, the
corrections' proxies asked for again once the dimension is chosen, a sweep's points that share a pilot) does not
run them twice.  A plan made without one prints nothing and keeps nothing.
"""
from __future__ import annotations

import contextlib
from dataclasses import dataclass, field
from typing import Any, Callable, Optional

from fretsim.simulate import simulate

CACHE_SIZE = 64  # proxies (or pilots) kept; beyond, the cache starts afresh
_MISSING = object()


@dataclass
class SideRuns:
    announce: Optional[Callable[[str], None]] = None
    progress: Optional[Callable[[Any], Any]] = None
    proxies: dict = field(default_factory=dict)  # repr(case dict) → the proxy run's summary
    # repr(case dict) → the cycle a pilot reached a limit at (inf: it reached none; None: it failed)
    pilots: dict = field(default_factory=dict)

    def say(self, what: str) -> None:
        if self.announce is not None:
            self.announce(what)

    def run(self, what: str, setup):
        """simulate(setup) for one of the runs a run makes besides its own, announced and with progress."""
        self.say(what)
        with self._progress(setup) as update:
            return simulate(setup, progress=update)

    def run_following(self, what: str, setup, case, rule, prepare_fn, widen: bool = False):
        """:meth:`run` carried through the grid's coarsenings and, ``widen``, its widenings
        (:func:`fretsim.regrid.following`): (last step, the setup it ended on, the coarsenings)."""
        from fretsim.regrid import following
        self.say(what)
        with self._progress(setup) as update:
            return following(lambda s, st, r, obs: simulate(s, obs, progress=update, resume=st, coarsen=r), setup,
                             case, rule, prepare_fn, widen)

    def _progress(self, setup):
        """The owner's progress for ``setup`` (a context manager yielding a callback), or none."""
        return self.progress(setup) if self.progress is not None else contextlib.nullcontext(None)

    def remembered(self, cache: dict, key: str, compute: Callable[[], Any]) -> Any:
        """``cache[key]``, computed once."""
        value = cache.get(key, _MISSING)  # one lookup: another thread may clear the cache between two
        if value is not _MISSING:
            return value
        value = compute()
        if len(cache) > CACHE_SIZE:
            cache.clear()
        cache[key] = value
        return value  # not cache[key]: a worker's other thread may have cleared the cache meanwhile
