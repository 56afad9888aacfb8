"""cf.CfModel, cf.CfState and cf.step: one model shared by threads, a state per thread, the
GIL released in the step; the same ticks as cf.Renderer."""

import threading

import numpy as np
import pytest

import cf
from conftest import DATA, TRAJECTORIES

VEC = ("F_W", "M_W", "F_A", "M_A")


@pytest.fixture(scope="module")
def corner(graphs):
    name = "cube_lblock_corner"
    graph = graphs[TRAJECTORIES[name]]
    t, p, q = cf.read_trajectory(DATA / "trajectories" / f"{name}.csv")
    return graph, t, p, q


def run(model, t, p, q):
    state = cf.CfState(model)
    return [cf.step(model, state, t[i], p[i], q[i]) for i in range(len(t))]


def same(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b):
        assert x["cf"] == y["cf"] and x["motion"] == y["motion"] and x["pcs_string"] == y["pcs_string"]
        for v in VEC:
            np.testing.assert_array_equal(x[v], y[v])


def test_step_equals_the_renderer(corner):
    graph, t, p, q = corner
    renderer = cf.Renderer(graph, mu_static=0.5)
    expected = [renderer.step(t[i], p[i], q[i]) for i in range(len(t))]
    model = cf.CfModel(graph, mu_static=0.5)
    assert model.params.mu_static == 0.5
    same(run(model, t, p, q), expected)
    assert any(e["cf"] >= 0 for e in expected)  # the trajectory touches


def test_two_threads_on_one_model_each_with_its_state(corner):
    # Each thread steps the whole trajectory with its own state, concurrently: each gets the
    # ticks one thread alone gets (the model is read-only, the states are the threads' own).
    graph, t, p, q = corner
    model = cf.CfModel(graph)
    alone = run(model, t, p, q)
    results = [None, None]

    def work(k):
        results[k] = run(model, t, p, q)

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for r in results:
        same(r, alone)


def test_errors(corner):
    graph, t, p, q = corner
    model, other = cf.CfModel(graph), cf.CfModel(graph)
    state = cf.CfState(model)
    with pytest.raises(cf.Error, match=r"^step: the state was made for another model$"):
        cf.step(other, state, t[0], p[0], q[0])
    cf.step(model, state, t[1], p[1], q[1])
    with pytest.raises(cf.Error, match=r"^step: time .* does not increase"):
        cf.step(model, state, t[0], p[0], q[0])
    state.reset()  # forgets the last time too
    cf.step(model, state, t[0], p[0], q[0])
    with pytest.raises(cf.Error, match=r"^CfModel: unknown parameter 'K'"):
        cf.CfModel(graph, K=2)


def test_step_many_equals_steps_and_carries_on(corner):
    graph, t, p, q = corner
    model = cf.CfModel(graph)
    steps = run(model, t, p, q)
    state = cf.CfState(model)
    half = len(t) // 2
    first = cf.step_many(model, state, t[:half], p[:half], q[:half])
    rest = cf.step_many(model, state, t[half:], p[half:], q[half:])
    cfs = list(first.cf) + list(rest.cf)
    assert cfs == [s["cf"] for s in steps]
    F = np.vstack([first.F_W, rest.F_W])
    np.testing.assert_array_equal(F, np.array([s["F_W"] for s in steps]))
    with pytest.raises(cf.Error, match=r"^step_many: time .* does not increase"):
        cf.step_many(model, state, t[:2], p[:2], q[:2])
    with pytest.raises(cf.Error, match=r"^step_many: the state was made for another model$"):
        cf.step_many(cf.CfModel(graph), state, t[-1:], p[-1:], q[-1:])
