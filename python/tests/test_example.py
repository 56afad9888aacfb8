"""examples/python/replay_forces.py runs and writes its plot."""

import os
import subprocess
import sys

from conftest import DATA, SOURCE


def test_example_writes_the_plot(tmp_path):
    png = tmp_path / "forces.png"
    env = dict(os.environ, MPLBACKEND="Agg")
    out = subprocess.run([sys.executable, str(SOURCE / "examples" / "python" / "replay_forces.py"),
                          "--graph", str(DATA / "graphs" / "cube_l_block.json"),
                          "--trajectory", str(DATA / "trajectories" / "cube_lblock_corner.csv"),
                          "--png", str(png)], check=True, capture_output=True, text=True, env=env).stdout
    data = png.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20000
    assert "1851 ticks" in out and "f-f:2:4;f-f:5:5" in out
