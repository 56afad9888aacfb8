#!/usr/bin/env bash
# Installs the npm packages of cfinspect's browser viewer (three.js, esbuild, playwright-core)
# into tools/cfinspect/viewer/node_modules with `npm ci`, exactly as its package-lock.json
# pins them. Idempotent and silent when node_modules already matches the lockfile. Run by
# scripts/setup.sh and scripts/test.sh after scripts/install-deps.sh (which installs
# Node.js and npm when missing). Without npm, cfinspect builds without --html.
set -euo pipefail

dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/tools/cfinspect/viewer"
stamp="$dir/node_modules/.cf-package-lock.json"  # the lockfile of the last npm ci

if [[ -f "$stamp" ]] && cmp -s "$dir/package-lock.json" "$stamp"; then
  exit 0
fi
if ! command -v npm >/dev/null 2>&1; then
  echo "install-npm.sh: npm not found; cfinspect will be built without the browser viewer (--html)" >&2
  exit 0
fi
echo "install-npm.sh: npm ci in $dir"
(cd "$dir" && npm ci --no-audit --no-fund --loglevel=error </dev/null)
cp "$dir/package-lock.json" "$stamp"
