"""cf.replay and cf.Renderer against the C++ renderer (cf::Replay, printed with 17 digits
by cf_python_replay_ref) to 1e-12, and against cfreplay's CSV to the 9 digits it prints."""

import csv
import io
import subprocess

import numpy as np
import pytest

import cf
from conftest import DATA, TRAJECTORIES, tool

VEC = ("F_W", "M_W", "F_A", "M_A")


def read_csv(text):
    return list(csv.DictReader(io.StringIO(text)))


def columns(rows, names):
    return np.array([[float(r[n]) for n in names] for r in rows])


CSV_COLS = {"F_W": ("Fx", "Fy", "Fz"), "M_W": ("Mx", "My", "Mz"), "F_A": ("FAx", "FAy", "FAz"),
            "M_A": ("MAx", "MAy", "MAz")}


@pytest.fixture(scope="module", params=sorted(TRAJECTORIES))
def case(request, graphs):
    name = request.param
    path = DATA / "trajectories" / f"{name}.csv"
    graph = graphs[TRAJECTORIES[name]]
    t, p, q = cf.read_trajectory(path)
    return name, path, graph, t, p, q, cf.replay(graph, t, p, q)


def test_same_cfs_and_forces_as_the_cpp_renderer(case):
    name, path, graph, t, p, q, r = case
    graph_path = DATA / "graphs" / f"{TRAJECTORIES[name]}.json"
    out = subprocess.run([tool("CF_REPLAY_REF"), str(graph_path), str(path)], check=True, capture_output=True,
                         text=True).stdout
    ref = read_csv(out)
    assert len(r) == len(ref) == len(t) > 100
    np.testing.assert_array_equal(r.t_s, [float(x["t"]) for x in ref])
    np.testing.assert_array_equal(r.cf, [int(x["cf"]) for x in ref])
    assert r.pcs.tolist() == [x["pcs"] for x in ref]
    assert r.motion.tolist() == [x["motion"] for x in ref]
    assert r.status.tolist() == [x["status"] for x in ref]
    for v in VEC:
        np.testing.assert_allclose(getattr(r, v), columns(ref, CSV_COLS[v]), rtol=1e-12, atol=1e-12, err_msg=v)
    # The trajectory does touch: some ticks have a CF and a contact force.
    assert (r.cf >= 0).sum() > 100 and np.abs(r.F_contact_W).max() > 0.1
    np.testing.assert_allclose(r.F_contact_W + r.F_gravity_W, r.F_W, rtol=0, atol=1e-12)


def test_same_as_cfreplay_csv(case, tmp_path):
    name, path, graph, t, p, q, r = case
    graph_path = DATA / "graphs" / f"{TRAJECTORIES[name]}.json"
    out = tmp_path / "out.csv"
    subprocess.run([tool("CF_CFREPLAY"), "--graph", str(graph_path), "--trajectory", str(path), "-o", str(out)],
                   check=True, capture_output=True)
    text = out.read_text()
    rows = read_csv(text)
    assert len(rows) == len(r)
    np.testing.assert_array_equal(r.cf, [int(x["cf"]) for x in rows])
    assert r.pcs.tolist() == [x["pcs"] for x in rows]
    assert r.motion.tolist() == [x["motion"] for x in rows]
    assert r.status.tolist() == [x["status"] for x in rows]
    assert r.regimes.tolist() == [x["regimes"] for x in rows]
    # The time as its shortest round-trip decimal: exact.
    np.testing.assert_array_equal(r.t_s, [float(x["t"]) for x in rows])
    for v in VEC:
        # %.9g: 9 significant digits, so within half a unit of the 9th.
        ref = columns(rows, CSV_COLS[v])
        np.testing.assert_array_less(np.abs(getattr(r, v) - ref), 5e-9 * np.abs(ref) + 1e-300, err_msg=v)
    # And the result's own CSV is cfreplay's, byte for byte.
    assert r.to_csv() == text


