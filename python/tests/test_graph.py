"""cf.load_graph and cf.CfGraph against the graph file read independently with json."""

import json

import numpy as np
import pytest

import cf
from conftest import DATA


@pytest.fixture(scope="module")
def raw():
    with open(DATA / "graphs" / "cube_l_block.json", encoding="utf-8") as f:
        return json.load(f)


def pcs_string(pcs):
    return ";".join(f"{p['type']}:{p['a']}:{p['b']}" for p in pcs)


def test_cfs_as_in_the_file(l_graph, raw):
    assert len(l_graph) == l_graph.num_cfs == len(raw["cfs"]) == 1390
    assert l_graph.num_transitions == len(raw["transitions"])
    cfs = l_graph.cfs
    for c, r in zip(cfs, raw["cfs"]):
        assert c.id == r["id"]
        # Canonical order is the file's order (the graph reader requires it).
        assert c.pcs_string == pcs_string(r["pcs"])
        assert [str(p) for p in c.pcs] == pcs_string(r["pcs"]).split(";")
        np.testing.assert_array_equal(c.witness_R, np.array(r["witness"]["R"]))
        np.testing.assert_array_equal(c.witness_t, np.array(r["witness"]["t"]))
        R = c.witness_R
        w, x, y, z = c.witness_q
        Rq = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                       [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                       [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        np.testing.assert_allclose(Rq, R, atol=1e-12)
        assert c.dof == r["dof"] and c.translation_dof == r["translation_dof"]
        assert c.pure_rotation == r["pure_rotation"]
        # The graph reader does not keep the stored contact planes (cf::CfGraph::load leaves
        # num_planes at 0); when it does, they must be the file's.
        if c.planes.shape[0]:
            np.testing.assert_array_equal(c.planes, np.array(r["planes"]).reshape(-1, 4))
        else:
            assert c.planes.shape == (0, 4)


def test_cf_of_finds_every_cf_by_its_pcs_in_any_form(l_graph):
    for c in l_graph.cfs:
        assert l_graph.cf_of(c.pcs_string) == c.id
        assert l_graph.cf_of(list(reversed(c.pcs))) == c.id
        assert l_graph.cf_of([(p.type, p.a, p.b) for p in c.pcs]) == c.id
    assert l_graph.cf_of("f-f:2:4") == l_graph.cf_of(cf.Pc("f-f", 2, 4)) is not None
    # A PC set the graph does not hold.
    assert l_graph.cf_of("v-f:0:0;v-f:1:0;v-f:2:0") is None


def test_neighbours_and_transitions_as_in_the_file(l_graph, raw):
    out = {}
    for t in raw["transitions"]:
        out.setdefault(t["from"], []).append((t["to"], t["kind"]))
    for i in range(l_graph.num_cfs):
        expected = sorted(out.get(i, []))
        assert l_graph.transitions_from(i) == expected
        assert l_graph.neighbours(i) == [to for to, _ in expected]
        for kind in ("gain", "lose", "change"):
            assert l_graph.neighbours(i, kind=kind) == [to for to, k in expected if k == kind]
    frm, to, kind = l_graph.transition_arrays()
    assert list(zip(frm.tolist(), to.tolist(), kind.tolist())) == [
        (t["from"], t["to"], t["kind"]) for t in raw["transitions"]]
    a, b = frm[0], to[0]
    assert l_graph.adjacent(a, b) and not l_graph.adjacent(a, a)


def test_models_of_the_graph(l_graph, raw):
    A = l_graph.model_a
    assert A.name == raw["models"]["A"]["name"]
    np.testing.assert_array_equal(A.vertices, np.array(raw["models"]["A"]["vertices"], dtype=float))
    np.testing.assert_array_equal(A.edges, np.array(raw["models"]["A"]["edges"]))
    assert [[loop.tolist() for loop in f] for f in A.faces] == [f["loops"] for f in raw["models"]["A"]["faces"]]
    np.testing.assert_allclose(A.face_normals, [f["normal"] for f in raw["models"]["A"]["faces"]], atol=1e-15)
    np.testing.assert_allclose(A.face_areas, [f["area"] for f in raw["models"]["A"]["faces"]], rtol=1e-12)
    assert A.vertices.shape == (8, 3) and A.edges.shape == (12, 2) and len(A.faces) == 6
    assert A.volume == pytest.approx(30.0 ** 3)
    assert l_graph.metadata_json and json.loads(l_graph.metadata_json)["stats"]["cfs"] == 1390


def test_cbor_round_trip(l_graph, tmp_path):
    path = tmp_path / "g.cbor"
    l_graph.save(path)
    back = cf.load_graph(path)
    assert back.to_json() == l_graph.to_json()


def test_to_networkx(l_graph):
    nx = pytest.importorskip("networkx")
    g = l_graph.to_networkx()
    assert isinstance(g, nx.DiGraph)
    assert g.number_of_nodes() == l_graph.num_cfs and g.number_of_edges() == l_graph.num_transitions
    c = l_graph.cf(84)
    assert g.nodes[84]["pcs"] == c.pcs_string and g.nodes[84]["dof"] == c.dof
    assert sorted(g.successors(84)) == l_graph.neighbours(84)
    for to, kind in l_graph.transitions_from(84):
        assert g.edges[84, to]["kind"] == kind


def test_graph_errors_carry_the_library_messages(l_graph, tmp_path):
    missing = tmp_path / "missing.json"
    with pytest.raises(cf.Error, match=r"missing\.json"):
        cf.load_graph(missing)
    bad = tmp_path / "bad.json"
    text = (DATA / "graphs" / "cube_l_block.json").read_text()
    bad.write_text(text.replace('"type":"f-f"', '"type":"f-x"', 1))
    with pytest.raises(cf.Error) as e:
        cf.load_graph(bad)
    assert "bad.json" in str(e.value) and "/cfs/0/pcs/0/type" in str(e.value)
    assert issubclass(cf.Error, ValueError)
    with pytest.raises(cf.Error, match=r"cf: no CF 1390 in the graph \(ids 0\.\.1389\)"):
        l_graph.cf(1390)
    with pytest.raises(cf.Error, match=r"neighbours: no CF -1"):
        l_graph.neighbours(-1)
    with pytest.raises(cf.Error, match=r"kind must be 'gain', 'lose' or 'change', got 'up'"):
        l_graph.neighbours(0, kind="up")
    with pytest.raises(cf.Error, match=r"not a PC: 'f-f:2'"):
        l_graph.cf_of("f-f:2")
    with pytest.raises(cf.Error, match=r"not a PC type: 'x-y'"):
        l_graph.cf_of([("x-y", 1, 2)])
