"""Wear coefficients fitted to McColl's measured flat scars (Table 4), against McColl's own coefficients.

For each of McColl's four tests the flat's measured centre-line depth and scar width after the test's cycles
(the cases' `expected.experiment`) are the data; both wear coefficients are fitted by `fretsim fit` (2D, the
case's stepping).  Two data for two values: the fit is exact where it can be, with no degrees of freedom left
for a confidence interval, so the table reports the fitted values and the residuals, not intervals.  This is a
report, not a calibration: the shipped cases keep McColl's coefficients.

    python scripts/fit_mccoll.py        # a table; scripts/results/fit_mccoll.csv
"""
from __future__ import annotations

import time

from _study import ROOT, write_csv

CASES = ["mccoll_185N", "mccoll_500N", "mccoll_1670N", "mccoll_500N_10um"]


def main() -> None:
    import tempfile
    from pathlib import Path

    from fretsim.api import load_case
    from fretsim.fit import fit, read_measured
    from fretsim.yamlread import loads
    rows = []
    print(f"{'case':17s} {'k_m McColl':>11s} {'k_m fitted':>11s} {'k_s McColl':>11s} {'k_s fitted':>11s} "
          f"{'depth res.':>10s} {'width res.':>10s} {'runs':>5s} {'s':>5s}")
    for name in CASES:
        path = ROOT / "cases" / f"{name}.yaml"
        text = path.read_text()
        case = load_case(path)
        exp = loads(text)["expected"]["experiment"]
        with tempfile.TemporaryDirectory() as tmp:
            csv_path = Path(tmp) / "m.csv"
            depth, width = exp["centre_wear_depth_stationary"].split(), exp["scar_width_stationary"].split()
            csv_path.write_text(f"cycle [cycles],centre_wear_depth_stationary [{depth[1]}],scar_width_stationary "
                                f"[{width[1]}]\n{case.loading.cycles},{depth[0]},{width[0]}\n")
            t = time.perf_counter()
            res = fit(text, str(path), read_measured(csv_path), overrides=["model.dimension=2d"])
            seconds = time.perf_counter() - t
        row = {"case": name, "k_m_mccoll": case.moving.wear_coefficient, "k_m_fitted": res.values[0],
               "k_s_mccoll": case.stationary.wear_coefficient, "k_s_fitted": res.values[1],
               "depth_residual": res.residuals[0], "width_residual": res.residuals[1], "runs": res.runs,
               "seconds": seconds, "note": "; ".join([res.message, *res.warnings])}
        rows.append(row)
        print(f"{name:17s} {row['k_m_mccoll']:11.3g} {row['k_m_fitted']:11.3g} {row['k_s_mccoll']:11.3g} "
              f"{row['k_s_fitted']:11.3g} {row['depth_residual']:+10.2%} {row['width_residual']:+10.2%} "
              f"{res.runs:5d} {seconds:5.1f}" + ("  (k_m at the search's edge: no fit)" if not res.converged else
                                                  "  (k_m not determined: no fit)" if not res.determined else ""),
              flush=True)
    write_csv(rows, ROOT / "scripts" / "results" / "fit_mccoll.csv")


if __name__ == "__main__":
    main()
