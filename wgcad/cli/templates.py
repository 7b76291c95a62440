"""``wgcad templates``: list the bundled design, requirements and sweep files, or copy them into a folder."""

from __future__ import annotations

import argparse
import os
import textwrap

from ..bundled import copy_templates, template_root, templates
from ..errors import DesignError
from .common import COMMAND_HELP, EXIT_OK, epilog
from .outputs import write_stdout

__all__ = ["register", "cmd_templates"]


def cmd_templates(args) -> int:
    if args.copy is None:
        if args.names:
            raise DesignError("NAME", "names the templates to copy: give --copy DIR too")
        rows = templates()
        width = max(len(t.name) for t in rows)
        write_stdout(
            f"bundled templates in {template_root()}/ (wgcad templates --copy DIR [NAME ...] copies them):\n"
            + "".join(f"  {t.name:<{width}}  {t.kind:<12}  {t.title}\n" for t in rows)
        )
        return EXIT_OK
    written = copy_templates(args.copy, args.names or None)
    if not args.quiet:
        write_stdout(
            f"wrote {len(written)} templates to {args.copy}/: "
            + ", ".join(os.path.relpath(p, args.copy) for p in written)
            + "\n"
        )
    return EXIT_OK


def register(sub) -> None:
    """Add the subcommand to the ``wgcad`` parser's subparsers."""
    t = sub.add_parser(
        "templates",
        help=COMMAND_HELP["templates"],
        description=textwrap.fill(
            "List the design, requirements and sweep files bundled with wgcad (their name, kind and title), or copy "
            "them into a folder to start from: wgcad templates --copy my_designs d1_involute, then "
            "wgcad generate my_designs/d1_involute.toml. Sub-folders are kept (requirements/, sweeps/), so the "
            "design a requirements file or sweep names is copied with it and still found; an existing file is "
            "never replaced.",
            width=79,
        ),
        epilog=epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    t.add_argument("names", nargs="*", metavar="NAME", help="with --copy: only these templates (default: all)")
    t.add_argument("--copy", metavar="DIR", help="copy the templates into DIR (created if missing)")
    t.add_argument("--quiet", action="store_true", help="print nothing on success")
    t.set_defaults(func=cmd_templates)
