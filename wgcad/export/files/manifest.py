"""The manifest of what ``wgcad generate`` wrote for one design in a folder: a re-run removes its own stale files and nothing else."""

from __future__ import annotations

import hashlib
import json
import os
import stat
from pathlib import Path

from ...errors import OutputError

__all__ = ["manifest_name", "Manifest"]


def manifest_name(stem: str) -> str:
    """Hidden file listing what ``generate`` wrote for the design ``stem`` in a folder."""
    return f".{stem}.wgcad-files.json"


def _sha256(path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fp:
        for block in iter(lambda: fp.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


class Manifest:
    """What one ``generate`` run wrote in its folder for one design: names, sizes and SHA-256 of each file.

    A re-run removes the files of the previous run that it does not write
    again, and nothing else: only names listed in the folder's manifest for
    the same design, still regular files, with the content wgcad wrote (a
    file changed since is kept, with a warning). A manifest written for a
    different design file of the same name is a collision: refused unless
    ``force``.
    """

    def __init__(self, folder: Path, stem: str, source: Path):
        self.folder = Path(folder)
        self.stem = stem
        self.source = os.path.abspath(source)
        self.path = self.folder / manifest_name(stem)
        self.previous = self._read()

    def _read(self) -> dict | None:
        try:
            st = os.lstat(self.path)
        except OSError:
            return None
        if not stat.S_ISREG(st.st_mode) or st.st_size > 10_000_000:
            return None
        try:
            doc = json.loads(self.path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None  # unreadable: treated as absent, nothing is removed on its word
        if not isinstance(doc, dict) or not isinstance(doc.get("files"), list):
            return None
        return doc

    def check_collision(self, force: bool) -> None:
        """Refuse to overwrite the files another design file of the same name wrote here."""
        prev = self.previous
        if prev is None or force or prev.get("source") == self.source:
            return
        raise OutputError(
            f"{self.folder}: holds the files of another design file named {self.stem} "
            f"({prev.get('source')}); give another --out, or --force to replace them"
        )

    def stale_files(self, new_names) -> tuple[list[Path], list[str]]:
        """Files of the previous run not written again: (to remove, kept because they changed)."""
        remove, kept = [], []
        if self.previous is None:
            return remove, kept
        new = set(new_names)
        for entry in self.previous["files"]:
            if not isinstance(entry, dict):
                continue
            name = entry.get("name")
            if (
                not isinstance(name, str)
                or name in new
                or name in ("", ".", "..")
                or "/" in name
                or os.sep in name
                or name.startswith(".")
            ):
                continue  # only plain names in this folder, never hidden files (temporaries, manifests)
            p = self.folder / name
            try:
                st = os.lstat(p)
            except OSError:
                continue
            if not stat.S_ISREG(st.st_mode):
                continue
            if st.st_size == entry.get("size") and _sha256(p) == entry.get("sha256"):
                remove.append(p)
            else:
                kept.append(name)
        return remove, kept

    def document(self, written: list[tuple[Path, str]]) -> str:
        """The manifest of this run: ``written`` is a list of (final path, temporary file with its content)."""
        files = [
            {"name": Path(final).name, "size": os.path.getsize(temp), "sha256": _sha256(temp)}
            for final, temp in written
        ]
        doc = {"written_by": "wgcad generate", "design": self.stem, "source": self.source, "files": files}
        return json.dumps(doc, allow_nan=False, indent=1) + "\n"
