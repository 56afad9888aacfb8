#!/usr/bin/env bash
# Checks that every C++ source of the repository is formatted by .clang-format (clang-format
# 14, Debian bookworm's). Lists the files that are not and exits 1; `--fix` formats them.
#
#   bash scripts/format-check.sh          check (ctest runs this as the test `format`)
#   bash scripts/format-check.sh --fix    format in place
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
fmt="${CLANG_FORMAT:-$(command -v clang-format-14 || command -v clang-format || true)}"
if [[ -z "$fmt" ]]; then
  echo "format-check.sh: clang-format not found (bash scripts/install-deps.sh installs it)" >&2
  exit 1
fi
# The tracked sources in a clone; every source under the tree's own folders otherwise (an
# unpacked archive).
if git -C "$root" rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.cc')
else
  mapfile -t files < <(find libcf tools python tests bench fuzz examples \
    \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' -o -name '*.cc' \) | sort)
fi
case "${1:-}" in
  --fix) "$fmt" -i "${files[@]}"; exit 0 ;;
  "") ;;
  *) echo "format-check.sh: unknown option '$1' (--fix formats in place)" >&2; exit 2 ;;
esac
# Files in batches on every core; clang-format names each file that differs in its errors
# ("FILE:LINE:COL: error: code should be clang-formatted").
mapfile -t bad < <(printf '%s\0' "${files[@]}" |
  xargs -0 -n 16 -P "$(nproc 2>/dev/null || echo 2)" "$fmt" --dry-run --Werror 2>&1 |
  sed -n 's/^\(.*\):[0-9]*:[0-9]*: error: code should be clang-formatted.*/\1/p' | sort -u)
if ((${#bad[@]})); then
  echo "format-check.sh: ${#bad[@]} of ${#files[@]} files differ from .clang-format ($("$fmt" --version | head -1)):" >&2
  printf '  %s\n' "${bad[@]}" >&2
  echo "format-check.sh: run 'bash scripts/format-check.sh --fix' to format them" >&2
  exit 1
fi
echo "format-check.sh: ${#files[@]} files formatted"
