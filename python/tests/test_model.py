"""cf.gen.load_model: the features of a model file, as the graph stores them."""

import numpy as np
import pytest

import cf
from conftest import DATA

gen = pytest.importorskip("cf.gen", reason="built without the CGAL tools")


def test_model_features_equal_the_graphs(l_graph):
    for path, stored in ((DATA / "models" / "cube.off", l_graph.model_a), (DATA / "models" / "l_block.off",
                                                                           l_graph.model_b)):
        m = gen.load_model(path)
        assert m.name == stored.name
        np.testing.assert_array_equal(m.vertices, stored.vertices)
        np.testing.assert_array_equal(m.edges, stored.edges)
        assert [[loop.tolist() for loop in f] for f in m.faces] == [[loop.tolist() for loop in f] for f in stored.faces]
        assert m.vertices.dtype == np.float64 and m.edges.dtype == np.int32
        np.testing.assert_allclose(m.face_normals, stored.face_normals, atol=1e-12)
        assert m.volume == pytest.approx(stored.volume, rel=1e-12)
    cube = gen.load_model(DATA / "models" / "cube.off")
    assert cube.vertices.shape == (8, 3) and cube.edges.shape == (12, 2) and len(cube.faces) == 6
    assert cube.edge_convex.all() and cube.face_areas == pytest.approx([900.0] * 6)
    # Every edge bounds its two faces; every face loop's sides are edges.
    edges = {tuple(e) for e in cube.edges.tolist()}
    for f in cube.faces:
        loop = f[0].tolist()
        for i in range(len(loop)):
            assert tuple(sorted((loop[i], loop[(i + 1) % len(loop)]))) in edges


def test_units_scale_to_mm():
    mm = gen.load_model(DATA / "models" / "cube.off")
    cm = gen.load_model(DATA / "models" / "cube.off", units="cm")
    np.testing.assert_allclose(cm.vertices, 10 * mm.vertices, rtol=1e-15)
    assert cm.volume == pytest.approx(1000 * mm.volume)


def test_model_errors(tmp_path):
    with pytest.raises(cf.Error, match=r"^load_model: units must be 'mm', 'cm', 'm' or 'in', got 'ft'$"):
        gen.load_model(DATA / "models" / "cube.off", units="ft")
    with pytest.raises(cf.Error, match=r"nothing\.off"):
        gen.load_model(tmp_path / "nothing.off")
    open_box = tmp_path / "open.off"
    open_box.write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
    with pytest.raises(cf.Error, match=r"^loading '.*open\.off': "):
        gen.load_model(open_box)


def _prism(path, n=64, r=10.0, h=5.0):
    """An n-gon prism as OFF, each side one quad: neighbouring sides turn by 360/n degrees."""
    import math
    pts = [(r * math.cos(2 * math.pi * i / n), r * math.sin(2 * math.pi * i / n), z) for z in (0.0, h) for i in range(n)]
    faces = [list(range(n - 1, -1, -1)), list(range(n, 2 * n))]
    faces += [[i, (i + 1) % n, n + (i + 1) % n, n + i] for i in range(n)]
    lines = ["OFF", f"{len(pts)} {len(faces)} 0"] + [f"{x!r} {y!r} {z!r}" for x, y, z in pts]
    lines += [" ".join(map(str, [len(f)] + f)) for f in faces]
    path.write_text("\n".join(lines) + "\n")
    return path


def test_crease_angle_bounds_merged_faces(tmp_path):
    prism = _prism(tmp_path / "prism.off")
    assert len(gen.load_model(prism).faces) == 66  # the default tolerance merges no sides
    # At a coarse tolerance, runs of sides merge; the crease angle bounds how far a face turns.
    wide = gen.load_model(prism, coplanar_rel_tol=2e-2, crease_angle_deg=180)
    bounded = gen.load_model(prism, coplanar_rel_tol=2e-2)  # the default, 10 degrees
    assert len(wide.faces) == 15
    assert 15 < len(bounded.faces) < 66
    assert len(gen.load_model(prism, coplanar_rel_tol=2e-2, crease_angle_deg=5).faces) == 66
    with pytest.raises(cf.Error, match=r"^load_model: crease_angle_deg must be a finite number in \[0, 180\], got 200$"):
        gen.load_model(prism, crease_angle_deg=200)
