"""cf.gen: cfgen's generator and model loader, from Python.

The build-time half of the project (tools/), apart from the run-time package ``cf`` so that
a haptic application that imports ``cf`` links libcf alone (docs/python.md):

- ``cf.gen.load_model(path, units="mm")``: a model's features (``cf.Polyhedron``: vertices,
  edges, faces as numpy arrays);
- ``cf.gen.generate(a_path, b_path, output=None, **options)``: a new graph through cfgen's
  generator, handed to ``cf`` in memory as a ``cf.CfGraph``.

Errors are ``cf.Error`` and ``cf.FileError``, with the messages cfgen prints. Importing this
module raises ImportError when cf was built without the CGAL tools.
"""

from __future__ import annotations

import os as _os
from typing import TYPE_CHECKING, Any

from .. import CfGraph, Error, FileError, Polyhedron  # noqa: F401  (the errors this module raises)

try:
    from . import _gen
except ImportError as _e:  # pragma: no cover - a build without the tools
    raise ImportError(
        "cf.gen: this build of cf has no generator or model loader (built without the CGAL tools, "
        "CF_BUILD_TOOLS=OFF or CF_WITH_CGAL=OFF)") from _e

if TYPE_CHECKING:
    import os

__all__ = ["generate", "load_model"]


def load_model(path: str | os.PathLike[str], units: str = "mm", coplanar_rel_tol: float | None = None,
               check_self_intersection: bool = True, name: str = "",
               crease_angle_deg: float | None = None) -> Polyhedron:
    """Reads a polyhedral model (OFF, OBJ, STL or PLY) and extracts its features.

    ``units`` is the file's length unit ('mm', 'cm', 'm' or 'in'); the returned
    cf.Polyhedron is in mm, indexed as cfgen indexes it (cfgen --features).
    ``coplanar_rel_tol`` and ``crease_angle_deg`` (degrees) decide which facets merge into one
    face, as cfgen's ``--coplanar-tol`` and ``--crease-angle`` (None: their defaults). Raises
    cf.Error naming the file and the problem (cf.FileError when it cannot be read).
    """
    kwargs: dict[str, Any] = {} if coplanar_rel_tol is None else {"coplanar_rel_tol": coplanar_rel_tol}
    if crease_angle_deg is not None:
        kwargs["crease_angle_deg"] = crease_angle_deg
    return _gen.load_model(_os.fspath(path), units=units, check_self_intersection=check_self_intersection,
                           name=name, **kwargs)


def generate(a_path: str | os.PathLike[str], b_path: str | os.PathLike[str],
             output: str | os.PathLike[str] | None = None, **options: Any) -> CfGraph:
    """Generates the CF graph of A (moving) against B (fixed) with cfgen's generator.

    Returns the graph as a cf.CfGraph, handed over in memory; with ``output`` it also writes
    the graph file (JSON, or CBOR when it ends in .cbor; whole or not at all), the same bytes
    as ``cfgen A B -o output``. Options are cfgen's, by their C++ names: ``threads`` (0: all
    cores), ``max_pcs`` (1..3), ``touch_tol``, ``min_clearance``, ``good_clearance``,
    ``min_margin`` (relative to the smaller model's bounding-box diagonal), ``angle_margin``
    (rad), ``theta_samples``, ``max_rotations``, ``units``, ``units_a``, ``units_b``,
    ``coplanar_rel_tol``, ``crease_angle_deg``, ``symmetry`` (default True: one search per orbit of the models'
    symmetries; False is ``--no-symmetry``), ``thorough`` (default False; True is
    ``--thorough``: every set searched, then every image of each CF added), ``quiet`` (default
    True: no progress on stderr), ``checkpoint`` (a directory: ``--checkpoint``, finished work
    kept there and resumed by the same call; without it no checkpoint is kept, as
    ``--no-checkpoint``), ``certificates`` (a file: ``--certificates``, every failed candidate
    set with its outcome and evidence, docs/certificates.md), ``cube_cells`` (default 0:
    ``--cube-cells``, the cells of rotation space each failed set without an f-f PC may take to
    be refuted), ``resolution`` (default 1.5e-5: ``--resolution``, rad, and in units of D in
    translation, below which the decision's cells are not split). Ctrl-C stops the run between
    tasks and raises KeyboardInterrupt; with ``checkpoint``, the chunks finished so far are
    kept for the next call. Raises cf.Error for bad models or options.
    """
    a, b = _os.fspath(a_path), _os.fspath(b_path)
    for path in ("checkpoint", "certificates"):
        if path in options:
            if options[path] is None:
                del options[path]
            else:
                options[path] = _os.fspath(options[path])
    out = "" if output is None else _os.fspath(output)
    g = _gen.generate(a, b, out, **options)
    if out:
        setattr(g, "_source_path", out)  # an input that ReplayResult.to_csv never overwrites
    return g
