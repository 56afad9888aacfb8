"""cf.gen.generate: cfgen's generator from Python, the same graph as the cfgen command."""

import subprocess

import pytest

import cf
from conftest import DATA, tool

gen = pytest.importorskip("cf.gen", reason="built without the CGAL tools")

CUBE = DATA / "models" / "cube.off"


def cfgen_bytes(tmp_path, *flags):
    """The bytes `cfgen --quiet --max-pcs 1 -j 2 FLAGS cube.off cube.off` writes."""
    ref = tmp_path / "cfgen.json"
    subprocess.run([tool("CF_CFGEN"), "--quiet", *flags, "--max-pcs", "1", "-j", "2", str(CUBE), str(CUBE),
                    "-o", str(ref)], check=True, capture_output=True)
    return ref.read_bytes()


def test_generate_equals_cfgen(tmp_path):
    # The cube against itself, single PCs only: about 5 s per run on 2 threads.
    a = b = CUBE
    out = tmp_path / "py.json"
    g = gen.generate(a, b, out, max_pcs=1, threads=2)
    assert out.read_bytes() == cfgen_bytes(tmp_path)
    # The options that made the models' faces are recorded (docs/features.md, "Creases").
    assert '"crease_angle_deg": {"A":10.0,"B":10.0}' in out.read_text()
    # Every face, edge and vertex pair of the cube that can touch alone: f-f 6 x 6, e-f and
    # f-e 12 x 6 each, v-f and f-v 8 x 6 each, e-e between the 12 x 12 edges (non-parallel).
    types = {}
    for c in g.cfs:
        assert len(c.pcs) == 1 and c.dof is not None
        types[c.pcs[0].type] = types.get(c.pcs[0].type, 0) + 1
    assert types["f-f"] == 36 and types["e-f"] == types["f-e"] == 72 and types["v-f"] == types["f-v"] == 48
    # Without an output file: the same graph.
    assert gen.generate(a, b, max_pcs=1, threads=2).to_json() == g.to_json()


def test_generate_without_symmetry(tmp_path):
    # symmetry=False is cfgen --no-symmetry: every set searched, the same CFs as one search
    # per orbit of the cube's 48 symmetries against itself.
    a = b = CUBE
    out = tmp_path / "plain.json"
    plain = gen.generate(a, b, out, max_pcs=1, threads=2, symmetry=False)
    assert out.read_bytes() == cfgen_bytes(tmp_path, "--no-symmetry")
    by_orbit = gen.generate(a, b, max_pcs=1, threads=2)

    def sets(g):
        return sorted(tuple((p.type, p.a, p.b) for p in c.pcs) for c in g.cfs)

    assert len(plain.cfs) == 420  # f-f 36, e-f and f-e 72 each, v-f and f-v 48 each, e-e 144
    assert sets(plain) == sets(by_orbit)


def test_generate_thorough(tmp_path):
    # thorough=True is cfgen --thorough: every set searched, then every image of each CF added
    # (the cube against itself: the per-set search already finds every single PC).
    a = b = CUBE
    out = tmp_path / "thorough.json"
    g = gen.generate(a, b, out, max_pcs=1, threads=2, thorough=True)
    assert out.read_bytes() == cfgen_bytes(tmp_path, "--thorough")
    assert len(g.cfs) == 420
    assert '"thorough": true' in out.read_text()
    with pytest.raises(cf.Error, match=r"^generate: symmetry=False excludes thorough=True$"):
        gen.generate(a, b, max_pcs=1, symmetry=False, thorough=True)


def test_generate_cube_cells(tmp_path):
    # cube_cells is cfgen --cube-cells: failed sets without an f-f searched over cubes of
    # rotation space; resolution is --resolution, below which the cells are not split. Both
    # are recorded in the graph's parameters, absent at their defaults.
    out = tmp_path / "cubes.json"
    gen.generate(CUBE, CUBE, out, max_pcs=1, threads=2, cube_cells=64, resolution=1e-3)
    assert out.read_bytes() == cfgen_bytes(tmp_path, "--cube-cells", "64", "--resolution", "1e-3")
    assert '"cube_cells": 64' in out.read_text()
    assert '"resolution_rad": 0.001' in out.read_text()
    with pytest.raises(cf.Error, match=r"^generate: cube_cells -1 is not in \[0, 10000000\]$"):
        gen.generate(CUBE, CUBE, max_pcs=1, cube_cells=-1)
    with pytest.raises(cf.Error, match=r"^generate: resolution must be a finite number in "
                                       r"\[1e-09, 0\.1\], got 0\.5$"):
        gen.generate(CUBE, CUBE, max_pcs=1, resolution=0.5)


