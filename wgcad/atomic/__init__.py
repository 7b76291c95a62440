"""Outputs written atomically: a temporary file in the target folder renamed into place (``writes``), the checks of
a target before anything is written (``targets``: only a missing or regular file is ever replaced), and the
temporary files' names and their clean-up after a killed run (``temps``). The ground floor under every writer
(export, sweep store, the CLI)."""

from .targets import check_target, check_writable_dir, ensure_writable_dir
from .temps import TEMP_SUFFIX, remove_stale_temps
from .writes import Batch, atomic_batch, atomic_write, atomic_writer, commit_all, discard_all

__all__ = [
    "TEMP_SUFFIX",
    "check_target",
    "check_writable_dir",
    "ensure_writable_dir",
    "remove_stale_temps",
    "atomic_writer",
    "atomic_write",
    "commit_all",
    "discard_all",
    "Batch",
    "atomic_batch",
]
