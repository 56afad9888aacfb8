"""cf: contact formations of two rigid polyhedra, from Python.

The C++ library libcf and the project's tools, bound with pybind11 (docs/python.md):

- ``cf.load_model(path, units="mm")``: a model's features (``cf.Polyhedron``: vertices,
  edges, faces as numpy arrays);
- ``cf.load_graph(path)``: a CF graph file, JSON or CBOR (``cf.CfGraph``: CFs with PCs,
  witnesses and freedoms, transitions, ``cf_of``, ``neighbours``, ``to_networkx``);
- ``cf.generate(a_path, b_path, **options)``: a new graph through cfgen's generator;
- ``cf.Renderer(graph, **params).step(t, p, q)``: one servo tick;
- ``cf.replay(graph, t, p, q, **params)``: cfreplay's loop over numpy arrays of poses.

Units are mm, N, kg, N mm and s; poses are x_B = R x_A + p with R the unit quaternion
q = (w, x, y, z). Bad input raises ``cf.Error`` (a ValueError) with libcf's message; a file
that cannot be read or written as such raises ``cf.FileError``, both a cf.Error and an OSError.
"""

import os as _os
import tempfile as _tempfile

from . import _cf
from ._cf import Cf, CfGraph, CfModel, CfState, Error, FileError, Params, Pc, Polyhedron, Renderer, step
from ._cf import __version__, graph_format_version
from ._replay import ReplayResult, read_trajectory
from ._networkx import to_networkx as _to_networkx

HAVE_TOOLS = _cf.HAVE_TOOLS

__all__ = [
    "Cf", "CfGraph", "CfModel", "CfState", "Error", "FileError", "Params", "Pc", "Polyhedron",
    "Renderer", "ReplayResult", "step", "step_many",
    "generate", "load_graph", "load_model", "read_trajectory", "replay", "HAVE_TOOLS",
]


def load_graph(path, validate_schema=True, full_schema_check=False):
    """Loads a CF graph file (JSON, or CBOR when the name ends in .cbor).

    The file is checked against the schema (schemas/cf-graph.schema.json) and for internal
    consistency, as every tool does (cf::CfGraph::load); ``full_schema_check`` also runs the
    schema validator over every CF and transition (slower). Raises cf.Error naming the file,
    the JSON pointer and the problem.
    """
    g = _cf.load_graph(_os.fspath(path), validate_schema, full_schema_check)
    g._source_path = _os.fspath(path)  # an input that ReplayResult.to_csv never overwrites
    return g


def load_model(path, units="mm", coplanar_rel_tol=None, check_self_intersection=True, name=""):
    """Reads a polyhedral model (OFF, OBJ, STL or PLY) and extracts its features.

    ``units`` is the file's length unit ('mm', 'cm', 'm' or 'in'); the returned
    cf.Polyhedron is in mm, indexed as cfgen indexes it (cfgen --features). Needs the CGAL
    tools (cf.HAVE_TOOLS). Raises cf.Error naming the file and the problem.
    """
    if not HAVE_TOOLS:
        raise Error("load_model: this build of cf has no model loader (configured with CF_WITH_CGAL=OFF)")
    kwargs = {} if coplanar_rel_tol is None else {"coplanar_rel_tol": coplanar_rel_tol}
    return _cf.load_model(_os.fspath(path), units=units, check_self_intersection=check_self_intersection,
                          name=name, **kwargs)


