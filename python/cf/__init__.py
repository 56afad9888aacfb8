"""cf: contact formations of two rigid polyhedra, from Python.

The run-time library libcf, bound with pybind11 (docs/python.md); the generator and the
model loader are the module ``cf.gen``:

- ``cf.load_graph(path)``: a CF graph file, JSON or CBOR (``cf.CfGraph``: CFs with PCs,
  witnesses and freedoms, transitions, ``cf_of``, ``neighbours``, ``to_networkx``);
- ``cf.Renderer(graph, **params).step(t, p, q)``: one servo tick;
- ``cf.replay(graph, t, p, q, **params)``: cfreplay's loop over numpy arrays of poses.

Units are mm, N, kg, N mm and s; poses are x_B = R x_A + p with R the unit quaternion
q = (w, x, y, z). Bad input raises ``cf.Error`` (a ValueError) with libcf's message; a file
that cannot be read or written as such raises ``cf.FileError``, both a cf.Error and an OSError.
"""

from __future__ import annotations

import os as _os
from typing import TYPE_CHECKING, Any

from . import _cf
from ._cf import Cf, CfGraph, CfModel, CfState, Error, FileError, Params, Pc, Polyhedron, Renderer, step
from ._cf import __version__, graph_format_version
from ._replay import ReplayResult, read_trajectory
from ._networkx import to_networkx as _to_networkx

if TYPE_CHECKING:
    import os

    import numpy.typing as npt

__all__ = [
    "Cf", "CfGraph", "CfModel", "CfState", "Error", "FileError", "Params", "Pc", "Polyhedron",
    "Renderer", "ReplayResult", "step", "step_many",
    "load_graph", "read_trajectory", "replay", "__version__", "graph_format_version",
]


def load_graph(path: str | os.PathLike[str], validate_schema: bool = True,
               full_schema_check: bool = False) -> CfGraph:
    """Loads a CF graph file (JSON, or CBOR when the name ends in .cbor).

    The file is checked against the schema (schemas/cf-graph.schema.json) and for internal
    consistency, as every tool does (cf::CfGraph::load); ``full_schema_check`` also runs the
    schema validator over every CF and transition (slower). Raises cf.Error naming the file,
    the JSON pointer and the problem.
    """
    g = _cf.load_graph(_os.fspath(path), validate_schema, full_schema_check)
    setattr(g, "_source_path", _os.fspath(path))  # an input that ReplayResult.to_csv never overwrites
    return g


def replay(graph: CfGraph, t: npt.ArrayLike, p: npt.ArrayLike, q: npt.ArrayLike, params: Params | None = None,
           **kwargs: Any) -> ReplayResult:
    """Replays a trajectory of A through the renderer: cfreplay's loop, at C++ speed.

    ``t`` (N,) times in s, strictly increasing; ``p`` (N, 3) translations in mm; ``q``
    (N, 4) unit quaternions w, x, y, z (normalised as cfreplay does; |q| must be 1 within
    1e-3). Parameters: a cf.Params and/or keyword arguments with cf::Params' names and
    units (mass_kg, contact_stiffness_N_per_mm, mu_static, epsilon_mm, ...). A fresh renderer steps
    over every pose (cf::Replay, the engine cfreplay runs); the result is a
    cf.ReplayResult whose arrays are named like cf::HapticResult's fields. Ctrl-C raises
    KeyboardInterrupt within a second.
    """
    source = getattr(graph, "_source_path", None)
    return ReplayResult(_cf.replay(graph, t, p, q, params, **kwargs), [source] if source else [])


def _save(self: CfGraph, path: str | os.PathLike[str]) -> None:
    """Writes the graph (JSON, or CBOR when the name ends in .cbor) through a temporary file and
    a rename, so that the file is whole or absent (cf::CfGraph::save)."""
    self._save(_os.fspath(path))


# Methods in Python on the extension's classes (setattr: the stubs declare them).
setattr(CfGraph, "save", _save)
setattr(CfGraph, "to_networkx", _to_networkx)


def _step_many(self: Renderer, t: npt.ArrayLike, p: npt.ArrayLike, q: npt.ArrayLike) -> ReplayResult:
    """N servo ticks at once, at C++ speed (the GIL released): the renderer's state carries
    on from the ticks before, and on to the next. ``t`` (N,) s, increasing and after the
    last step; ``p`` (N, 3) mm; ``q`` (N, 4) w, x, y, z. Returns a cf.ReplayResult: the same
    values, tick by tick, as N calls of step(). Ctrl-C raises KeyboardInterrupt within a second;
    the renderer keeps the ticks it took."""
    return ReplayResult(self._step_many(t, p, q), [])


setattr(Renderer, "step_many", _step_many)


def step_many(model: CfModel, state: CfState, t: npt.ArrayLike, p: npt.ArrayLike,
              q: npt.ArrayLike) -> ReplayResult:
    """N servo ticks of ``state`` on ``model`` at once, at C++ speed with the GIL released (so
    that threads, each with its own state of one model, run in parallel): the same values,
    tick by tick, as N calls of cf.step(). ``t`` (N,) s, increasing and after the state's last
    tick; ``p`` (N, 3) mm; ``q`` (N, 4) w, x, y, z. Returns a cf.ReplayResult. Ctrl-C raises
    KeyboardInterrupt within a second; the state keeps the ticks it took."""
    return ReplayResult(_cf._step_many(model, state, t, p, q), [])
