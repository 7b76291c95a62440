"""Tests of wgcad.export.atomic: nothing half-written, nothing left behind, unwritable folders caught early."""

import os
import stat

import pytest

from wgcad.errors import OutputError, WgcadError
from wgcad.export.atomic import (
    atomic_batch,
    atomic_write,
    atomic_writer,
    commit_all,
    ensure_writable_dir,
)


class Boom(RuntimeError):
    pass


def listing(folder):
    return sorted(p.name for p in folder.iterdir())


def current_umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_atomic_write_writes_and_leaves_no_temp(tmp_path):
    atomic_write(tmp_path / "a.bin", b"\x00\x01abc")
    assert (tmp_path / "a.bin").read_bytes() == b"\x00\x01abc"
    assert listing(tmp_path) == ["a.bin"]
    # mode follows the umask like open() would, not mkstemp's 0600
    mode = stat.S_IMODE((tmp_path / "a.bin").stat().st_mode)
    assert mode == 0o666 & ~current_umask()


def test_temp_file_is_in_the_target_folder(tmp_path):
    with atomic_writer(tmp_path / "sub" / "x.dxf") as temp:
        # same folder, so os.replace is a rename on one file system
        assert os.path.dirname(temp) == str(tmp_path / "sub")
        assert os.path.exists(temp)
        with open(temp, "w") as fp:
            fp.write("x")
    assert listing(tmp_path / "sub") == ["x.dxf"]


@pytest.mark.parametrize("exc", [Boom("writer failed"), KeyboardInterrupt()])
def test_failing_writer_leaves_no_file_and_no_temp(tmp_path, exc):
    with pytest.raises(type(exc)):
        with atomic_writer(tmp_path / "out.stl") as temp:
            with open(temp, "wb") as fp:
                fp.write(b"half")
            raise exc
    assert listing(tmp_path) == []


def test_failing_writer_keeps_the_old_file(tmp_path):
    target = tmp_path / "out.stl"
    target.write_bytes(b"old")
    with pytest.raises(Boom):
        with atomic_writer(target) as temp:
            with open(temp, "wb") as fp:
                fp.write(b"new but incomplete")
            raise Boom()
    assert target.read_bytes() == b"old"
    assert listing(tmp_path) == ["out.stl"]


def test_oserror_in_writer_becomes_outputerror_naming_the_path(tmp_path):
    target = tmp_path / "out.dxf"
    with pytest.raises(OutputError, match="out.dxf: cannot write file") as info:
        with atomic_writer(target):
            raise OSError(28, "No space left on device")
    assert isinstance(info.value, OSError) and isinstance(info.value, WgcadError)
    assert "\n" not in str(info.value)
    assert listing(tmp_path) == []


def test_ensure_writable_dir_creates_parents(tmp_path):
    folder = ensure_writable_dir(tmp_path / "a" / "b")
    assert folder.is_dir()
    assert listing(folder) == []  # the probe file is gone


def test_parent_is_a_regular_file_raises_outputerror(tmp_path):
    # works as root too, where chmod does not stop writes
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    with pytest.raises(OutputError, match="output folder is not writable"):
        ensure_writable_dir(blocker / "out")
    with pytest.raises(OutputError, match="output folder is not writable"):
        ensure_writable_dir(blocker)
    with pytest.raises(OutputError, match="output folder is not writable"):
        atomic_write(blocker / "out" / "a.stl", b"x")
    assert listing(tmp_path) == ["file"]


@pytest.mark.skipif(os.name != "posix" or os.geteuid() == 0, reason="root ignores chmod")
@pytest.mark.parametrize("trust_access", [False, True])
def test_read_only_folder_raises_outputerror(tmp_path, monkeypatch, trust_access):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o500)
    if trust_access:
        # os.access can say yes where writes fail (root on a read-only mount,
        # ACLs, network file systems): the probe file must still catch it
        monkeypatch.setattr(os, "access", lambda *args, **kwargs: True)
    try:
        with pytest.raises(OutputError, match=r"ro: output folder is not writable"):
            ensure_writable_dir(folder)
        with pytest.raises(OutputError, match="not writable"):
            atomic_write(folder / "a.stl", b"x")
    finally:
        folder.chmod(0o700)
    assert listing(folder) == []


def test_batch_commits_all(tmp_path):
    with atomic_batch() as batch:
        for name in ("a.dxf", "b.dxf", "c.stl"):
            with open(batch.temp_path(tmp_path / name), "w") as fp:
                fp.write(name)
        # nothing is visible before the end of the block
        assert not any((tmp_path / n).exists() for n in ("a.dxf", "b.dxf", "c.stl"))
    assert listing(tmp_path) == ["a.dxf", "b.dxf", "c.stl"]
    assert (tmp_path / "b.dxf").read_text() == "b.dxf"


def test_batch_with_one_failure_writes_nothing(tmp_path):
    (tmp_path / "a.dxf").write_text("old a")
    with pytest.raises(Boom):
        with atomic_batch() as batch:
            for k, name in enumerate(("a.dxf", "b.dxf", "c.stl")):
                with open(batch.temp_path(tmp_path / name), "w") as fp:
                    fp.write("new")
                if k == 1:
                    raise Boom("second file failed")
    assert listing(tmp_path) == ["a.dxf"]
    assert (tmp_path / "a.dxf").read_text() == "old a"


def test_batch_rejects_the_same_file_twice(tmp_path):
    with pytest.raises(OutputError, match="listed twice"):
        with atomic_batch() as batch:
            batch.temp_path(tmp_path / "a.dxf")
            batch.temp_path(tmp_path / "a.dxf")
    assert listing(tmp_path) == []


def test_commit_all_missing_temp_removes_the_others(tmp_path):
    t1 = tmp_path / ".a.tmp"
    t1.write_text("a")
    with pytest.raises(OutputError, match="b.dxf: cannot write file"):
        commit_all([(tmp_path / "a.dxf", t1), (tmp_path / "b.dxf", tmp_path / ".gone.tmp")])
    assert listing(tmp_path) == []


def test_commit_all_rename_failure_reports_progress_and_cleans_up(tmp_path, monkeypatch):
    # a file-system fault on the second rename (the targets themselves are fine)
    temps = []
    for name in ("a", "b", "c"):
        t = tmp_path / f".{name}.tmp"
        t.write_text(name)
        temps.append(t)
    finals = [tmp_path / n for n in ("a.dxf", "b.dxf", "c.dxf")]
    real_replace, calls = os.replace, []

    def flaky_replace(src, dst):
        calls.append(dst)
        if len(calls) == 2:
            raise OSError(5, "Input/output error")
        return real_replace(src, dst)

    monkeypatch.setattr(os, "replace", flaky_replace)
    with pytest.raises(OutputError, match="1 of 3 files were already written"):
        commit_all(zip(finals, temps))
    assert listing(tmp_path) == ["a.dxf"]


def test_commit_all_refuses_a_folder_as_target_before_renaming_anything(tmp_path):
    (tmp_path / "b.dxf").mkdir()
    temps = []
    for name in ("a", "b"):
        t = tmp_path / f".{name}.tmp"
        t.write_text(name)
        temps.append(t)
    with pytest.raises(OutputError, match="b.dxf: is a folder"):
        commit_all(zip([tmp_path / "a.dxf", tmp_path / "b.dxf"], temps))
    assert listing(tmp_path) == ["b.dxf"]
