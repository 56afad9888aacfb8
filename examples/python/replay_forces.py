#!/usr/bin/env python3
"""Load a CF graph, replay a trajectory of A through the renderer, plot the forces.

A notebook-style script (cells marked with # %%). From the repository root, after building:

    PYTHONPATH=build/python /usr/bin/python3 examples/python/replay_forces.py

writes build/replay/forces.png (options: --graph, --trajectory, --png, --mu-static).
"""

# %% Imports: the package cf from the build tree (PYTHONPATH=build/python) and matplotlib.
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import cf  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("--graph", default=ROOT / "data" / "graphs" / "cube_l_block.json")
ap.add_argument("--trajectory", default=ROOT / "data" / "trajectories" / "cube_lblock_corner.csv")
ap.add_argument("--png", default=ROOT / "build" / "replay" / "forces.png")
ap.add_argument("--mu-static", type=float, default=0.7, help="static friction coefficient (mu_static)")
args = ap.parse_args()

# %% The graph: CFs, transitions, the two models.
graph = cf.load_graph(args.graph)
print(graph)
print("A:", graph.model_a, " B:", graph.model_b)

# %% The trajectory: times (s), translations (N x 3, mm), quaternions (N x 4, w x y z).
t, p, q = cf.read_trajectory(args.trajectory)

# %% Replay at C++ speed: cfreplay's loop over every pose; keyword arguments are cf::Params.
r = cf.replay(graph, t, p, q, mu_static=args.mu_static)
print(f"{len(r)} ticks, {(r.status != 'no_contact').sum()} in contact")

# %% The CFs visited, in order, with their motion types.
runs = [0] + [i for i in range(1, len(r)) if r.cf[i] != r.cf[i - 1]]
for i in runs:
    where = f"CF {r.cf[i]} ({r.pcs[i]})" if r.cf[i] >= 0 else "no CF"
    print(f"  t = {r.t[i]:.3f} s: {where}, {r.motion[i]}, {r.status[i]}")
for c in sorted(set(r.cf[r.cf >= 0].tolist())):
    print(f"  CF {c}: {graph.cf(c).pcs_string}, dof {graph.cf(c).dof}, neighbours {len(graph.neighbours(c))}")

# %% Plot the force and moment in the world frame, one band per CF.
fig, (ax_f, ax_m) = plt.subplots(2, 1, sharex=True, figsize=(10, 6))
for ax, v, unit in ((ax_f, r.F_W, "force (N)"), (ax_m, r.M_W, "moment (N mm)")):
    for k, (name, colour) in enumerate(zip("xyz", ("tab:red", "tab:green", "tab:blue"))):
        ax.plot(r.t, v[:, k], color=colour, label=name)
    ax.set_ylabel(unit)
    ax.grid(alpha=0.3)
ax_f.legend(loc="upper right")
bands = runs + [len(r)]
for j, (a, b) in enumerate(zip(bands[:-1], bands[1:])):
    if r.cf[a] >= 0:
        for ax in (ax_f, ax_m):
            ax.axvspan(r.t[a], r.t[b - 1], color=("#eef3fb", "#fbf3e6")[j % 2], zorder=0)
        ax_f.annotate(f"CF {r.cf[a]}", (r.t[a], 1.0), xycoords=("data", "axes fraction"), va="bottom", fontsize=8)
ax_m.set_xlabel("t (s)")
fig.suptitle(f"{pathlib.Path(args.trajectory).name} against {graph.model_a.name} / {graph.model_b.name}", y=0.99)
fig.tight_layout()
png = pathlib.Path(args.png)
png.parent.mkdir(parents=True, exist_ok=True)
fig.savefig(png, dpi=100)
print("wrote", png, f"(peak |F| {np.linalg.norm(r.F_W, axis=1).max():.2f} N)")
