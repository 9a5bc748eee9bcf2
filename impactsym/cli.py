"""The ``impactsym`` command (also ``python -m impactsym``)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="impactsym", description="Exact symbolic-numeric impact mechanics."
    )
    commands = parser.add_subparsers(dest="command", required=True)
    rep = commands.add_parser("reproduce", help="regenerate every figure, table and formula")
    rep.add_argument("--out", type=Path, required=True, help="output directory")
    rep.add_argument("--quick", action="store_true", help="coarse grids (seconds, for tests)")
    rep.add_argument("--force", action="store_true", help="overwrite a non-empty --out")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the process exit code."""
    args = build_parser().parse_args(argv)
    if args.command == "reproduce":
        from impactsym.reproduce import OutputExistsError, reproduce

        try:
            reproduce(args.out, quick=args.quick, force=args.force)
        except OutputExistsError as exc:
            print(f"impactsym: error: {exc}", file=sys.stderr)
            return 2
    return 0
