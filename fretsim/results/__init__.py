"""The HDF5 results file: layout, crash-safe exclusive writer, and a reader that verifies what it reads.

    /                  attrs format_version, fretsim_version, status, status_message, case_name, notes,
                       input_sha256 (the case as asked for, before the plan filled it: Case.fingerprint)
    /case              the validated case with defaults and automatic choices filled (YAML text; attr sha256)
    /inputs            the resolved inputs as scalar datasets with units; attrs overrides (the --set items), case_file
    /choices           every automatic choice: key, value, reason, given, error (the model difference auto
                       accepted with it, a share; since 1.4 files of fretsim after issue 31: absent → 0)
    /grid/x, /grid/y   element centres (mm)
    /history/<name>    one entry per accepted step over the dimension ``step``, ``cycle`` its coordinate
    /fields/<name>     at the snapshot cycles: (cycle, y, x), with ``cycle``, ``y``, ``x`` as dimension scales
    /summary           attrs: the run's headline figures (same names as `fretsim summary`), and the same values
                       as scalar datasets each with its ``units``
    /fretting_loop     at the snapshot cycles: the applied displacement and the tangential force round the loop,
                       (cycle, point); no points for the uniform-slip model, which has no loop
    /checkpoint        the loop's state at the last written step, for `fretsim run --resume` (attr sha256)

Format 1.3 seals the rest too: every dataset carries ``sha256`` of its values, every group (and the root)
``attrs_sha256`` of its attributes and member names; readers refuse a file that differs, naming where.
The whole file is sealed too: its first 512 bytes are an HDF5 user block holding the sha256 of the rest, checked
before libhdf5 reads a byte (it loops for ever on some damaged files); files without one are read as before.

The layout is a contract (README): names are only ever added.  Every dataset has ``units`` and ``long_name``,
and the dimension scales make ``xarray.open_dataset(path, engine="h5netcdf", group="fields")`` come out
labelled.  Format 1.2 adds /inputs, /choices, the dimension scales, the summary datasets and the checksums to
1.1; format 1.3 adds friction: the slip-distance and shear-traction fields, the dissipated energy and the
invariant's work in the history, /fretting_loop, and the regime in the summary; format 1.4 adds load histories
and wear limits: the block of every step in the history, and the summary's limit_reached, cycles_to_limit and
time_to_limit_h; format 1.5 adds the cumulative dissipated energy to the history (Fouvry's abscissa).  1.1, 1.2,
1.3 and 1.4 files are still read.

Writing.  The writer keeps the run in memory and at every flush builds the whole file as an in-memory HDF5
image, writes it with plain file I/O to a temporary file beside the target, fsyncs it and renames it over the
target (atomic on POSIX).  HDF5 therefore never writes to a disk that can fail: a full disk or an I/O error is
an ordinary OSError at a known point, after which the temporary is removed and the last good file is intact
(:class:`ResultsIOError`).  The first placement uses a hard link, which fails if the name appeared meanwhile,
so a results file is never replaced without overwrite.  Flushes happen at most every FLUSH_SECONDS (the first
FLUSH_SECONDS into the run), or 20 times the last flush's cost if longer, and at the end: a run shorter than
that writes its file once.

Claiming.  A run holds an exclusive ``flock`` on a lock file beside its output for as long as it may write it
(:class:`OutputClaim`), so two runs never share one output, with or without overwrite; the kernel releases the
lock if the process dies, so a killed run leaves no stale claim.

Reading.  :func:`read_results` checks structure, types, shapes against the grid, sizes before allocating,
finiteness and the checksums, and refuses a damaged file with the path of what is wrong.
"""
from __future__ import annotations

from fretsim.errors import ResultsFileError
from fretsim.results.claim import MAX_NAME, OutputBusy, OutputClaim, check_output_path
from fretsim.results.layout import (FIELDS, FORMAT_VERSION, HISTORY, NAN_SUMMARY, READABLE_FORMATS, STATUSES,
                                    SUMMARY_UNITS)
from fretsim.results.reader import Results, read_results, summary_json
from fretsim.results.seal import _seal, _verify_seal, reseal_file
from fretsim.results.sweep_table import SweepTable, read_sweep_table
from fretsim.results.writer import ResultsIOError, ResultsWriter

__all__ = ["FIELDS", "FORMAT_VERSION", "HISTORY", "MAX_NAME", "NAN_SUMMARY", "READABLE_FORMATS", "STATUSES",
           "SUMMARY_UNITS", "OutputBusy", "OutputClaim", "Results", "ResultsFileError", "ResultsIOError", "ResultsWriter", "SweepTable",
           "_seal", "_verify_seal", "reseal_file", "check_output_path", "read_results", "read_sweep_table", "summary_json"]
