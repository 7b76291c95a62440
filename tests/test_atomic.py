"""Tests of wgcad.atomic: nothing half-written, nothing left behind, unwritable folders caught early."""

import os
import stat

import pytest

from wgcad.atomic import (
    atomic_batch,
    atomic_write,
    atomic_writer,
    commit_all,
    ensure_writable_dir,
)
from wgcad.errors import OutputError, WgcadError


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


# -- targets that are not regular files (issue 13: a rename onto /dev/null replaced the device) --


def _special_targets(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    (tmp_path / "real.json").write_text("keep")
    link = tmp_path / "link.json"
    link.symlink_to(tmp_path / "real.json")
    dangling = tmp_path / "dangling.json"
    dangling.symlink_to(tmp_path / "nowhere.json")
    folder = tmp_path / "folder.json"
    folder.mkdir()
    return {"fifo": fifo, "link": link, "dangling": dangling, "folder": folder}


@pytest.mark.parametrize("kind", ["fifo", "link", "dangling", "folder"])
def test_special_targets_are_refused_and_left_alone(tmp_path, kind):
    from wgcad.atomic import check_target

    target = _special_targets(tmp_path)[kind]
    before = os.lstat(target)
    with pytest.raises(OutputError, match="wgcad writes only new or regular files"):
        check_target(target)
    with pytest.raises(OutputError, match="only new or regular"):
        atomic_write(target, b"x")
    with pytest.raises(OutputError, match="only new or regular"):
        with atomic_batch() as batch:
            batch.temp_path(target)
    after = os.lstat(target)
    assert (after.st_mode, after.st_ino) == (before.st_mode, before.st_ino)
    assert (tmp_path / "real.json").read_text() == "keep"
    assert not [p for p in os.listdir(tmp_path) if p.endswith(".tmp")]


@pytest.mark.parametrize("device", ["/dev/null", "/dev/full", "/dev/stdout"])
def test_devices_are_refused_even_as_root(device):
    from wgcad.atomic import check_target

    if not os.path.lexists(device):
        pytest.skip(f"{device} missing here")
    before = os.lstat(device)
    with pytest.raises(OutputError, match="only new or regular files"):
        check_target(device)
    with pytest.raises(OutputError):
        atomic_write(device, b"x")
    after = os.lstat(device)
    assert (after.st_mode, after.st_ino, after.st_rdev) == (before.st_mode, before.st_ino, before.st_rdev)


def test_target_that_turns_into_a_fifo_before_the_commit_is_refused(tmp_path):
    # checked again just before the rename, not only when the temporary file is made
    target = tmp_path / "out.json"
    with pytest.raises(OutputError, match="named pipe"):
        with atomic_batch() as batch:
            with open(batch.temp_path(target), "w") as fp:
                fp.write("new")
            os.mkfifo(target)
    assert stat.S_ISFIFO(os.lstat(target).st_mode)
    assert listing(tmp_path) == ["out.json"]


# -- folders: created only when files are written, removed again when the write fails --


def test_check_writable_dir_creates_nothing(tmp_path):
    from wgcad.atomic import check_writable_dir

    check_writable_dir(tmp_path / "a" / "b" / "c")
    assert listing(tmp_path) == []


def test_failed_batch_removes_the_folders_it_created(tmp_path):
    with pytest.raises(Boom):
        with atomic_batch() as batch:
            with open(batch.temp_path(tmp_path / "new" / "sub" / "a.dxf"), "w") as fp:
                fp.write("x")
            raise Boom()
    assert listing(tmp_path) == []


def test_failed_batch_keeps_folders_that_hold_other_files(tmp_path):
    (tmp_path / "old").mkdir()
    with pytest.raises(Boom):
        with atomic_batch() as batch:
            batch.temp_path(tmp_path / "old" / "new" / "a.dxf")
            (tmp_path / "old" / "new" / "user.txt").write_text("someone else's")
            raise Boom()
    assert listing(tmp_path / "old" / "new") == ["user.txt"]


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs a proc file system")
@pytest.mark.parametrize("folder", ["/proc", "/proc/wgcad-test/out"])
def test_proc_is_named_as_such_not_no_such_file(folder):
    from wgcad.atomic import check_writable_dir

    with pytest.raises(OutputError) as info:
        check_writable_dir(folder)
    msg = str(info.value)
    assert "proc file system" in msg and "No such file" not in msg


def test_a_device_in_the_path_is_named(tmp_path):
    from wgcad.atomic import check_writable_dir

    os.mkfifo(tmp_path / "pipe")
    with pytest.raises(OutputError, match=r"pipe is a named pipe \(FIFO\), not a folder"):
        check_writable_dir(tmp_path / "pipe" / "out")


# -- leftovers of killed runs --


def _dead_pid():
    import subprocess
    import sys

    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_stale_temps_of_dead_writers_are_removed_and_nothing_else(tmp_path):
    from wgcad.atomic import remove_stale_temps

    dead, alive = _dead_pid(), os.getpid()
    names = {
        f".a.dxf.{dead}-0123456789ab.tmp": True,  # writer gone
        f".b.stl.{alive}-0123456789ab.tmp": False,  # writer alive (a concurrent run)
        ".c.png.0123456789ab.tmp": True,  # wgcad 0.1.0 name, untouched for two hours
        ".d.png.0123456789ac.tmp": False,  # wgcad 0.1.0 name, recent
        f".e.dxf.{dead}-0123456789.tmp": False,  # not wgcad's pattern (10 hex digits)
        f"f.dxf.{dead}-0123456789ab.tmp": False,  # not hidden
        "notes.tmp": False,
        "a.dxf": False,
    }
    for name in names:
        (tmp_path / name).write_text("x")
    old = os.stat(tmp_path / ".c.png.0123456789ab.tmp").st_mtime - 7200
    os.utime(tmp_path / ".c.png.0123456789ab.tmp", (old, old))
    (tmp_path / f".g.dxf.{dead}-0123456789ab.tmp").symlink_to(tmp_path / "a.dxf")  # a link: not ours
    removed = remove_stale_temps(tmp_path)
    assert sorted(removed) == sorted(n for n, stale in names.items() if stale)
    left = set(listing(tmp_path))
    assert left == {n for n, stale in names.items() if not stale} | {f".g.dxf.{dead}-0123456789ab.tmp"}


def test_a_batch_sweeps_its_folder_first(tmp_path):
    dead = _dead_pid()
    (tmp_path / f".a.dxf.{dead}-0123456789ab.tmp").write_bytes(b"x" * 1000)
    with atomic_batch() as batch:
        with open(batch.temp_path(tmp_path / "a.dxf"), "w") as fp:
            fp.write("new")
    assert listing(tmp_path) == ["a.dxf"]


def test_temp_names_carry_the_pid(tmp_path):
    with atomic_writer(tmp_path / "x.dxf") as temp:
        assert f".x.dxf.{os.getpid()}-" in os.path.basename(temp)


def test_commit_removes_listed_files_with_the_renames(tmp_path):
    (tmp_path / "old.stl").write_text("previous run")
    with atomic_batch() as batch:
        with open(batch.temp_path(tmp_path / "new.stl"), "w") as fp:
            fp.write("this run")
        batch.remove_on_commit(tmp_path / "old.stl")
        assert (tmp_path / "old.stl").exists()  # not before the commit
    assert listing(tmp_path) == ["new.stl"]


def test_failed_batch_removes_nothing_listed(tmp_path):
    (tmp_path / "old.stl").write_text("previous run")
    with pytest.raises(Boom):
        with atomic_batch() as batch:
            batch.remove_on_commit(tmp_path / "old.stl")
            raise Boom()
    assert listing(tmp_path) == ["old.stl"]
