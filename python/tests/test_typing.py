"""The package's Python surface: a signature and a docstring on every public function and
method, and shipped type stubs that pass `mypy --strict` on the examples."""

import importlib
import inspect
import os
import pathlib
import subprocess
import sys

import pytest

import cf
from conftest import SOURCE


def public_callables():
    """(qualified name, object) of every public function of cf and cf.gen and every method of
    their classes, the dunder constructors included."""
    modules = [cf]
    try:
        modules.append(importlib.import_module("cf.gen"))
    except ImportError:  # built without the CGAL tools
        pass
    for mod in modules:
        for name in mod.__all__:
            obj = getattr(mod, name)
            if isinstance(obj, type):
                if issubclass(obj, BaseException):
                    continue
                for key, member in vars(obj).items():
                    if (key.startswith("_") and key != "__init__") or isinstance(member, property):
                        continue
                    yield f"{mod.__name__}.{name}.{key}", getattr(obj, key)
            elif callable(obj):
                yield f"{mod.__name__}.{name}", obj


def overloaded(obj):
    return "Overloaded function." in (obj.__doc__ or "")


def test_every_function_has_a_signature_and_a_docstring():
    seen = 0
    for name, obj in public_callables():
        seen += 1
        assert (obj.__doc__ or "").strip(), f"{name} has no docstring"
        if overloaded(obj):  # cf.Pc(spec) or cf.Pc(type, a, b): no one signature
            continue
        inspect.signature(obj)  # raises ValueError where there is none
    assert seen >= 30  # the walk reaches the classes (34 callables in 0.1.0)


def test_signatures_name_the_arguments_and_defaults():
    g = cf.load_graph(SOURCE / "data" / "graphs" / "cube_l_block.json")
    assert str(inspect.signature(cf.Renderer(g).step)) == "(t, p, q)"
    assert str(inspect.signature(cf.CfGraph.neighbours)) == "(self, id, kind=None)"
    assert str(inspect.signature(cf.load_graph)).startswith("(path: 'str | os.PathLike[str]', validate_schema: 'bool' = True")
    # The typed line pybind11 writes stays in the doc, under the signature.
    assert cf.CfGraph.neighbours.__doc__.startswith(
        "neighbours(self: cf._cf.CfGraph, id: int, kind: Optional[str] = None) -> List[int]")


def test_stubs_are_shipped_beside_the_extensions():
    root = pathlib.Path(cf.__file__).parent
    assert (root / "py.typed").exists()
    stub = (root / "_cf.pyi").read_text()
    assert "class CfGraph:" in stub and "def step(self, t: float, p: Any, q: Any) -> dict[str, Any]: ..." in stub
    assert "def save(self, path: str | os.PathLike[str]) -> None: ..." in stub  # the Python part's method


def test_mypy_strict_on_the_examples(tmp_path):
    pytest.importorskip("mypy", reason="mypy is not installed (Debian python3-mypy)")
    examples = sorted(str(p) for p in (SOURCE / "examples" / "python").glob("*.py"))
    assert examples
    # From a folder of its own (no package cf in the working directory), with the project's
    # configuration (pyproject.toml: strict), on the package this interpreter imports.
    r = subprocess.run([sys.executable, "-m", "mypy", "--config-file", str(SOURCE / "pyproject.toml"),
                        "--cache-dir", str(tmp_path / "cache"), *examples],
                       capture_output=True, text=True, cwd=tmp_path, env={**os.environ, "MYPYPATH": ""})
    assert r.returncode == 0, r.stdout + r.stderr
    # And it checks something: a call with a wrong type is an error.
    bad = tmp_path / "bad.py"
    bad.write_text("import cf\ng = cf.load_graph(3)\nx: int = g.cf(0).pcs_string\n")
    r = subprocess.run([sys.executable, "-m", "mypy", "--config-file", str(SOURCE / "pyproject.toml"),
                        "--cache-dir", str(tmp_path / "cache"), str(bad)], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode == 1 and 'Argument 1 to "load_graph" has incompatible type "int"' in r.stdout
    assert 'Incompatible types in assignment (expression has type "str", variable has type "int")' in r.stdout
