"""cf.generate: cfgen's generator from Python, the same graph as the cfgen command."""

import subprocess

import pytest

import cf
from conftest import DATA, tool

pytestmark = pytest.mark.skipif(not cf.HAVE_TOOLS, reason="built without the CGAL tools")


def test_generate_equals_cfgen(tmp_path):
    a, b = DATA / "models" / "cube.off", DATA / "models" / "l_block.off"
    out = tmp_path / "py.json"
    g = cf.generate(a, b, out, max_pcs=1, threads=2)
    ref = tmp_path / "cfgen.json"
    subprocess.run([tool("CF_CFGEN"), "--quiet", "--max-pcs", "1", "-j", "2", str(a), str(b), "-o", str(ref)],
                   check=True, capture_output=True)
    assert out.read_bytes() == ref.read_bytes()
    # The single-PC CFs are those of the bundled graph.
    full = cf.load_graph(DATA / "graphs" / "cube_l_block.json")
    singles = sorted(c.pcs_string for c in full.cfs if len(c.pcs) == 1)
    assert sorted(c.pcs_string for c in g.cfs) == singles
    # Without an output file: the same graph.
    assert cf.generate(a, b, max_pcs=1, threads=2).to_json() == g.to_json()


def test_generate_errors(tmp_path):
    a = DATA / "models" / "cube.off"
    with pytest.raises(cf.Error, match=r"^generate: max_pcs must be an integer in \[1, 3\], got 4$"):
        cf.generate(a, a, max_pcs=4)
    with pytest.raises(cf.Error, match=r"^generate: min_clearance must be a finite number in \[1e-09, 0\.1\], got 1$"):
        cf.generate(a, a, min_clearance=1.0)
    with pytest.raises(cf.Error, match=r"missing\.off"):
        cf.generate(a, tmp_path / "missing.off")
    with pytest.raises(TypeError):
        cf.generate(a, a, bogus=1)
