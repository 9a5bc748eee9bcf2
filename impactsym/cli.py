"""The ``impactsym`` command (also ``python -m impactsym``).

* ``impactsym reproduce --out DIR [--quick] [--force]`` -- every figure, table and formula;
* ``impactsym latex NAME`` (``--list`` for the names) -- one formula, for pasting;
* ``impactsym export python FILE`` / ``impactsym export latex FILE`` -- generated files.
"""

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

    latex = commands.add_parser("latex", help="print one derived formula as LaTeX")
    latex.add_argument("name", nargs="?", help="formula label, e.g. sd-ridge-force-underdamped")
    latex.add_argument("--list", action="store_true", help="list the formula labels")

    export = commands.add_parser("export", help="write a generated file")
    export.add_argument(
        "kind", choices=["python", "latex"], help="python: NumPy-only module; latex: formulas.tex"
    )
    export.add_argument("file", type=Path, help="output file")
    return parser


def _run(args: argparse.Namespace) -> None:
    if args.command == "reproduce":
        from impactsym.reproduce import reproduce

        reproduce(args.out, quick=args.quick, force=args.force)
    elif args.command == "latex":
        from impactsym.export import formula, formula_names

        if args.list or args.name is None:
            print("\n".join(formula_names()))
        else:
            print(formula(args.name))
    else:
        from impactsym.export import write_latex_document, write_python_module

        writer = write_python_module if args.kind == "python" else write_latex_document
        print(f"wrote {writer(args.file)}")


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the process exit code (non-zero on any failure).

    >>> main(["latex", "sd-conditions"])
    g_\\mathrm{position} = z, \\qquad g_\\mathrm{force} = 2 D z' + z
    0
    """
    args = build_parser().parse_args(argv)
    try:
        _run(args)
    except (OSError, ValueError, RuntimeError) as exc:
        print(f"impactsym: error: {exc}", file=sys.stderr)
        return 2
    except Exception as exc:  # an unexpected failure: still a clear message and exit code
        print(f"impactsym: internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
        return 3
    return 0
