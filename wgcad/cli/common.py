"""What every subcommand shares: the parser class, flag converters, exit codes, output folders, the progress bar."""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import signal
import sys
from pathlib import Path

from ..errors import WgcadError
from .progress import Progress

__all__ = [
    "EXIT_OK",
    "EXIT_INTERFERENCE",
    "EXIT_INPUT",
    "EXIT_INTERNAL",
    "EXIT_MODEL",
    "EPILOG",
    "epilog",
    "TRACEBACK_ENV",
    "Parser",
    "angles_deg",
    "positive_float",
    "angle_count",
    "out_dir",
    "circle",
    "Progress",
    "Terminated",
    "signals_raise",
    "internal_error_line",
    "want_progress",
    "add_memory_flag",
]

EXIT_OK = 0
EXIT_INTERFERENCE = 1  # reserved for `wgcad audit`: interference found or baseline drift
EXIT_INPUT = 2  # bad design file, flag or output path; nothing written
EXIT_INTERNAL = 3  # an unexpected error inside wgcad (a bug): one line, a request for a report
EXIT_MODEL = 4  # valid input the model could not answer: it did not converge or the drive is outside it

#: set to 1 to get the Python traceback of an internal error (same as --traceback)
TRACEBACK_ENV = "WGCAD_TRACEBACK"

_CODES = {
    0: "success",
    2: "bad input: design file, flag, or output path (one-line message, nothing written)",
    3: f"internal error: a bug in wgcad (one-line message; --traceback or {TRACEBACK_ENV}=1 shows the traceback)",
    4: "the model could not answer: it did not converge, or the drive lies outside what it represents (one\n"
    "       line saying what to change; the input itself is valid; nothing written)",
}
_SIGNALS = (
    "  130  interrupted (Ctrl-C); 143 SIGTERM; 129 SIGHUP: temporary files removed, nothing half-written\n"
    "  141  standard output closed by its reader (e.g. | head)\n"
)


def epilog(one: str | None = None, model: str | None = None, four: str | None = None) -> str:
    """The exit codes a command can return, for its ``--help``: 1 only where the command has a verdict (``one``
    says what it means), 4 only where a model can fail to answer (``model`` says when) or, ``four``, what 4
    means for this command instead."""
    lines = ["exit codes:", f"  0    {_CODES[0]}"]
    if one:
        lines.append(f"  1    {one}")
    lines += [f"  2    {_CODES[2]}", f"  3    {_CODES[3]}"]
    if model:
        lines.append(f"  4    {_CODES[4]} ({model})")
    elif four:
        lines.append(f"  4    {four}")
    return "\n".join(lines) + "\n" + _SIGNALS


#: every code of every command (the top-level help)
EPILOG = epilog(
    one="a verdict failed: interference or drift from --baseline (audit), the entry gap closes (audit --torque-nm), "
    "teeth meet tip to tip (sector)",
    model="the elastic model (--torque-nm), a KE of teeth that never touch",
)