def test_generate_errors(tmp_path):
    a = DATA / "models" / "cube.off"
    with pytest.raises(cf.Error, match=r"^generate: max_pcs must be an integer in \[1, 3\], got 4$"):
        gen.generate(a, a, max_pcs=4)
    with pytest.raises(cf.Error, match=r"^generate: min_clearance must be a finite number in \[1e-09, 0\.1\], got 1$"):
        gen.generate(a, a, min_clearance=1.0)
    # Each in its range, together no witness would be kept: refused before any work.
    with pytest.raises(cf.Error, match=r"^generate: good_clearance 0\.0001 is below min_clearance 0\.0002: "):
        gen.generate(a, a, good_clearance=1e-4)
    with pytest.raises(cf.Error, match=r"^generate: crease_angle_deg must be a finite number in \[0, 180\], got -1$"):
        gen.generate(a, a, crease_angle_deg=-1.0)
    with pytest.raises(cf.Error, match=r"missing\.off"):
        gen.generate(a, tmp_path / "missing.off")
    with pytest.raises(TypeError):
        gen.generate(a, a, bogus=1)


def test_generate_stops_on_ctrl_c_and_resumes(tmp_path):
    # Ctrl-C (SIGINT from another thread here) stops cf.gen.generate between tasks and raises
    # KeyboardInterrupt; the chunks finished so far stay in the checkpoint and the same call
    # resumes from them and writes the graph of an uninterrupted run. The peg in the block
    # with a hole, every set searched, one thread: about 40 s whole, stopped in its first
    # level-2 round.
    import os
    import signal
    import threading
    import time

    peg, hole = DATA / "models" / "peg.off", DATA / "models" / "hole_block.off"
    ckpt = tmp_path / "ckpt"
    out = tmp_path / "g.json"

    def chunks():
        return len(list(ckpt.glob("stage*_chunk*.json"))) if ckpt.exists() else 0

    def interrupt_after_70_chunks():
        for _ in range(6000):
            if chunks() >= 70:
                break
            time.sleep(0.01)
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Thread(target=interrupt_after_70_chunks)
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        gen.generate(peg, hole, out, threads=1, symmetry=False, checkpoint=ckpt)
    timer.join()
    kept = chunks()
    assert kept >= 70
    assert not out.exists()
    g = gen.generate(peg, hole, out, threads=2, symmetry=False, checkpoint=ckpt)
    ref = tmp_path / "whole.json"
    subprocess.run([tool("CF_CFGEN"), "--quiet", "--no-symmetry", "-j", "2", str(peg), str(hole), "-o", str(ref)],
                   check=True, capture_output=True)
    assert out.read_bytes() == ref.read_bytes()
    assert len(g.cfs) > 0


def test_generate_certificates(tmp_path):
    # The certificate file cfgen --certificates writes, the same bytes from Python.
    import json
    out, cert = tmp_path / "py.json", tmp_path / "py_cert.json"
    gen.generate(CUBE, DATA / "models" / "l_block.off", out, threads=2, certificates=cert)
    ref, ref_cert = tmp_path / "c.json", tmp_path / "c_cert.json"
    subprocess.run([tool("CF_CFGEN"), "--quiet", "-j", "2", str(CUBE), str(DATA / "models" / "l_block.off"),
                    "-o", str(ref), "--certificates", str(ref_cert)], check=True, capture_output=True)
    py, cli = json.loads(cert.read_text()), json.loads(ref_cert.read_text())
    assert py["format"] == "cf-certificates"
    py.pop("graph"), cli.pop("graph")  # each names its own graph file
    assert py == cli
    # 96 refuted over cells: one set of each of 2 orbits searched, the 94 others its images;
    # 48 by the rule for two e-e PCs at mirror corners (the L's two reflex corners); none left.
    assert py["summary"] == {
        "sets": 144, "invalid_by_rule": 48, "invalid_by_cells": 2, "invalid_as_image": 94,
        "thin": 0, "undecided": 0
    }


def test_generated_graph_reaches_the_runtime_in_memory(tmp_path):
    # Without `output` nothing is written: the graph is handed from cf.gen to cf as a
    # cf.CfGraph, whose renderer runs on it; its bytes are cfgen's.
    g = gen.generate(CUBE, DATA / "models" / "l_block.off", max_pcs=1, threads=2)
    assert isinstance(g, cf.CfGraph) and list(tmp_path.iterdir()) == []
    assert len(g.cfs) == 574  # every single PC of the cube against the L-block (data/graphs)
    r = cf.Renderer(g)
    w = r.step(0.0, [0.0, 0.0, 200.0], [1.0, 0.0, 0.0, 0.0])
    assert w["cf"] == -1  # far above the block: free space
    out = tmp_path / "g.json"
    g.save(out)
    ref = tmp_path / "cfgen.json"
    subprocess.run([tool("CF_CFGEN"), "--quiet", "--max-pcs", "1", "-j", "2", str(CUBE),
                    str(DATA / "models" / "l_block.off"), "-o", str(ref)], check=True, capture_output=True)
    assert out.read_bytes() == ref.read_bytes()
