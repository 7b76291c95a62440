"""Command-line interface: ``wgcad generate``, ``audit`` and ``kinematics``, one module per subcommand (heavy modules imported lazily)."""

from __future__ import annotations

import argparse
import sys

from .. import __version__
from ..errors import WgcadError
from . import audit, generate, kinematics, parts
from .common import EPILOG, EXIT_INPUT, EXIT_INTERFERENCE, EXIT_OK, Parser, circle as _circle  # noqa: F401

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_INTERFERENCE", "EXIT_INPUT"]


def build_parser() -> argparse.ArgumentParser:
    p = Parser(prog="wgcad", description="Geometry, deformation and clearance of harmonic (strain-wave) drives.",
               epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"wgcad {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    for mod in (generate, audit, kinematics, parts):
        mod.register(sub)
    return p


def main(argv=None) -> int:
    """Entry point of the ``wgcad`` command; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return args.func(args)
    except WgcadError as e:
        print(f"wgcad: error: {e}", file=sys.stderr)
        return e.exit_code
    except KeyboardInterrupt:
        print("wgcad: interrupted; nothing was written", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())