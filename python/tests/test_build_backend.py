"""The wheel backend's choice of build tree (python/build_backend/cf_build.py), on fake trees:
no CMake runs here (the ctest fixture python:wheel runs the whole backend through pip)."""

import os
import subprocess
import sys

from conftest import SOURCE

BACKEND = SOURCE / "python" / "build_backend"


def backend(cwd, code):
    """Runs `code` with the backend imported in `cwd` (pip runs the hooks in the source tree)."""
    env = {**os.environ, "PYTHONPATH": str(BACKEND)}
    env.pop("CF_WHEEL_BUILD_DIR", None)
    return subprocess.run([sys.executable, "-c", "import cf_build as b\n" + code], cwd=cwd, env=env,
                          capture_output=True, text=True)


def fake_tree(path, python, build_type="Release", sanitize="OFF"):
    path.mkdir(parents=True)
    (path / "CMakeCache.txt").write_text(f"Python3_EXECUTABLE:FILEPATH={python}\nCMAKE_BUILD_TYPE:STRING={build_type}\n"
                                         f"CF_SANITIZE:BOOL={sanitize}\n")


def test_the_readme_build_tree_is_reused_only_when_it_suits(tmp_path):
    me = os.path.realpath(sys.executable)
    tag = f"cp{sys.version_info.major}{sys.version_info.minor}"
    for build_type, sanitize, python, reused in (("Release", "OFF", me, True), ("Debug", "OFF", me, False),
                                                 ("Release", "ON", me, False), ("Release", "OFF", "/no/python", False)):
        src = tmp_path / f"{build_type}-{sanitize}-{reused}-{python.count('/')}"
        fake_tree(src / "build", python, build_type, sanitize)
        out = backend(src, "print(b._default_build_dir())")
        assert out.returncode == 0, out.stderr
        want = src / "build" if reused else src / "build" / f"wheel-{tag}"
        assert os.path.realpath(out.stdout.strip()) == os.path.realpath(want), (build_type, sanitize, python)


def test_a_tree_configured_for_another_interpreter_is_refused(tmp_path):
    fake_tree(tmp_path / "other", "/opt/python3.9/bin/python3")
    out = backend(tmp_path, f"b._cmake_tree({{'build-dir': {str(tmp_path / 'other')!r}}})")
    assert out.returncode == 1
    msg = out.stderr.strip().splitlines()[-1]
    assert msg.startswith(f"cf_build.BuildError: build tree '{tmp_path / 'other'}' was configured for Python "
                          f"'/opt/python3.9/bin/python3', not for '{os.path.realpath(sys.executable)}' that pip runs")
    assert "--config-settings build-dir=DIR" in msg


def test_wheel_tag_and_metadata():
    out = backend(SOURCE, "print(b._tag()); print(b._metadata())")
    assert out.returncode == 0, out.stderr
    tag, *meta = out.stdout.splitlines()
    impl = f"cp{sys.version_info.major}{sys.version_info.minor}"
    assert tag.startswith(f"{impl}-{impl}") and tag.count("-") == 2
    assert "Name: cf-haptics" in meta and "Requires-Dist: numpy>=1.21" in meta
    assert 'Requires-Dist: networkx; extra == "graphs"' in meta
