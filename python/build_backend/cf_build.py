"""The PEP 517 build backend of the Python package cf: `pip install .` from the source tree.

It drives the project's own CMake (the same targets and flags as every other build) and packs
what `cmake --install --component python` puts in site-packages into a wheel. It lives in the
tree (pyproject.toml's backend-path) and needs nothing from the package index: the machines it
is built on may have no route to one, and scikit-build-core, which does this job elsewhere, is
not a Debian package (docs/python.md, "Installing with pip").

Config settings (`pip install . --config-settings KEY=VALUE`, or the environment variables):
- build-dir (CF_WHEEL_BUILD_DIR): the CMake build tree to use or make. Default: the README's
  build/ when it is configured for this interpreter, Release and without sanitizers, else
  build/wheel-cpXY (made on first use: Release, no tests or benchmarks). A given tree is
  reused as configured, after checking that it was configured for this interpreter.
- jobs (CF_WHEEL_JOBS): parallel build jobs; default the machine's cores.
"""

import base64
import csv
import hashlib
import io
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tarfile
import tempfile
import zipfile

try:
    import tomllib  # Python 3.11
except ImportError:  # pragma: no cover - older interpreters with tomli installed
    import tomli as tomllib

_SOURCE = os.path.abspath(os.getcwd())  # pip runs the hooks in the source tree


class BuildError(RuntimeError):
    """A wheel that cannot be built, with the reason and what to do."""


def _project():
    with open(os.path.join(_SOURCE, "pyproject.toml"), "rb") as f:
        return tomllib.load(f)["project"]


def _version():
    text = open(os.path.join(_SOURCE, "cmake", "version.cmake"), encoding="utf-8").read()
    m = re.search(r"set\(CF_VERSION\s+([0-9]+\.[0-9]+\.[0-9]+)\)", text)
    if not m:
        raise BuildError("cmake/version.cmake: no 'set(CF_VERSION X.Y.Z)'")
    return m.group(1)


def _dist_name():
    return re.sub(r"[-_.]+", "_", _project()["name"]).lower()


def _metadata():
    p = _project()
    lines = ["Metadata-Version: 2.1", f"Name: {p['name']}", f"Version: {_version()}",
             f"Summary: {p['description']}", f"Requires-Python: {p['requires-python']}"]
    lines += [f"License: {p['license']['text']}"] if "license" in p else []
    lines += [f"Requires-Dist: {d}" for d in p.get("dependencies", [])]
    for extra, deps in p.get("optional-dependencies", {}).items():
        lines.append(f"Provides-Extra: {extra}")
        lines += [f"Requires-Dist: {d}; extra == \"{extra}\"" for d in deps]
    return "\n".join(lines) + "\n"


def _tag():
    impl = f"cp{sys.version_info.major}{sys.version_info.minor}"
    plat = re.sub(r"[^a-zA-Z0-9]", "_", sysconfig.get_platform())
    return f"{impl}-{impl}{sys.abiflags}-{plat}"


def _setting(config, key, env):
    value = (config or {}).get(key) or os.environ.get(env)
    return value if value else None


def _interpreter():
    # The interpreter itself, not a virtual environment's link to it: CMake records the path,
    # and pip's isolated build environment is deleted after the build.
    return os.path.realpath(sys.executable)


def _run(cmd, what):
    print("cf_build: " + " ".join(cmd), file=sys.stderr, flush=True)
    r = subprocess.run(cmd, cwd=_SOURCE)
    if r.returncode != 0:
        raise BuildError(f"{what} failed (exit {r.returncode}): {' '.join(cmd)}")


def _cache(build_dir):
    """The CMake cache's entries (name: value), or None when the tree is not configured."""
    path = os.path.join(build_dir, "CMakeCache.txt")
    if not os.path.exists(path):
        return None
    entries = {}
    for line in open(path, encoding="utf-8", errors="replace"):
        m = re.match(r"([A-Za-z0-9_]+):[A-Z]+=(.*)$", line.rstrip("\n"))
        if m:
            entries[m.group(1)] = m.group(2)
    return entries


def _usable(cache):
    """A configured tree a wheel may come from: this interpreter's, optimised, no sanitizers."""
    return (cache is not None and os.path.realpath(cache.get("Python3_EXECUTABLE", "")) == _interpreter()
            and cache.get("CMAKE_BUILD_TYPE") == "Release" and cache.get("CF_SANITIZE", "OFF") == "OFF")


def _default_build_dir():
    # The README's build tree when it suits (a pip install after scripts/setup.sh takes
    # seconds), else a tree of the wheel's own.
    readme_tree = os.path.join(_SOURCE, "build")
    if _usable(_cache(readme_tree)):
        return readme_tree
    return os.path.join(_SOURCE, "build", f"wheel-cp{sys.version_info.major}{sys.version_info.minor}")


