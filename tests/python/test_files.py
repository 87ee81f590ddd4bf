"""The files nystrom.solve writes and reads: checkpoint= is written atomically through a unique temporary file
and refuses devices, FIFOs, folders and symbolic links without touching them; several threads or processes may
checkpoint to one file; restart= reads only a regular file of bounded size, without blocking, and refuses a
checkpoint with any change."""
import os
import stat
import subprocess
import sys
import threading
import time

import pytest

import nystrom
from nystrom.problems import Kepler

RUN = dict(t_span=(0, 20.0), method="M8", steps=2000)


def solve(**kw):
    return nystrom.solve(Kepler(0.5), **{**RUN, **kw})


def fnv1a64(data: bytes) -> int:
    h = 0xCBF29CE484222325
    for c in data:
        h = ((h ^ c) * 0x100000001B3) & 0xFFFFFFFFFFFFFFFF
    return h


def rechecksum(text: bytes) -> bytes:
    body = text[: text.rindex(b"checksum ")]
    return body + b"checksum fnv1a64 %016x\n" % fnv1a64(body)


def test_checkpoint_targets_that_are_not_regular_files_are_refused_untouched(tmp_path):
    (tmp_path / "victim").write_text("precious\n")
    os.symlink(tmp_path / "victim", tmp_path / "link")
    os.mkfifo(tmp_path / "fifo")
    (tmp_path / "folder").mkdir()
    targets = [("link", "symbolic link"), ("fifo", "FIFO"), ("folder", "folder")]
    try:  # a private character device (as root; /dev/full's numbers)
        os.mknod(tmp_path / "node", 0o600 | stat.S_IFCHR, os.makedev(1, 7))
        targets.append(("node", "device"))
    except (PermissionError, OSError):
        pass
    for name, why in targets:
        with pytest.raises(ValueError, match=f"cannot write the checkpoint file .*{why}"):
            solve(checkpoint=tmp_path / name, checkpoint_at=7.0)
    assert (tmp_path / "victim").read_text() == "precious\n"
    assert os.path.islink(tmp_path / "link")
    assert stat.S_ISFIFO(os.lstat(tmp_path / "fifo").st_mode)
    if (tmp_path / "node").exists():
        assert stat.S_ISCHR(os.lstat(tmp_path / "node").st_mode)
    assert sorted(os.listdir(tmp_path)) == sorted(["victim", "link", "fifo", "folder"] +
                                                  (["node"] if (tmp_path / "node").exists() else []))


def test_a_planted_temporary_name_is_neither_written_through_nor_consumed(tmp_path):
    (tmp_path / "victim").write_text("precious\n")
    os.symlink(tmp_path / "victim", tmp_path / "run.checkpoint.tmp")
    solve(checkpoint=tmp_path / "run.checkpoint", checkpoint_at=7.0)
    assert (tmp_path / "victim").read_text() == "precious\n"
    assert os.path.islink(tmp_path / "run.checkpoint.tmp")
    (tmp_path / "mine.tmp").write_text("mine\n")
    solve(checkpoint=tmp_path / "mine", checkpoint_at=7.0)
    assert (tmp_path / "mine.tmp").read_text() == "mine\n"
    assert sorted(os.listdir(tmp_path)) == ["mine", "mine.tmp", "run.checkpoint", "run.checkpoint.tmp", "victim"]
    assert solve(restart=tmp_path / "mine").success


def test_threads_and_processes_checkpointing_to_one_file_all_succeed(tmp_path, child_env):
    path = tmp_path / "shared.checkpoint"
    errors = []

    def work():
        try:
            for _ in range(3):
                solve(checkpoint=path, checkpoint_at=7.0)
        except Exception as exc:  # noqa: BLE001 - every failure is reported
            errors.append(repr(exc))

    threads = [threading.Thread(target=work) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors == []
    code = ("import nystrom\nfrom nystrom.problems import Kepler\n"
            f"for _ in range(3): nystrom.solve(Kepler(0.5), t_span=(0, 20.0), method='M8', steps=2000, "
            f"checkpoint={str(path)!r}, checkpoint_at=7.0)\n")
    procs = [subprocess.Popen([sys.executable, "-c", code], env=child_env, stderr=subprocess.PIPE) for _ in range(4)]
    for p in procs:
        _, err = p.communicate(timeout=120)
        assert p.returncode == 0, err.decode()
    assert os.listdir(tmp_path) == ["shared.checkpoint"]
    assert solve(restart=path).success


def test_restart_reads_only_regular_files_without_blocking(tmp_path):
    os.mkfifo(tmp_path / "fifo")  # no writer: opening it for reading would block
    for path, why in [("/dev/zero", "device"), (tmp_path / "fifo", "FIFO"), (tmp_path, "folder"),
                      (tmp_path / "missing", "No such file")]:
        t0 = time.monotonic()
        with pytest.raises(ValueError, match=f"cannot read the checkpoint file .*{why}"):
            solve(restart=path)
        assert time.monotonic() - t0 < 10


def test_a_changed_checkpoint_is_refused(tmp_path):
    path = tmp_path / "cp"
    solve(checkpoint=path, checkpoint_at=7.0)
    good = path.read_bytes()
    bad = tmp_path / "bad"
    i = good.index(b"\nstate 4 0x") + 11
    changes = [
        (good[:i] + (b"2" if good[i:i + 1] == b"1" else b"1") + good[i + 1:], "checksum does not match"),
        (good.replace(b"\nt 0x", b"\nt 0x\0", 1), "NUL byte"),
        (good.replace(b"nystrom-checkpoint 2", b"nystrom-checkpoint 1", 1), "version 1"),
    ]
    for text, why in changes:
        bad.write_bytes(text)
        with pytest.raises(ValueError, match=why):
            solve(restart=bad)
    # GBS: an order far beyond the integrator's columns and a NaN state, with a valid checksum
    g = tmp_path / "g"
    nystrom.solve(Kepler(0.5), t_span=(0, 20.0), method="GBS", rtol=1e-10, checkpoint=g, checkpoint_at=7.0)
    lines = g.read_bytes().split(b"\n")
    for crafted, why in [({b"columns": b"columns 100000000", b"state": b"state 4 nan nan nan nan"},
                          "malformed checkpoint"),
                         ({b"columns": b"columns 25"}, "outside 2..11")]:
        text = b"\n".join(crafted.get(line.split(b" ")[0], line) for line in lines)
        bad.write_bytes(rechecksum(text))
        with pytest.raises(ValueError, match=why):
            nystrom.solve(Kepler(0.5), t_span=(0, 20.0), method="GBS", rtol=1e-10, restart=bad)