def generate(a_path, b_path, output=None, **options):
    """Generates the CF graph of A (moving) against B (fixed) with cfgen's generator.

    Writes the graph file ``output`` when given (JSON, or CBOR when it ends in .cbor;
    whole or not at all) and returns the graph, the same bytes as
    ``cfgen A B -o output``. Options are cfgen's, by their C++ names: ``threads`` (0: all
    cores), ``max_pcs`` (1..3), ``touch_tol``, ``min_clearance``, ``good_clearance``,
    ``min_margin`` (relative to the smaller model's bounding-box diagonal), ``angle_margin``
    (rad), ``theta_samples``, ``max_rotations``, ``units``, ``units_a``, ``units_b``,
    ``coplanar_rel_tol``, ``symmetry`` (default True: one search per orbit of the models'
    symmetries; False is ``--no-symmetry``), ``thorough`` (default False; True is
    ``--thorough``: every set searched, then every image of each CF added), ``quiet`` (default True: no progress on stderr),
    ``checkpoint`` (a directory: ``--checkpoint``, finished work kept there and resumed by the
    same call; without it no checkpoint is kept, as ``--no-checkpoint``), ``certificates`` (a
    file: ``--certificates``, every failed candidate set with its outcome and evidence,
    docs/certificates.md). Ctrl-C stops the run between tasks and raises KeyboardInterrupt;
    with ``checkpoint``, the chunks finished so far are kept for the next call.
    Raises cf.Error for bad models or options.
    """
    if not HAVE_TOOLS:
        raise Error("generate: this build of cf has no generator (configured with CF_WITH_CGAL=OFF)")
    a_path, b_path = _os.fspath(a_path), _os.fspath(b_path)
    for path in ("checkpoint", "certificates"):
        if path in options:
            if options[path] is None:
                del options[path]
            else:
                options[path] = _os.fspath(options[path])
    if output is not None:
        _cf.generate(a_path, b_path, _os.fspath(output), **options)
        return load_graph(output)
    with _tempfile.TemporaryDirectory(prefix="cf-generate-") as tmp:
        out = _os.path.join(tmp, "graph.cbor")
        _cf.generate(a_path, b_path, out, **options)
        return load_graph(out)


def replay(graph, t, p, q, params=None, **kwargs):
    """Replays a trajectory of A through the renderer: cfreplay's loop, at C++ speed.

    ``t`` (N,) times in s, strictly increasing; ``p`` (N, 3) translations in mm; ``q``
    (N, 4) unit quaternions w, x, y, z (normalised as cfreplay does; |q| must be 1 within
    1e-3). Parameters: a cf.Params and/or keyword arguments with cf::Params' names and
    units (mass_kg, contact_stiffness_N_per_mm, mu_static, epsilon_mm, ...). A fresh renderer steps
    over every pose (cf::Replay, the engine cfreplay runs); the result is a
    cf.ReplayResult whose arrays are named like cf::HapticResult's fields. Ctrl-C raises
    KeyboardInterrupt within a second.
    """
    inputs = [getattr(graph, "_source_path", None)]
    return ReplayResult(_cf.replay(graph, t, p, q, params, **kwargs), [i for i in inputs if i])


def _save(self, path):
    """Writes the graph (JSON, or CBOR when the name ends in .cbor) through a temporary file and
    a rename, so that the file is whole or absent (cf::CfGraph::save)."""
    self._save(_os.fspath(path))


CfGraph.save = _save
CfGraph.to_networkx = _to_networkx


def _step_many(self, t, p, q):
    """N servo ticks at once, at C++ speed (the GIL released): the renderer's state carries
    on from the ticks before, and on to the next. ``t`` (N,) s, increasing and after the
    last step; ``p`` (N, 3) mm; ``q`` (N, 4) w, x, y, z. Returns a cf.ReplayResult: the same
    values, tick by tick, as N calls of step(). Ctrl-C raises KeyboardInterrupt within a second;
    the renderer keeps the ticks it took."""
    return ReplayResult(self._step_many(t, p, q), [])


Renderer.step_many = _step_many


def step_many(model, state, t, p, q):
    """N servo ticks of ``state`` on ``model`` at once, at C++ speed with the GIL released (so
    that threads, each with its own state of one model, run in parallel): the same values,
    tick by tick, as N calls of cf.step(). ``t`` (N,) s, increasing and after the state's last
    tick; ``p`` (N, 3) mm; ``q`` (N, 4) w, x, y, z. Returns a cf.ReplayResult. Ctrl-C raises
    KeyboardInterrupt within a second; the state keeps the ticks it took."""
    return ReplayResult(_cf._step_many(model, state, t, p, q), [])
