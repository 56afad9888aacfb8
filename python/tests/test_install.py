"""cmake --install puts a working package cf under PREFIX/lib/python3.X/site-packages."""

import os
import subprocess
import sys

import pytest

from conftest import DATA


def test_installed_package_imports_and_replays(tmp_path):
    cmake, binary = os.environ.get("CF_CMAKE"), os.environ.get("CF_PYTHON_BINARY_DIR")
    if not cmake or not binary:
        pytest.skip("CF_CMAKE and CF_PYTHON_BINARY_DIR are set by ctest")
    prefix = tmp_path / "prefix"
    subprocess.run([cmake, "--install", binary, "--prefix", str(prefix)], check=True, capture_output=True)
    site = prefix / "lib" / f"python{sys.version_info.major}.{sys.version_info.minor}" / "site-packages"
    assert (site / "cf" / "__init__.py").exists()
    code = ("import cf, numpy as np; g = cf.load_graph(%r); t, p, q = cf.read_trajectory(%r); "
            "r = cf.replay(g, t, p, q); print(cf.__file__); print(int((r.cf >= 0).sum()))"
            % (str(DATA / "graphs" / "cube_l_block.json"), str(DATA / "trajectories" / "cube_lblock_guarded.csv")))
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env["PYTHONPATH"] = str(site)
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True, env=env,
                         cwd=tmp_path).stdout.split()
    assert out[0].startswith(str(site)) and int(out[1]) > 100


def test_version_from_the_module_and_the_command_line():
    # The project's version (cmake/version.cmake), as the tools print it.
    import re

    import cf

    version = (DATA.parent / "cmake" / "version.cmake").read_text()
    want = re.search(r"CF_VERSION\s+\"?([0-9]+\.[0-9]+\.[0-9]+)", version).group(1)
    assert cf.__version__ == want and cf.graph_format_version == 1
    out = subprocess.run([sys.executable, "-m", "cf", "--version"], check=True, capture_output=True, text=True)
    assert out.stdout == f"cf {want} (graph format 1)\n"


def test_runtime_package_links_libcf_alone():
    # `import cf` loads the run-time extension only; the generator is cf.gen, a module of its
    # own, so CGAL's code (its names appear in every symbol of its templates) is not in cf._cf.
    import pathlib

    code = "import cf, sys; print(cf._cf.__file__); print(sorted(m for m in sys.modules if m.startswith('cf')))"
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    so, modules = out.splitlines()
    assert modules == str(sorted(["cf", "cf._cf", "cf._networkx", "cf._replay"]))
    data = pathlib.Path(so).read_bytes()
    assert b"CGAL" not in data and b"WitnessSearch" not in data
    gen = pytest.importorskip("cf.gen", reason="built without the CGAL tools")
    assert b"CGAL" in pathlib.Path(gen._gen.__file__).read_bytes()


def test_tests_run_against_the_installed_wheel():
    # ctest runs this suite with the interpreter of the virtual environment python:wheel made
    # and pip-installed the package into (CF_VENV): cf and cf.gen come from its site-packages,
    # with the distribution's metadata, not from the build tree.
    venv = os.environ.get("CF_VENV")
    if not venv:
        pytest.skip("CF_VENV is set by ctest")
    import importlib.metadata

    import cf

    assert os.path.realpath(sys.prefix) == os.path.realpath(venv)
    site = os.path.realpath(os.path.join(venv, "lib", f"python{sys.version_info.major}.{sys.version_info.minor}",
                                         "site-packages"))
    assert os.path.realpath(cf.__file__).startswith(site + os.sep)
    assert importlib.metadata.version("cf-haptics") == cf.__version__
    assert "numpy" in " ".join(importlib.metadata.requires("cf-haptics"))


def test_sdist_holds_the_tracked_sources_and_the_metadata(tmp_path):
    # The backend's build_sdist (PEP 517 requires it; `python -m build` calls it first): the
    # tracked files under cf_haptics-X.Y.Z/, PKG-INFO with the distribution's metadata, no
    # build tree.
    import tarfile

    from conftest import SOURCE

    code = f"import cf_build; print(cf_build.build_sdist({str(tmp_path)!r}))"
    env = {**os.environ, "PYTHONPATH": str(SOURCE / "python" / "build_backend")}
    name = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True, env=env,
                          cwd=SOURCE).stdout.strip()
    import cf

    base = f"cf_haptics-{cf.__version__}"
    assert name == f"{base}.tar.gz"
    with tarfile.open(tmp_path / name) as tar:
        names = set(tar.getnames())
        info = tar.extractfile(f"{base}/PKG-INFO").read().decode()
    for f in ("pyproject.toml", "CMakeLists.txt", "cmake/version.cmake", "python/build_backend/cf_build.py",
              "python/src/module.cpp", "libcf/include/cf/graph.hpp", "tools/cfgen/generate.cpp"):
        assert f"{base}/{f}" in names, f
    assert not any(n.startswith(f"{base}/build/") for n in names)
    assert "Name: cf-haptics\n" in info and f"Version: {cf.__version__}\n" in info
    assert "Requires-Dist: numpy>=1.21\n" in info
