"""numpy in and out: the model's and the CF's arrays are read-only views (no copy) that keep
their owner alive; pose arrays are read in place when float64 and C-contiguous, converted
when float32, integer or strided, and refused with a message naming the argument otherwise."""

import gc
import json

import numpy as np
import pytest

import cf
from conftest import DATA

GRAPH = DATA / "graphs" / "cube_l_block.json"


@pytest.fixture(scope="module")
def graph():
    return cf.load_graph(GRAPH)


@pytest.fixture(scope="module")
def stored():
    return json.loads(GRAPH.read_text())


MODEL_ARRAYS = ("vertices", "edges", "edge_faces", "edge_convex", "edge_dihedral", "face_normals", "face_offsets",
                "face_areas", "face_centroids")


@pytest.mark.parametrize("name", MODEL_ARRAYS)
def test_model_arrays_are_read_only_views(graph, name):
    m = graph.model_b
    a, b = getattr(m, name), getattr(m, name)
    assert a is not b and np.shares_memory(a, b)  # two reads, one memory: no copy
    assert not a.flags.writeable
    with pytest.raises(ValueError):
        a[0] = a[0]


def test_face_loops_are_views(graph, stored):
    m = graph.model_b
    a, b = m.faces[3][0], m.faces[3][0]
    assert np.shares_memory(a, b) and not a.flags.writeable and a.dtype == np.int32
    assert [[loop.tolist() for loop in f] for f in m.faces] == [f["loops"] for f in stored["models"]["B"]["faces"]]


def test_model_views_hold_the_stored_values(graph, stored):
    m, s = graph.model_b, stored["models"]["B"]
    assert np.array_equal(m.vertices, np.array(s["vertices"], dtype=float))
    assert np.array_equal(m.edges, np.array(s["edges"], dtype=np.int32))
    assert m.vertices.dtype == np.float64 and m.edges.dtype == np.int32 and m.edge_convex.dtype == np.bool_
    # The faces' views step over whole face records: each row is its own face's normal.
    for f, n in enumerate(m.face_normals):
        loop = m.faces[f][0]
        assert abs(np.dot(n, m.vertices[loop[1]] - m.vertices[loop[0]])) < 1e-9
        assert np.allclose(n @ m.vertices[loop].T, m.face_offsets[f])


def test_cf_arrays_are_read_only_views(graph, stored):
    c = graph.cf(84)
    for name in ("witness_R", "witness_t", "planes"):
        a, b = getattr(c, name), getattr(c, name)
        assert np.shares_memory(a, b) and not a.flags.writeable
    w = stored["cfs"][84]["witness"]
    assert np.array_equal(c.witness_R, np.array(w["R"], dtype=float).reshape(3, 3))
    assert np.array_equal(c.witness_t, np.array(w["t"], dtype=float))
    assert np.array_equal(c.planes, np.array(stored["cfs"][84]["planes"], dtype=float).reshape(-1, 4))
    assert np.allclose(c.witness_R @ c.witness_R.T, np.eye(3), atol=1e-12)


def test_views_keep_their_owner_alive():
    v = cf.load_graph(GRAPH).model_a.vertices  # the graph and the model go out of scope
    R = cf.load_graph(GRAPH).cf(5).witness_R
    gc.collect()
    fresh = cf.load_graph(GRAPH)
    assert np.array_equal(v, fresh.model_a.vertices) and np.array_equal(R, fresh.cf(5).witness_R)


@pytest.fixture(scope="module")
def trajectory():
    return cf.read_trajectory(DATA / "trajectories" / "cube_lblock_corner.csv")


def test_float32_and_strided_poses_are_converted(graph, trajectory):
    t, p, q = trajectory
    ref = cf.replay(graph, t, p, q)
    # float32: the same as its values in float64.
    r32 = cf.replay(graph, t, p.astype(np.float32), q.astype(np.float32))
    r32_64 = cf.replay(graph, t, p.astype(np.float32).astype(np.float64), q.astype(np.float32).astype(np.float64))
    assert np.array_equal(r32.F_W, r32_64.F_W) and np.array_equal(r32.cf, r32_64.cf)
    # A strided view (every other column of a wider array) and integers: converted.
    wide = np.zeros((len(t), 6))
    wide[:, ::2] = p
    assert not wide[:, ::2].flags.c_contiguous
    assert np.array_equal(cf.replay(graph, t, wide[:, ::2], q).F_W, ref.F_W)
    ints = np.round(p).astype(np.int64)
    assert np.array_equal(cf.replay(graph, t, ints, q).F_W, cf.replay(graph, t, ints.astype(float), q).F_W)


@pytest.mark.parametrize("bad, kind", [(np.complex128, "complex128"), (str, "<U32"), (object, "object")])
def test_other_arrays_are_refused_by_name(graph, trajectory, bad, kind):
    t, p, q = trajectory
    arr = p.astype(bad) if bad is not object else np.array([[1, None, 3]] * len(t), dtype=object)
    with pytest.raises(cf.Error) as e:
        cf.replay(graph, t, arr, q)
    assert str(e.value) == f"replay: p must be real numbers, got an array of {kind}"
    with pytest.raises(cf.Error, match=r"^Params: moment_point_A must be real numbers, got an array of complex128$"):
        cf.Params(moment_point_A=[1j, 0, 0])
