"""The error types the command line maps to exit codes (no heavy imports: the CLI loads this at start-up).

* :class:`InputError` — input that cannot be used (a case, a sweep file, an option, an output name): exit 2.
  :class:`fretsim.case.CaseError` is one.
* :class:`ResultsFileError` — a results file or sweep table that is missing, damaged or not ours: exit 2.
  A ValueError, so callers that catch ValueError keep working.
"""
from __future__ import annotations


class InputError(Exception):
    """Input that cannot be used; the message names the file, the key and what was expected."""


class ResultsFileError(ValueError):
    """A results file (or a sweep's table) that cannot be read or verified; the message names what is wrong."""
