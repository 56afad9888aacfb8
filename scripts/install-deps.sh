#!/usr/bin/env bash
# Installs every Debian package that building and testing cf needs (Debian bookworm).
# Idempotent: when all packages are already installed it prints nothing and does nothing
# (not even apt-get update). Uses sudo only when not running as root.
#
#   bash scripts/install-deps.sh          install what is missing
#   bash scripts/install-deps.sh --list   print the package list and exit
#   bash scripts/install-deps.sh --check  exit 0 when everything is installed, 1 otherwise
#
# The list below is the single source of truth; docs/dependencies.md says why each is here.
set -euo pipefail

CF_APT_PACKAGES=(
  # build tools
  cmake ninja-build g++ ccache pkg-config
  # tools/ only: exact geometry and mesh IO (CGAL and its number types)
  libcgal-dev libgmp-dev libmpfr-dev
  # libcf (private): CF graph, graph and model files; public: small linear algebra
  libboost-dev libboost-graph-dev nlohmann-json3-dev libsimdjson-dev libeigen3-dev
  # tools/: command lines, JSON Schema checks
  libcli11-dev libvalijson-dev
  # tools/cfgen: linear programs of the witness search; `mpirun -n K cfgen` (Open MPI)
  libglpk-dev libopenmpi-dev openmpi-bin
  # tests/ and bench/
  catch2 libbenchmark-dev libfcl-dev
  # the sanitizer and fuzz build (scripts/sanitize.sh, scripts/fuzz.sh): clang, its
  # ASan/UBSan runtimes and libFuzzer (clang is only a recommendation of clang-14)
  clang clang-14 libclang-rt-14-dev libfuzzer-14-dev
  # the formatting check of every C++ source (scripts/format-check.sh, the ctest test format)
  clang-format-14
  # cfinspect --html: the browser test of the viewer (tools/cfinspect/viewer, headless)
  chromium
  # python/: the Python package cf (pybind11 against Debian's /usr/bin/python3), its
  # pytest suite, the example's plots, graph.to_networkx(); the virtual environment the
  # tests install the wheel into (python3-venv), the type check of its stubs (python3-mypy)
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib python3-networkx
  python3-venv python3-mypy
)
# The viewer's bundler and browser driver run on Node.js; Debian's nodejs and npm only when
# the machine has no node or npm (Debian's npm would conflict with another vendor's nodejs).
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  CF_APT_PACKAGES+=(nodejs npm)
fi

missing_packages() {
  local pkg status
  for pkg in "${CF_APT_PACKAGES[@]}"; do
    status=$(dpkg-query -W -f='${db:Status-Status}' "$pkg" 2>/dev/null || true)
    [[ "$status" == "installed" ]] || printf '%s\n' "$pkg"
  done
}

case "${1:-}" in
  --list) printf '%s\n' "${CF_APT_PACKAGES[@]}"; exit 0 ;;
  --check|"") ;;
  -h|--help) sed -n '2,10p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
  *) echo "install-deps.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
esac

if ! command -v dpkg-query >/dev/null 2>&1; then
  echo "install-deps.sh: dpkg-query not found; this script supports Debian/Ubuntu (apt) only." >&2
  echo "install-deps.sh: install these by other means: ${CF_APT_PACKAGES[*]}" >&2
  exit 1
fi

mapfile -t missing < <(missing_packages)
if ((${#missing[@]} == 0)); then
  exit 0
fi
if [[ "${1:-}" == "--check" ]]; then
  echo "install-deps.sh: missing packages: ${missing[*]}" >&2
  exit 1
fi

SUDO=()
if [[ "$(id -u)" -ne 0 ]]; then
  if ! command -v sudo >/dev/null 2>&1; then
    echo "install-deps.sh: not root and sudo is not available; as root run:" >&2
    echo "  apt-get update && apt-get install -y --no-install-recommends ${missing[*]}" >&2
    exit 1
  fi
  SUDO=(sudo)
fi

echo "install-deps.sh: installing ${#missing[@]} missing package(s): ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -qq
"${SUDO[@]}" env DEBIAN_FRONTEND=noninteractive \
  apt-get install -y -qq --no-install-recommends "${missing[@]}" </dev/null

mapfile -t still_missing < <(missing_packages)
if ((${#still_missing[@]} != 0)); then
  echo "install-deps.sh: still missing after apt-get install: ${still_missing[*]}" >&2
  exit 1
fi
echo "install-deps.sh: all ${#CF_APT_PACKAGES[@]} packages installed."
