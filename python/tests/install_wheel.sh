#!/usr/bin/env bash
# The ctest fixture python:wheel: a virtual environment made from the interpreter the package
# is built for, with its system site packages (Debian's numpy, pytest, networkx, matplotlib),
# and `pip install` of the source tree into it through the in-tree backend, reusing the
# configured build tree (no network: --no-index; numpy is the system's). The Python tests
# then run with that environment's interpreter against the installed package.
#
#   install_wheel.sh PYTHON VENV SOURCE_DIR BUILD_DIR
set -euo pipefail
python=$1 venv=$2 source=$3 build=$4
rm -rf "$venv"
"$python" -m venv --system-site-packages "$venv"
"$venv/bin/python" -m pip install --no-index --disable-pip-version-check --quiet \
  --config-settings "build-dir=$build" "$source"
"$venv/bin/python" -m pip show --files cf-haptics | grep "cf/_cf\." > /dev/null
