"""What every subcommand shares: the parser class, flag converters, exit codes, output folders, the progress bar."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..errors import WgcadError

__all__ = ["EXIT_OK", "EXIT_INTERFERENCE", "EXIT_INPUT", "EPILOG", "Parser", "angles_deg", "positive_float",
           "angle_count", "add_memory_flag", "out_dir", "angle_tag", "circle", "Progress"]

EXIT_OK = 0
EXIT_INTERFERENCE = 1  # reserved for `wgcad audit`: interference found
EXIT_INPUT = 2  # bad design file, flag or output folder; nothing written

EPILOG = """exit codes:
  0  success
  1  interference found (audit)
  2  bad input: design file, flag, or output folder (one-line message, nothing written)
"""


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit code 2, no usage dump."""

    def error(self, message):  # noqa: D401
        self.exit(EXIT_INPUT, f"wgcad: error: {message}\n")


class _UsageError(WgcadError, ValueError):
    pass


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


def angle_count(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a whole number") from None
    if not 4 <= n <= 3_600_000:
        raise argparse.ArgumentTypeError(f"must be 4..3600000 angles per revolution, got {n}")
    return n


def add_memory_flag(parser) -> None:
    """``--max-memory-mb``: the memory budget a run is judged against before it starts (wgcad.design.budget)."""
    from ..design.budget import DEFAULT_MAX_MEMORY_MB

    parser.add_argument("--max-memory-mb", type=positive_float(0.0, 1e7, "MB"), default=DEFAULT_MAX_MEMORY_MB,
                        help=f"refuse a run whose estimated memory exceeds this, MB (default {DEFAULT_MAX_MEMORY_MB:g})")


def out_dir(args, design_path: str) -> Path:
    return Path(args.out) if args.out else Path("output") / Path(design_path).stem


def angle_tag(deg: float) -> str:
    # angles closer than the tag's 1e-3 deg resolution share a file name: keep 6 decimals then
    tag = f"{deg:+08.3f}"
    if abs(round(deg, 3) - deg) > 1e-9:
        tag = f"{deg:+011.6f}"
    return tag.replace("+", "p").replace("-", "m").replace(".", "_")


def circle(radius: float, tol: float):
    import numpy as np

    step = 2.0 * np.arccos(max(-1.0, 1.0 - tol / radius))
    n = max(64, int(np.ceil(2 * np.pi / step)))
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.stack([radius * np.cos(t), radius * np.sin(t)], axis=1)


class Progress:
    """A one-line progress bar on stderr, only when stderr is a terminal (or forced)."""

    def __init__(self, enabled: bool):
        self.enabled = enabled

    def __call__(self, done, total, stage):
        if self.enabled:
            n = int(30 * done / total)
            sys.stderr.write(f"\r[{'#' * n}{'.' * (30 - n)}] {stage:<12s}")
            sys.stderr.flush()
            if done == total:
                sys.stderr.write("\n")

