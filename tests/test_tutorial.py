"""docs/tutorial.md runs as written: every shell command in it, in an empty directory, with the files its YAML
blocks name (`# file: NAME` on their first line), and what it says they produce exists."""
import re
import subprocess
from pathlib import Path

TUTORIAL = Path(__file__).resolve().parent.parent / "docs" / "tutorial.md"


def test_the_tutorial_runs_as_written_and_produces_what_it_says(tmp_path):
    text = TUTORIAL.read_text()
    blocks = re.findall(r"```(yaml|sh)\n(.*?)```", text, flags=re.S)
    assert sum(kind == "sh" for kind, _ in blocks) >= 5
    for kind, body in blocks:
        if kind == "yaml":
            first, rest = body.split("\n", 1)
            assert first.startswith("# file: "), first
            (tmp_path / first.removeprefix("# file: ").strip()).write_text(rest)
            continue
        for line in body.splitlines():
            if line.strip() and not line.startswith("#"):
                r = subprocess.run(line, shell=True, cwd=tmp_path, capture_output=True, text=True, timeout=300)
                assert r.returncode == 0, (line, r.stdout[-2000:], r.stderr[-2000:])
    for produced in ("ball.h5", "figures/ball_maps.png", "figures/ball_fretting.png", "figures/overlay.png",
                     "figures/ball_energy_wear.png", "sweep/table.csv", "sweep/table.h5",
                     "sweep/figures/sweep_fretting_map.png", "sweep/figures/sweep_energy_wear.png",
                     "csv/history.csv"):
        assert (tmp_path / produced).exists(), produced
    from fretsim.api import read_results
    res = read_results(tmp_path / "ball.h5")
    assert res.status == "complete" and res.summary["regime"] == "gross_slip"
    # the tutorial's numbers: the Hertz contact it quotes, and a flat wearing more than the ball
    assert 500 < res.inputs["hertz_peak_pressure"][0] < 600 and 0.09 < res.inputs["hertz_half_width_x"][0] < 0.1
    assert res.summary["max_wear_depth_stationary_um"] > res.summary["max_wear_depth_moving_um"]
    assert len((tmp_path / "sweep" / "table.csv").read_text().splitlines()) == 1 + 6
