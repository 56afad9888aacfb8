#!/usr/bin/env python3
"""A batch step and a two-thread servo loop: one cf.CfModel shared, one cf.CfState per thread.

    python examples/python/servo_threads.py [--repeat N]

Each thread steps the cube's corner trajectory against the L-block N times over with
cf.step_many (the GIL released while libcf runs), and the script prints the ticks per second
of one thread and of two. With a package built in the source tree, run it with
PYTHONPATH=build/python /usr/bin/python3.
"""

from __future__ import annotations

import argparse
import pathlib
import threading
import time

import numpy as np
import numpy.typing as npt

import cf

ROOT = pathlib.Path(__file__).resolve().parents[2]


def laps(t: npt.NDArray[np.float64], p: npt.NDArray[np.float64], q: npt.NDArray[np.float64],
         repeat: int) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """The trajectory `repeat` times over, each lap after the last in time."""
    span = t[-1] - t[0] + (t[1] - t[0])
    tt = np.concatenate([t + k * span for k in range(repeat)])
    return tt, np.tile(p, (repeat, 1)), np.tile(q, (repeat, 1))


def ticks_per_second(model: cf.CfModel, poses: tuple[npt.NDArray[np.float64], ...], threads: int) -> float:
    """Ticks per second of `threads` threads, each with its own state of `model`."""
    states = [cf.CfState(model) for _ in range(threads)]
    results: list[cf.ReplayResult | None] = [None] * threads

    def work(k: int) -> None:
        results[k] = cf.step_many(model, states[k], *poses)

    workers = [threading.Thread(target=work, args=(k,)) for k in range(threads)]
    start = time.perf_counter()
    for w in workers:
        w.start()
    for w in workers:
        w.join()
    seconds = time.perf_counter() - start
    first = results[0]
    assert first is not None and all(r is not None and np.array_equal(r.F_W, first.F_W) for r in results)
    return threads * len(poses[0]) / seconds


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--repeat", type=int, default=20, help="laps of the trajectory each thread steps")
    args = ap.parse_args()
    graph = cf.load_graph(ROOT / "data" / "graphs" / "cube_l_block.json")
    t, p, q = cf.read_trajectory(ROOT / "data" / "trajectories" / "cube_lblock_corner.csv")

    # A batch step: N poses in, N wrenches and CF ids out, at C++ speed.
    model = cf.CfModel(graph, mu_static=0.5)
    r = cf.step_many(model, cf.CfState(model), t, p, q)
    touching = r.cf >= 0
    print(f"batch: {len(r)} ticks, {int(touching.sum())} in a CF, CFs {sorted(set(r.cf[touching].tolist()))}")
    print(f"last tick: CF {r.cf[-1]} ({r.pcs[-1]}), F_W = {np.round(r.F_W[-1], 3)} N")

    # The servo loop on one and on two threads, one state each.
    poses = laps(t, p, q, args.repeat)
    one = ticks_per_second(model, poses, 1)
    two = ticks_per_second(model, poses, 2)
    print(f"{len(poses[0])} ticks a thread: 1 thread {one:,.0f} ticks/s, 2 threads {two:,.0f} ticks/s "
          f"({two / one:.2f}x)")


if __name__ == "__main__":
    main()
