"""CfGraph.to_networkx (needs networkx, Debian python3-networkx)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ._cf import CfGraph


def to_networkx(graph: CfGraph) -> Any:
    """The graph as a networkx.DiGraph.

    Nodes are CF ids with attributes ``pcs`` (the 'type:a:b;...' string), ``num_pcs``,
    ``dof``, ``translation_dof``, ``pure_rotation`` (None when not stored); edges are the
    transitions with attribute ``kind`` ('gain', 'lose', 'change').
    """
    try:
        import networkx as nx
    except ImportError as e:  # pragma: no cover - depends on the machine
        raise ImportError("CfGraph.to_networkx needs networkx (Debian: python3-networkx)") from e
    g = nx.DiGraph()
    for c in graph.cfs:
        g.add_node(c.id, pcs=c.pcs_string, num_pcs=len(c.pcs), dof=c.dof, translation_dof=c.translation_dof,
                   pure_rotation=c.pure_rotation)
    frm, to, kind = graph.transition_arrays()
    g.add_edges_from((int(a), int(b), {"kind": str(k)}) for a, b, k in zip(frm, to, kind))
    return g
