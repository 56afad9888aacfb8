"""``python -m cf --version``: the package's version and the graph format it reads."""

from __future__ import annotations

import argparse
import sys

import cf


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m cf", description=cf.__doc__.splitlines()[0] if cf.__doc__ else None)
    ap.add_argument("--version", action="store_true", help="print the version and exit")
    args = ap.parse_args(argv)
    if args.version:
        print(f"cf {cf.__version__} (graph format {cf.graph_format_version})")
        return 0
    ap.print_help()
    return 0


if __name__ == "__main__":
    sys.exit(main())
