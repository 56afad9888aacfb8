"""Shared fixtures of the tests of the Python package cf (run by ctest as python:pytest with
PYTHONPATH on the build tree's python/ folder, CF_SOURCE_DIR, CF_REPLAY_REF, CF_CFREPLAY,
CF_CFGEN set by python/CMakeLists.txt)."""

import os
import pathlib

import pytest

import cf

SOURCE = pathlib.Path(os.environ.get("CF_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
DATA = SOURCE / "data"

# Each bundled trajectory with the graph of its model pair.
TRAJECTORIES = {
    "cube_lblock_guarded": "cube_l_block",
    "cube_lblock_slide": "cube_l_block",
    "cube_lblock_corner": "cube_l_block",
    "cube_lblock_break": "cube_l_block",
    "cube_lblock_rotate": "cube_l_block",
    "cube_corner_seat": "cube_corner_block",
}


def tool(name):
    """The path of a built program from the environment (set by ctest), or skip."""
    path = os.environ.get(name)
    if not path or not os.path.exists(path):
        pytest.skip(f"{name} is not set to a built program (run through ctest)")
    return path


@pytest.fixture(scope="session")
def graphs():
    """The bundled graphs, loaded once."""
    return {name: cf.load_graph(DATA / "graphs" / f"{name}.json") for name in set(TRAJECTORIES.values())}


@pytest.fixture(scope="session")
def l_graph(graphs):
    return graphs["cube_l_block"]
