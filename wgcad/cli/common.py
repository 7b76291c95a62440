"""What every subcommand shares: the parser class, flag converters, exit codes, output folders, the progress bar."""

from __future__ import annotations

import argparse
import contextlib
import math
import os
import re
import signal
import sys
import traceback
from dataclasses import fields
from pathlib import Path

from ..design.budget import DEFAULT_MAX_MEMORY_MB
from ..design.rules import key_meta
from ..design.schema import TABLES
from ..errors import EXIT_BUSY, WgcadError
from ..extras import require
from ..plane import circle_polygon
from .bounds import bounded
from .progress import Progress

__all__ = [
    "EXIT_OK",
    "EXIT_INTERFERENCE",
    "EXIT_INPUT",
    "EXIT_INTERNAL",
    "EXIT_MODEL",
    "EXIT_DEPENDENCY",
    "EXIT_BUSY",
    "EPILOG",
    "epilog",
    "TRACEBACK_ENV",
    "Parser",
    "angles_deg",
    "flag_value",
    "positive_float",
    "angle_count",
    "out_dir",
    "circle",
    "Progress",
    "Terminated",
    "signals_raise",
    "internal_error_line",
    "want_progress",
    "require_picture_extras",
    "add_memory_flag",
    "scheduler_address",
]

#: every subcommand in the order the help lists them, with its one line there (the commands' modules are
#: imported only for the command that runs: wgcad.cli.build_parser)
COMMAND_HELP = {
    "generate": "write DXF, STL, <design>.report.json (and deformed-state DXF/PNG) for a design",
    "audit": "clearance and interference over the generator cycle; exit 1 on interference or baseline drift",
    "kinematics": "gear ratios; velocities of the external ring generator (CSV + PNG)",
    "ke": "no-load kinematic error, lost motion and the installation-angle lever of an imperfect drive",
    "rating": "datasheet: rated torque and the criterion that binds it, stresses, stiffness, ratcheting, bearing life",
    "sector": "discrete-motion drive: sectored rigid gear, variable tooth heights, motion law, audit",
    "parts": "write the parts a shop makes: cup flexspline, generator plug, rigid gear (DXF, SVG, STL, 3MF, STEP)",
    "sweep": "tolerance Monte Carlo or design study over a sweep spec, on Dask; resumable",
    "design": "search the free keys of a requirements file for drives that meet it; resumable, on Dask",
    "templates": "list the bundled templates, or copy them into a folder (--copy DIR)",
}


EXIT_OK = 0
EXIT_INTERFERENCE = 1  # a verdict failed (audit, sector, rating, design: each command's --help says which)
EXIT_INPUT = 2  # bad design file, flag or output path; nothing written
EXIT_INTERNAL = 3  # an unexpected error inside wgcad (a bug): one line, a request for a report
EXIT_MODEL = 4  # valid input the model could not answer: it did not converge or the drive is outside it
EXIT_DEPENDENCY = 5  # the command needs an optional extra that is not installed (the message names it)

#: set to 1 to get the Python traceback of an internal error (same as --traceback)
TRACEBACK_ENV = "WGCAD_TRACEBACK"

_CODES = {
    0: "success",
    2: "bad input: design file, flag, or output path (one-line message, nothing written)",
    3: f"internal error: a bug in wgcad (one-line message; --traceback or {TRACEBACK_ENV}=1 shows the traceback)",
    4: "the model could not answer: it did not converge, or the drive lies outside what it represents (one\n"
    "       line saying what to change; the input itself is valid; nothing written)",
}
_BUSY = "the results folder (--out) is held by another live run (one line naming its pid; nothing written)"
_SIGNALS = (
    "  130  interrupted (Ctrl-C); 143 SIGTERM; 129 SIGHUP: temporary files removed, nothing half-written\n"
    "  141  standard output closed by its reader (e.g. | head)\n"
)


def epilog(
    one: str | None = None,
    model: str | None = None,
    four: str | None = None,
    five: str | None = None,
    busy: bool = False,
) -> str:
    """The exit codes a command can return, for its ``--help``: 1 only where the command has a verdict (``one``
    says what it means), 4 only where a model can fail to answer (``model`` says when) or, ``four``, what 4
    means for this command instead; 5 where an optional extra is needed (``five`` says for what); 6 (``busy``)
    where the command holds its results folder."""
    lines = ["exit codes:", f"  0    {_CODES[0]}"]
    if one:
        lines.append(f"  1    {one}")
    lines += [f"  2    {_CODES[2]}", f"  3    {_CODES[3]}"]
    if model:
        lines.append(f"  4    {_CODES[4]} ({model})")
    elif four:
        lines.append(f"  4    {four}")
    if five:
        lines.append(f"  5    an optional extra is not installed ({five})")
    if busy:
        lines.append(f"  6    {_BUSY}")
    return "\n".join(lines) + "\n" + _SIGNALS


