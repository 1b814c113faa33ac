"""Claiming an output: an exclusive flock on a lock file beside it for the life of a run, and a name checked
before anything is written (a directory, a case file, an unwritable place refused)."""
from __future__ import annotations

import errno
import fcntl
import hashlib
import os
import stat
from pathlib import Path
from typing import Optional

MAX_NAME = 200  # bytes of the output's base name we accept (temporaries use fixed-length names)


class OutputBusy(Exception):
    """Another live run holds the output."""


def _lock_path(path: Path) -> Path:
    digest = hashlib.sha1(path.name.encode()).hexdigest()[:16]
    return path.with_name(f".fretsim-{digest}.lock")


class OutputClaim:
    """An exclusive claim on an output name, held for the life of a run (flock on a lock file beside it)."""

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.lock = _lock_path(self.path)
        self.fd: Optional[int] = None

    def acquire(self) -> "OutputClaim":
        while True:
            fd = os.open(self.lock, os.O_CREAT | os.O_RDWR, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                    raise OutputBusy(f"{self.path}: another fretsim run is writing this file; wait for it, or "
                                     f"choose another -o") from None
                raise
            # the lock file may have been unlinked by its previous holder after we opened it: then retry
            try:
                if os.fstat(fd).st_ino == os.stat(self.lock).st_ino:
                    self.fd = fd
                    os.ftruncate(fd, 0)
                    os.write(fd, f"{os.getpid()}\n".encode())
                    _clean_stale_locks(self.lock)
                    return self
            except FileNotFoundError:
                pass
            os.close(fd)

    def release(self) -> None:
        if self.fd is None:
            return
        try:
            os.unlink(self.lock)
        except OSError:
            pass
        os.close(self.fd)
        self.fd = None

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()


def _clean_stale_locks(mine: Path) -> None:
    """Remove the lock files beside ``mine`` that nobody holds (left by a kill -9: the kernel drops the lock, the
    file stays).  One a live run holds cannot be locked here and stays; one a run is just claiming it re-checks
    (the inode test in acquire) and claims again."""
    try:
        names = [p for p in mine.parent.glob(".fretsim-*.lock") if p != mine]
    except OSError:
        return
    for p in names[:100]:
        try:
            fd = os.open(p, os.O_RDWR)
        except OSError:
            continue
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            os.unlink(p)
        except OSError:
            pass
        finally:
            os.close(fd)


def check_output_path(path: str | Path, protect: tuple = ()) -> Path:
    """An output name that can be a results file: not a directory, not one of ``protect`` (the case file), in an
    existing directory, of a sane length.  Raises ValueError with the reason."""
    text = str(path)
    p = Path(path)
    if text in ("", "-"):
        raise ValueError(f"{text!r} is not a file name; results go to an HDF5 file, e.g. -o out.h5")
    if text.endswith(os.sep) or p.is_dir():
        what = "is a directory" if p.is_dir() else "ends in a '/', so it names a directory"
        raise ValueError(f"{text} {what}; give a file name, e.g. -o {os.path.join(text, 'out.h5')}")
    if p.is_symlink():
        # the writer replaces the file by renaming over it, which would replace the link, not write through it
        target = os.readlink(p)
        raise ValueError(f"{text} is a symbolic link (to {target}{'' if p.exists() else ', which does not exist'}); "
                         f"give the file's own name, or a new name")
    if len(p.name.encode()) > MAX_NAME:
        raise ValueError(f"the output name is {len(p.name.encode())} bytes long; at most {MAX_NAME}")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise ValueError(f"the directory {parent} does not exist; create it first")
    for other in protect:
        if other is not None and Path(other).exists() and p.exists() and os.path.samefile(p, other):
            raise ValueError(f"{text} is the case file itself; choose another output name")
        if other is not None and os.path.abspath(p) == os.path.abspath(other):
            raise ValueError(f"{text} is the case file itself; choose another output name")
    if p.exists() and not stat.S_ISREG(os.stat(p).st_mode):
        raise ValueError(f"{text} exists and is not a regular file")
    return p