def _cmake_tree(config):
    """The configured build tree: the one given, or build/wheel-cpXY made on first use."""
    cmake = shutil.which("cmake")
    if not cmake:
        raise BuildError("cmake not found on PATH (Debian: apt install cmake; scripts/install-deps.sh)")
    build_dir = os.path.abspath(_setting(config, "build-dir", "CF_WHEEL_BUILD_DIR") or _default_build_dir())
    cache = _cache(build_dir)
    if cache is None:
        gen = ["-G", "Ninja"] if shutil.which("ninja") else []
        _run([cmake, "-S", _SOURCE, "-B", build_dir, *gen, "-DCMAKE_BUILD_TYPE=Release",
              "-DCF_BUILD_TESTS=OFF", "-DCF_BUILD_BENCH=OFF", "-DCF_BUILD_PYTHON=ON",
              f"-DPython3_EXECUTABLE={_interpreter()}"], "configuring the CMake build")
    elif os.path.realpath(cache.get("Python3_EXECUTABLE", "")) != _interpreter():
        raise BuildError(f"build tree '{build_dir}' was configured for Python "
                         f"'{cache.get('Python3_EXECUTABLE', '(none)')}', not for '{_interpreter()}' "
                         f"that pip runs; give another build-dir (--config-settings build-dir=DIR) "
                         f"or reconfigure it with -DPython3_EXECUTABLE={_interpreter()}")
    return cmake, build_dir


def _record_line(path, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return [path, f"sha256={digest}", str(len(data))]


def _dist_info(directory):
    name = f"{_dist_name()}-{_version()}.dist-info"
    os.makedirs(os.path.join(directory, name), exist_ok=True)
    with open(os.path.join(directory, name, "METADATA"), "w", encoding="utf-8") as f:
        f.write(_metadata())
    return name


def _site_packages(stage):
    for root, dirs, _ in os.walk(stage):
        if "cf" in dirs and os.path.exists(os.path.join(root, "cf", "__init__.py")):
            return root
    raise BuildError(f"cmake --install put no package cf under '{stage}'")


def _write_wheel(wheel_path, site, dist_info):
    record = []
    with zipfile.ZipFile(wheel_path, "w", zipfile.ZIP_DEFLATED) as z:
        def add(arcname, data, mode=0o644):
            info = zipfile.ZipInfo(arcname, date_time=(2020, 1, 1, 0, 0, 0))
            info.external_attr = (0o100000 | mode) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data)
            record.append(_record_line(arcname, data))

        for root, dirs, files in os.walk(site):
            dirs.sort()
            for name in sorted(files):
                full = os.path.join(root, name)
                rel = os.path.relpath(full, site).replace(os.sep, "/")
                with open(full, "rb") as f:
                    add(rel, f.read(), 0o755 if name.endswith(".so") else 0o644)
        add(f"{dist_info}/METADATA", _metadata().encode())
        wheel = ("Wheel-Version: 1.0\nGenerator: cf_build (python/build_backend)\n"
                 f"Root-Is-Purelib: false\nTag: {_tag()}\n")
        add(f"{dist_info}/WHEEL", wheel.encode())
        out = io.StringIO()
        w = csv.writer(out, lineterminator="\n")
        w.writerows(record)
        w.writerow([f"{dist_info}/RECORD", "", ""])
        z.writestr(zipfile.ZipInfo(f"{dist_info}/RECORD", date_time=(2020, 1, 1, 0, 0, 0)), out.getvalue())


def _source_files():
    """The files of the source tree an sdist holds: git's when it is a checkout (tracked files,
    as a fresh clone has them), else every file outside the build trees and node_modules."""
    try:
        out = subprocess.run(["git", "-C", _SOURCE, "ls-files", "-z"], capture_output=True, check=True).stdout
        return sorted(f for f in out.decode().split("\0") if f and os.path.isfile(os.path.join(_SOURCE, f)))
    except (OSError, subprocess.CalledProcessError):
        files = []
        for root, dirs, names in os.walk(_SOURCE):
            rel = os.path.relpath(root, _SOURCE)
            dirs[:] = sorted(d for d in dirs if not (rel == "." and d.startswith("build")) and d not in (".git", "node_modules"))
            files += [os.path.normpath(os.path.join(rel, n)) for n in sorted(names)]
        return files


# PEP 517 hooks.

def get_requires_for_build_sdist(config_settings=None):
    return []


def build_sdist(sdist_directory, config_settings=None):
    """The source tree as `cf_haptics-X.Y.Z.tar.gz` (its files under `cf_haptics-X.Y.Z/`, with
    PKG-INFO), from which `pip install` builds the wheel as from the tree itself."""
    base = f"{_dist_name()}-{_version()}"
    name = f"{base}.tar.gz"
    os.makedirs(sdist_directory, exist_ok=True)
    with tarfile.open(os.path.join(sdist_directory, name), "w:gz", format=tarfile.PAX_FORMAT) as tar:
        for rel in _source_files():
            tar.add(os.path.join(_SOURCE, rel), arcname=f"{base}/{rel}", recursive=False)
        data = _metadata().encode()
        info = tarfile.TarInfo(f"{base}/PKG-INFO")
        info.size, info.mode = len(data), 0o644
        tar.addfile(info, io.BytesIO(data))
    return name


def get_requires_for_build_wheel(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    return _dist_info(metadata_directory)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    cmake, build_dir = _cmake_tree(config_settings)
    jobs = _setting(config_settings, "jobs", "CF_WHEEL_JOBS") or str(os.cpu_count() or 1)
    _run([cmake, "--build", build_dir, "--target", "cf_python_package", "-j", jobs],
         "building the extensions")
    with tempfile.TemporaryDirectory(prefix="cf-wheel-") as stage:
        _run([cmake, "--install", build_dir, "--component", "python", "--prefix", stage],
             "installing the package into the wheel's staging directory")
        site = _site_packages(stage)
        dist_info = f"{_dist_name()}-{_version()}.dist-info"
        name = f"{_dist_name()}-{_version()}-{_tag()}.whl"
        os.makedirs(wheel_directory, exist_ok=True)
        _write_wheel(os.path.join(wheel_directory, name), site, dist_info)
    return name