def terminal_columns() -> int:
    """``shutil.get_terminal_size().columns`` without loading ``shutil`` (and with it ``zlib``, ``bz2`` and
    ``lzma``, ~1.7 ms of every start): ``COLUMNS`` if a positive integer, else the width of the terminal on
    standard output, else 80."""
    try:
        columns = int(os.environ["COLUMNS"])
    except (KeyError, ValueError):
        columns = 0
    if columns <= 0:
        try:
            columns = os.get_terminal_size(sys.__stdout__.fileno()).columns
        except (AttributeError, ValueError, OSError):
            columns = 0
    return columns or 80


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit code 2, no usage dump."""

    def error(self, message):  # noqa: D401
        self.exit(EXIT_INPUT, f"wgcad: error: {message}\n")

    def _get_formatter(self):
        # argparse makes a formatter for every flag it adds (to check the flag's metavar); the width argparse
        # itself would take (the terminal's less 2), from terminal_columns
        return self.formatter_class(prog=self.prog, width=terminal_columns() - 2)


class _UsageError(WgcadError, ValueError):
    pass


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP turned into an exception, so the same clean-up as Ctrl-C runs (temporary files removed)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum
        self.name = signal.Signals(signum).name


@contextlib.contextmanager
def signals_raise():
    """While active, SIGTERM and SIGHUP raise :class:`Terminated` in the main thread (SIGINT already raises)."""

    def handler(signum, frame):
        raise Terminated(signum)

    saved = {}
    for name in ("SIGTERM", "SIGHUP"):
        sig = getattr(signal, name, None)
        if sig is None:  # pragma: no cover (Windows has no SIGHUP)
            continue
        try:
            saved[sig] = signal.signal(sig, handler)
        except ValueError:  # not the main thread: leave the handlers alone
            break
    try:
        yield
    finally:
        for sig, old in saved.items():
            signal.signal(sig, old)


def internal_error_line(exc: BaseException) -> str:
    """One line for an unexpected exception: what, where in wgcad, and what to do."""
    import traceback

    what = " ".join(str(exc).split()) or "(no message)"
    if len(what) > 200:
        what = what[:197] + "..."
    where = ""
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if f"{os.sep}wgcad{os.sep}" in f.filename]
    if frames:
        f = frames[-1]
        rel = f.filename[f.filename.rfind(f"{os.sep}wgcad{os.sep}") + 1 :]
        where = f" at {rel}:{f.lineno}"
    kind = type(exc).__name__
    if isinstance(exc, MemoryError):
        what = "out of memory" + ("" if what == "(no message)" else f" ({what})")
    return (
        f"wgcad: internal error: {kind}: {what}{where}; this is a bug in wgcad, please report it with the design "
        f"file and the command (run with --traceback or {TRACEBACK_ENV}=1 to print the traceback on stderr)"
    )


def want_progress(flag: bool) -> bool:
    """The bar is drawn when asked for, or when stderr is a terminal."""
    if flag:
        return True
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def angles_deg(text: str) -> list[float]:
    out = []
    for part in text.split(","):
        part = part.strip()
        try:
            val = float(part)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{part}' is not a number (degrees, comma separated)") from None
        if not -3600.0 <= val <= 3600.0:
            raise argparse.ArgumentTypeError(f"{val:g} deg is outside [-3600, 3600]")
        if val == 0.0:
            val = 0.0  # -0 is 0
        if val not in out:
            out.append(val)
    return out


def positive_float(lo: float, hi: float, unit: str):
    def conv(text: str) -> float:
        try:
            val = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
        if not lo < val <= hi:
            raise argparse.ArgumentTypeError(f"must be in ({lo:g}, {hi:g}] {unit}, got {val:g}")
        return val

    return conv


def key_float(table: str, key: str):
    """An argparse type for a flag that sets design key ``[table] key``: the key's own bounds and unit
    (:mod:`wgcad.design.rules`), so a flag and its key accept the same values. The schema is read only when the
    flag is given (``wgcad --help`` stays light)."""

    def conv(text: str) -> float:
        from dataclasses import fields

        from ..design.rules import key_meta
        from ..design.schema import TABLES

        meta = key_meta(next(f for f in fields(TABLES[table]) if f.name == key))
        lo, hi, unit = float(meta["lo"]), float(meta["hi"]), meta.get("unit") or ""
        try:
            val = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
        if not (math.isfinite(val) and lo <= val <= hi):
            raise argparse.ArgumentTypeError(
                f"must be in [{lo:g}, {hi:g}] {unit} (as the key [{table}] {key}), got {val:g}"
            )
        return val

    return conv


def whole_number(lo: int, hi: int, what: str, words: dict | None = None):
    """An argparse type: a whole number in ``lo..hi`` of ``what``, or one of ``words`` (word -> value)."""

    def conv(text: str):
        if words and text in words:
            return words[text]
        try:
            n = int(text)
        except ValueError:
            alt = "".join(f" nor '{w}'" for w in words) if words else ""
            raise argparse.ArgumentTypeError(
                f"'{text}' is {'neither' if words else 'not'} a whole number{alt}"
            ) from None
        if not lo <= n <= hi:
            alt = "".join(f" or '{w}'" for w in words) if words else ""
            raise argparse.ArgumentTypeError(f"must be {lo}..{hi} {what}{alt}, got {n}")
        return n

    return conv


angle_count = whole_number(4, 3_600_000, "angles per revolution")


def add_memory_flag(parser) -> None:
    """``--max-memory-mb``: the memory budget a run is judged against before it starts (wgcad.design.budget)."""
    from ..design.budget import DEFAULT_MAX_MEMORY_MB

    parser.add_argument(
        "--max-memory-mb",
        type=positive_float(0.0, 1e7, "MB"),
        default=DEFAULT_MAX_MEMORY_MB,
        help=f"refuse a run whose estimated memory exceeds this, MB (default {DEFAULT_MAX_MEMORY_MB:g})",
    )


def out_dir(args, design_path: str) -> Path:
    return Path(args.out) if args.out else Path("output") / Path(design_path).stem


def circle(radius: float, tol: float):
    """The rim circle as a polygon within ``tol`` (mm): :func:`wgcad.plane.circle_polygon`."""
    from ..plane import circle_polygon

    return circle_polygon(radius, tol)