#: every code of every command (the top-level help)
EPILOG = epilog(
    one="a verdict failed: interference or drift from --baseline (audit), the entry gap closes (audit --torque-nm), "
    "teeth still meet with the built heights (sector), no rated torque: a criterion fails at no load (rating), no "
    "candidate met every requirement (design)",
    model="audit and ke with --torque-nm, rating: the elastic model; ke: teeth that never touch; sweep: the Dask "
    "cluster failed, the chunks done are kept, run again to resume",
    five="the command's optional extra: wgcad[plots] for pictures, [html] for --html, [sweep], [design], "
    "[cad] for STEP; the line names it",
    busy=True,
)


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit code 2, no usage dump, and negative numbers as values."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        # a word that starts with a minus and a digit is a value (-3000:0:500, -30,-15, -1e-3), not an unknown
        # option: argparse's own test takes only -N and -N.N (Python 3.13 widened it to this). No wgcad option
        # looks like a number, so nothing else changes; the inf and nan spellings are values too (refused by rule)
        self._negative_number_matcher = re.compile(r"^-(\.?\d|inf|nan)", re.IGNORECASE)

    def error(self, message):  # noqa: D401
        self.exit(EXIT_INPUT, f"wgcad: error: {message}\n")


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


def require_picture_extras(args) -> None:
    """``--plot`` needs matplotlib (``[plots]``), ``--html`` plotly (``[html]``): refused in one line (exit 5) before
    any work, rather than after minutes of it."""
    if getattr(args, "plot", None):
        require("plots", what="--plot")
    if getattr(args, "html", None):
        require("html", what="--html")


def scheduler_address(text: str) -> str:
    """The ``--scheduler`` flag of ``sweep`` and ``design``: a Dask scheduler's ``tcp://HOST:PORT`` (or ``tls://``)."""
    if not (text.startswith("tcp://") or text.startswith("tls://")) or ":" not in text[6:]:
        raise argparse.ArgumentTypeError(f"expected tcp://HOST:PORT (or tls://), got '{text}'")
    return text


def want_progress(flag: bool) -> bool:
    """The bar is drawn when asked for, or when stderr is a terminal."""
    if flag:
        return True
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def flag_value(parse, text: str):
    """``parse(text)`` as an argparse type: its :class:`~wgcad.errors.DesignError` becomes argparse's one-line refusal
    (``argument --FLAG: RULE``, exit 2), which argparse shows only for its own ArgumentTypeError."""
    from ..errors import DesignError

    try:
        return parse(text)
    except DesignError as e:
        raise argparse.ArgumentTypeError(e.rule) from None


def angles_deg(text: str) -> list[float]:
    """``--generator-angle``: degrees as a value, a comma list or START:STOP:STEP (:func:`wgcad.numbers.read_values`,
    at most :data:`~wgcad.constants.MAX_GENERATOR_ANGLES`), each in [-3600, 3600]; repeats dropped, -0 is 0."""
    from ..constants import MAX_GENERATOR_ANGLES
    from ..numbers import read_values

    def parse(t: str) -> list[float]:
        return read_values(
            "--generator-angle", t, what="angles", unit="deg", max_count=MAX_GENERATOR_ANGLES, lo=-3600.0, hi=3600.0
        )

    return list(dict.fromkeys(v + 0.0 for v in flag_value(parse, text)))  # + 0.0: -0 is 0


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
    (:mod:`wgcad.design.rules`), so a flag and its key accept the same values."""

    def conv(text: str) -> float:
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
    parser.add_argument(
        "--max-memory-mb",
        type=bounded("*", "--max-memory-mb"),
        default=DEFAULT_MAX_MEMORY_MB,
        help=f"refuse a run whose estimated memory exceeds this, MB (default {DEFAULT_MAX_MEMORY_MB:g})",
    )


def out_dir(args, design_path: str) -> Path:
    return Path(args.out) if args.out else Path("output") / Path(design_path).stem


def circle(radius: float, tol: float):
    """The rim circle as a polygon within ``tol`` (mm): :func:`wgcad.plane.circle_polygon`."""
    return circle_polygon(radius, tol)
