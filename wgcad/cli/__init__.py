"""Command-line interface: ``wgcad COMMAND``, one module per subcommand (:data:`COMMANDS`), each only parsing its
flags, calling the library and printing; only the named command's module is imported."""

from __future__ import annotations

import argparse
import os
import sys

# The solvers' matrices are small (a few hundred rows): BLAS threads cost more than they save and, on a busy
# machine, thrash (benchmarks/elastic.py run with and without
# OPENBLAS_NUM_THREADS=1 shows it). Set before numpy loads; a user's own setting wins.
for _var in ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import importlib
import traceback

from .. import __version__
from ..errors import WgcadError
from .common import (  # noqa: F401
    COMMAND_HELP,
    EPILOG,
    EXIT_INPUT,
    EXIT_INTERFERENCE,
    EXIT_INTERNAL,
    EXIT_OK,
    TRACEBACK_ENV,
    Parser,
    Terminated,
    internal_error_line,
    signals_raise,
)
from .common import circle as _circle  # noqa: F401  (tests/test_cli.py reaches it here)

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_INTERFERENCE", "EXIT_INPUT", "EXIT_INTERNAL"]

#: the subcommands, each the module of this package named as the command, in the order the help lists them
COMMANDS = tuple(COMMAND_HELP)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The command line's parser: every subcommand's flags, or with ``command`` only that one's.

    A subcommand's module imports the pipeline it runs at its top, so registering all ten loads every model,
    exporter and the synthesis (~500 modules); :func:`main` registers only the command named on its command
    line (the others are listed, with their one line of help, for ``wgcad --help`` and for argparse's
    messages), so a command loads only its own pipeline.
    """
    p = Parser(
        prog="wgcad",
        description="Geometry, deformation and clearance of harmonic (strain-wave) drives.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--version", action="version", version=f"wgcad {__version__}", help="print the version and exit")
    p.add_argument(
        "--traceback",
        action="store_true",
        help=f"on an internal error (exit 3) also print the Python traceback on stderr (same as {TRACEBACK_ENV}=1)",
    )
    sub = p.add_subparsers(
        dest="command",
        required=True,
        parser_class=Parser,
        metavar="COMMAND",
        help="generate, audit, kinematics, ke, rating, sector, parts, sweep, design or templates; wgcad COMMAND --help for its flags",
    )
    for name in COMMANDS:
        if command is None or name == command:
            importlib.import_module(f"{__name__}.{name}").register(sub)
        else:
            sub.add_parser(name, help=COMMAND_HELP[name], add_help=False)
    # accepted after the subcommand too (wgcad audit D --traceback): users put it where the other flags are
    for sp in sub.choices.values():
        sp.add_argument(
            "--traceback",
            action="store_true",
            default=argparse.SUPPRESS,
            help="on an internal error (exit 3) also print the Python traceback on stderr",
        )
    return p


def _quiet_stdout() -> None:
    """After a broken pipe, point stdout at /dev/null so the interpreter's final flush stays silent."""
    try:
        fd = os.open(os.devnull, os.O_WRONLY)
        os.dup2(fd, sys.stdout.fileno())
        os.close(fd)
    except (OSError, ValueError, AttributeError):
        pass


def main(argv=None) -> int:
    """Entry point of the ``wgcad`` command; returns the exit code.

    Exit codes: 0 success, 1 a verdict failed (audit: interference, drift, the entry gap closing; sector, rating,
    design: each command's ``--help`` says what), 2 bad
    input (one line on stderr, nothing written), 3 internal error (one line
    asking for a report; the traceback with ``--traceback`` or
    ``WGCAD_TRACEBACK=1``), 4 the model could not answer (no convergence, or
    the drive outside it: one line, nothing written), 5 an optional extra the command needs is not installed (one
    line naming it: ``pip install 'wgcad[EXTRA]'``), 6 the results folder of ``sweep`` or ``design`` held by
    another live run, 128 + signal number when interrupted (SIGINT,
    SIGTERM, SIGHUP: temporary files are removed first).
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    # the command is the first word that is not a flag (the global flags take no value)
    named = next((a for a in argv if not a.startswith("-")), None)
    args = build_parser(named if named in COMMANDS else None).parse_args(argv)
    show_tb = args.traceback or os.environ.get(TRACEBACK_ENV, "") not in ("", "0")
    try:
        with signals_raise():
            return args.func(args)
    except WgcadError as e:
        print(f"wgcad: error: {' '.join(str(e).split())}", file=sys.stderr)
        return e.exit_code
    except Terminated as e:
        print(f"wgcad: stopped by {e.name}; temporary files removed, no file half-written", file=sys.stderr)
        return 128 + e.signum
    except KeyboardInterrupt:
        print("wgcad: interrupted; temporary files removed, no file half-written", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader of our stdout went away (`wgcad audit --json - | head`): nothing more to say
        _quiet_stdout()
        return 141  # 128 + SIGPIPE, what a shell reports for a process killed by it
    except Exception as e:  # noqa: BLE001 (the one place that turns bugs into a clear exit)
        if show_tb:
            traceback.print_exc()
        print(internal_error_line(e), file=sys.stderr)
        return EXIT_INTERNAL


def run() -> None:
    """The process entry point (``wgcad`` and ``python -m wgcad``): :func:`main`, then exit with its code.

    The output is flushed first, so a reader of stdout gone by the last flush gives 141, as one gone earlier.
    An interrupted run leaves by ``os._exit``: the clean-up has already run in :func:`main`, and a normal exit
    would let CPython's finalisation turn the exit into death by SIGINT (return code -2 instead of the documented
    130) whenever the Ctrl-C landed inside code that an extension ran through ``PyRun_*`` (measured: 2-5 of 40
    interrupted ``python -m wgcad generate`` runs).
    """
    code = _flush(main())
    if code > 128 and code != 141:  # 128 + SIGINT, SIGTERM or SIGHUP (141, SIGPIPE, closed its stdout)
        os._exit(code)
    sys.exit(code)


def _flush(code: int) -> int:
    """Flush stdout and stderr; 141 if the reader of stdout has gone."""
    try:
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_stdout()
        code = 141
    except (OSError, ValueError, AttributeError):
        pass
    try:
        sys.stderr.flush()
    except (OSError, ValueError, AttributeError):
        pass
    return code


if __name__ == "__main__":  # pragma: no cover
    run()