def test_renderer_step_by_step_equals_replay(case):
    name, path, graph, t, p, q, r = case
    renderer = cf.Renderer(graph)
    for i in range(len(t)):
        s = renderer.step(t[i], p[i], q[i])
        assert s["cf"] == r.cf[i] and s["motion"] == r.motion[i] and s["status"] == r.status[i]
        assert s["pcs_string"] == r.pcs[i] and s["regimes"] == r.regimes[i]
        for v in VEC:
            np.testing.assert_array_equal(s[v], getattr(r, v)[i])
    if name == "cube_lblock_corner":
        # Per-PC diagnostics of the last tick: the CF's PCs, the force's parts.
        assert [str(e["pc"]) for e in s["pc_forces"]][: len(s["pcs"])] == [str(pc) for pc in s["pcs"]]
        total = sum(e["F_W"] for e in s["pc_forces"])
        assert np.allclose(total, s["F_contact_W"], atol=1e-9)
    renderer.reset()
    s = renderer.step(t[0], p[0], q[0])
    assert s["cf"] == r.cf[0]


def test_step_many_carries_the_renderer_on(case):
    # A batch of ticks is the same as the ticks one by one, and the state carries across
    # batches: the trajectory in three batches equals the replay of it whole, bit for bit.
    name, path, graph, t, p, q, r = case
    renderer = cf.Renderer(graph)
    cuts = [0, len(t) // 3, 2 * len(t) // 3, len(t)]
    parts = [renderer.step_many(t[a:b], p[a:b], q[a:b]) for a, b in zip(cuts, cuts[1:])]
    for field in ("cf", "F_W", "M_W", "F_A", "M_A", "F_contact_W", "proxy_p", "dof"):
        np.testing.assert_array_equal(np.concatenate([getattr(x, field) for x in parts]), getattr(r, field))
    assert sum((list(x.motion) for x in parts), []) == list(r.motion)
    with pytest.raises(cf.Error, match=r"^step_many: time .* s does not increase \(previous step: .* s\)$"):
        renderer.step_many(t[:1], p[:1], q[:1])
    renderer.reset()
    assert list(renderer.step_many(t[:5], p[:5], q[:5]).cf) == list(r.cf[:5])


def test_parameters_are_cfreplays_options(l_graph, tmp_path):
    path = DATA / "trajectories" / "cube_lblock_slide.csv"
    t, p, q = cf.read_trajectory(path)
    kw = dict(mu_static=0.3, mu_kinetic=0.2, contact_stiffness_N_per_mm=1.5, kp_N_per_mm=0.9, mass_kg=0.25,
              epsilon_mm=0.5, friction_displacement="per_tick", centroid="volume", moment_reference="a_point",
              moment_point_A=[1.0, 2.0, 3.0], hold_fcy_threshold_N=0.01, interpolation_time_constant_s=0.002)
    r = cf.replay(l_graph, t, p, q, **kw)
    assert not np.array_equal(r.F_W, cf.replay(l_graph, t, p, q).F_W)
    # A cf.Params, or a Params plus keywords, are the same run.
    params = cf.Params(**kw)
    assert cf.replay(l_graph, t, p, q, params=params).to_csv() == r.to_csv()
    assert cf.replay(l_graph, t, p, q, params=cf.Params(mu_static=0.3), **{k: v for k, v in kw.items()
                                                                           if k != "mu_static"}).to_csv() == r.to_csv()
    out = tmp_path / "out.csv"
    subprocess.run([tool("CF_CFREPLAY"), "--graph", str(DATA / "graphs" / "cube_l_block.json"), "--trajectory",
                    str(path), "-o", str(out), "--mu-static", "0.3", "--mu-kinetic", "0.2", "--contact-stiffness-N-per-mm", "1.5", "--kp-N-per-mm", "0.9",
                    "--mass-kg", "0.25", "--epsilon-mm", "0.5", "--friction-displacement", "per_tick", "--centroid", "volume",
                    "--moment-point-A", "1", "2", "3", "--hold-fcy-threshold-N", "0.01", "--interpolation-time-constant-s", "0.002"],
                   check=True, capture_output=True)
    assert r.to_csv() == out.read_text()
    assert params.mu_static == 0.3 and params.friction_displacement == "per_tick"
    np.testing.assert_array_equal(params.moment_point_A, [1, 2, 3])


def test_detection_and_identification_parameters_are_reachable(l_graph):
    t, p, q = cf.read_trajectory(DATA / "trajectories" / "cube_lblock_corner.csv")
    base = cf.replay(l_graph, t, p, q).to_csv()
    # Culling and kept pairs never change a result; the fields are in the one tree.
    assert cf.replay(l_graph, t, p, q, use_bvh=False, reuse_margin_mm=0.0).to_csv() == base
    params = cf.Params(touch_distance_mm=0.002, deepest_contact_mm=0.5, max_combinations=100)
    assert params.touch_distance_mm == 0.002 and params.deepest_contact_mm == 0.5 and params.max_combinations == 100
    assert {"in_plane_tolerance_mm", "angular_tolerance_rad", "dominance_fit", "use_bvh"} <= set(params.to_dict())
    with pytest.raises(cf.Error, match=r"^Params: max_combinations must be an integer in \[1, 1000000000\], got 0$"):
        cf.Params(max_combinations=0)
    # Names two parameters shared before, kept for one release with a warning.
    old_names = {"stiffness_N_per_mm": "contact_stiffness_N_per_mm", "max_penetration_mm": "deepest_contact_mm",
                 "proxy_stiffness_N_per_mm": "proxy_coupling_stiffness_N_per_mm",
                 "proxy_damping_N_s_per_mm": "proxy_coupling_damping_N_s_per_mm",
                 "proxy_max_penetration_mm": "proxy_penetration_tolerance_mm"}
    for old, new in old_names.items():
        with pytest.warns(DeprecationWarning, match=f"parameter '{old}' is now '{new}'"):
            renamed = cf.Params(**{old: 0.5})
        assert renamed.to_dict()[new] == 0.5 and old not in renamed.to_dict()
    with pytest.raises(cf.Error, match=r"^Params: use_bvh must be True or False, got 'yes'$"):
        cf.Params(use_bvh="yes")


def test_the_proxy_keeps_a_pressing_device_in_contact(l_graph):
    # The bundled press: from 1 mm above the floor to 10 mm inside it, slide, pull out.
    t, p, q = cf.read_trajectory(DATA / "trajectories" / "cube_lblock_press.csv")
    inside = p[:, 1] < 35.0  # the cube's bottom below the floor's top (y = 20)
    on = cf.replay(l_graph, t, p, q)
    off = cf.replay(l_graph, t, p, q, proxy=False)
    assert inside.sum() > 1500
    assert (on.cf[inside] >= 0).all()
    assert (off.cf[inside] < 0).sum() > 0.9 * inside.sum()
    # The proxy stays on the floor (within its 0.01 mm), the device goes 10 mm below it,
    # and the push there is K (epsilon + 10 mm) less the weight: 2.3 * 11 - 4.9 N.
    assert on.proxy_p[inside, 1].min() >= 35.0 - 0.01
    deepest = np.argmin(p[:, 1])
    assert on.F_W[deepest, 1] == pytest.approx(2.3 * 11 - 4.9, abs=1e-3)
    assert on.F_contact_W[deepest, 1] == pytest.approx(2.3 * 11, abs=1e-3)
    # Off, A's pose is the device's.
    np.testing.assert_array_equal(off.proxy_p, p)
    params = cf.Params(proxy=False, proxy_coupling_stiffness_N_per_mm=1.5, proxy_friction=False)
    assert params.to_dict()["proxy"] is False and params.proxy_coupling_stiffness_N_per_mm == 1.5
    with pytest.raises(cf.Error, match=r"^Params: proxy must be True or False, got 1$"):
        cf.Params(proxy=1)
    with pytest.raises(cf.Error, match=r"^Params: proxy_coupling_stiffness_N_per_mm must be a finite number in \(0, 1e\+09\], got 0$"):
        cf.Params(proxy_coupling_stiffness_N_per_mm=0.0)


def test_replay_errors_carry_messages(l_graph):
    t, p, q = cf.read_trajectory(DATA / "trajectories" / "cube_lblock_guarded.csv")
    with pytest.raises(cf.Error, match=r"^replay: p must have shape \(N, 3\) with N = len\(t\) = \d+, got \(\d+, 2\)$"):
        cf.replay(l_graph, t, p[:, :2], q)
    with pytest.raises(cf.Error, match=r"^replay: q must have shape \(N, 4\) \(w, x, y, z\)"):
        cf.replay(l_graph, t, p, q[:-1])
    with pytest.raises(cf.Error, match=r"^replay: no poses \(t is empty\)$"):
        cf.replay(l_graph, t[:0], p[:0], q[:0])
    t2 = t.copy()
    t2[5] = t2[4]
    with pytest.raises(cf.Error, match=r"^replay: row 5: time 0\.004 s does not increase \(previous row: 0\.004 s\)$"):
        cf.replay(l_graph, t2, p, q)
    q2 = q.copy()
    q2[7] = [1, 0.1, 0, 0]
    with pytest.raises(cf.Error, match=r"^replay: row 7: the quaternion \(qw,qx,qy,qz\) has norm 1\.00498756, "
                                       r"not 1 within 0\.001$"):
        cf.replay(l_graph, t, p, q2)
    p2 = p.copy()
    p2[3, 1] = np.nan
    with pytest.raises(cf.Error, match=r"^replay: row 3: the translation is not finite$"):
        cf.replay(l_graph, t, p2, q)
    with pytest.raises(cf.Error, match=r"^replay: unknown parameter 'mu' \(parameters: mass_kg, "):
        cf.replay(l_graph, t, p, q, mu=0.3)
    with pytest.raises(cf.Error, match=r"^replay: epsilon_mm must be a finite number in \[1e-06, 1000\], got -1$"):
        cf.replay(l_graph, t, p, q, epsilon_mm=-1)
    with pytest.raises(cf.Error, match=r"^replay: friction_displacement must be one of 'stick_anchor', 'per_tick', "
                                       r"got 'anchor'$"):
        cf.replay(l_graph, t, p, q, friction_displacement="anchor")
    with pytest.raises(cf.Error, match=r"^replay: mass_kg must be a number, got 'heavy'$"):
        cf.replay(l_graph, t, p, q, mass_kg="heavy")
    with pytest.raises(cf.Error, match=r"^replay: t must be real numbers, got an array of <U1$"):
        cf.replay(l_graph, ["a"], p[:1], q[:1])
    with pytest.raises(cf.Error, match=r"^replay: t must be an array of numbers, got "):
        cf.replay(l_graph, [[0.0], [0.1, 0.2]], p[:2], q[:2])  # ragged: not an array
    r = cf.Renderer(l_graph)
    r.step(0.0, p[0], q[0])
    with pytest.raises(cf.Error, match=r"^step: time 0 s does not increase \(previous step: 0 s\)$"):
        r.step(0.0, p[0], q[0])
    with pytest.raises(cf.Error, match=r"^step: q must have shape \(4,\) \(w, x, y, z\), got \(3,\)$"):
        r.step(1.0, p[0], q[0][:3])
    with pytest.raises(cf.Error, match=r"^Renderer: unknown parameter 'K'"):
        cf.Renderer(l_graph, K=2)


def test_replay_and_step_many_stop_on_ctrl_c(l_graph):
    # Ctrl-C (SIGINT from another thread here) during a long replay raises KeyboardInterrupt
    # part way: the ticks run without the GIL but look for signals every 8,192 ticks (about
    # 0.1 s). 400,000 ticks of the cube resting take about 4 s whole.
    import os
    import signal
    import threading
    import time

    n = 400_000
    t = np.arange(1, n + 1) * 1e-3
    p = np.tile([20.0, 10.0, 5.0], (n, 1))
    q = np.tile([1.0, 0.0, 0.0, 0.0], (n, 1))

    def interrupt_soon():
        time.sleep(0.3)
        os.kill(os.getpid(), signal.SIGINT)

    renderer = cf.Renderer(l_graph)
    for run in (lambda: cf.replay(l_graph, t, p, q), lambda: renderer.step_many(t, p, q)):
        timer = threading.Thread(target=interrupt_soon)
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            run()
        timer.join()
    # The renderer stopped part way, not at the end (where Python would also have raised the
    # KeyboardInterrupt), and carries on from the ticks it took: the trajectory's last time is
    # still ahead of it. (Where it stopped depends on when the timer thread gets to run: 0.3 s
    # on an idle machine, over 2 s under a loaded ctest -j2.)
    renderer.step_many(t[n - 1:], p[:1], q[:1])
