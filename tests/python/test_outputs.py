# SPDX-License-Identifier: BSD-3-Clause
"""The output rule from Python (rotacal.outputs.write_output): files replaced atomically,
devices and FIFOs written through, symlinks followed, bad targets refused with IoError."""

import os
import stat
import threading

import pytest

from rotacal import _core
from rotacal.outputs import check_output, write_output


def entries(d):
    return sorted(os.listdir(d))


def test_new_and_existing_files_are_written_whole(tmp_path):
    p = tmp_path / "a.json"
    write_output(p, "first\n")
    write_output(p, b"second\n")
    assert p.read_bytes() == b"second\n"
    assert check_output(p) == "replace"
    assert entries(tmp_path) == ["a.json"]


def test_text_is_utf8(tmp_path):
    write_output(tmp_path / "u.txt", "µm ±")
    assert (tmp_path / "u.txt").read_bytes() == "µm ±".encode("utf-8")


def test_own_tmp_file_untouched_and_255_char_name(tmp_path):
    (tmp_path / "out.csv.tmp").write_text("mine")
    write_output(tmp_path / "out.csv", "x")
    assert (tmp_path / "out.csv.tmp").read_text() == "mine"
    name = "n" * 255
    write_output(tmp_path / name, "long")
    assert (tmp_path / name).read_text() == "long"
    assert entries(tmp_path) == sorted(["out.csv", "out.csv.tmp", name])


def test_character_device_is_written_through(tmp_path):
    dev = tmp_path / "mynull"
    try:
        os.mknod(dev, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except PermissionError:
        pytest.skip("mknod needs root here")
    write_output(dev, "discarded")
    st = os.lstat(dev)
    assert stat.S_ISCHR(st.st_mode) and st.st_rdev == os.makedev(1, 3)
    assert check_output(dev) == "write-through"
    write_output("/dev/null", "discarded")


def test_fifo_is_written_through(tmp_path):
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got = []
    t = threading.Thread(target=lambda: got.append(fifo.read_bytes()))
    t.start()
    write_output(fifo, b"through\n")
    t.join(timeout=30)
    assert got == [b"through\n"]
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_symlink_followed(tmp_path):
    (tmp_path / "target").write_text("old")
    os.symlink("target", tmp_path / "link")
    write_output(tmp_path / "link", "new")
    assert os.path.islink(tmp_path / "link")
    assert (tmp_path / "target").read_text() == "new"


@pytest.mark.parametrize(
    "make,path,words",
    [
        (lambda d: (d / "sub").mkdir(), "sub", "is a directory"),
        (lambda d: None, "missing/out.csv", "does not exist"),
    ],
)
def test_bad_targets_refused(tmp_path, make, path, words):
    make(tmp_path)
    with pytest.raises(_core.IoError, match=words):
        write_output(tmp_path / path, "x")


def test_nul_byte_and_empty_and_none_refused(tmp_path):
    with pytest.raises(_core.IoError, match="NUL"):
        write_output(str(tmp_path / "f.csv") + "\x00junk", "x")
    with pytest.raises(_core.IoError):
        write_output("", "x")
    with pytest.raises(_core.IoError):
        write_output(None, "x")
    assert entries(tmp_path) == []


def test_input_and_other_output_refused(tmp_path):
    s = tmp_path / "S.csv"
    s.write_text("measurements")
    with pytest.raises(_core.IoError, match="input"):
        write_output(tmp_path / "." / "S.csv", "predicted", inputs=[s])
    assert s.read_text() == "measurements"
    with pytest.raises(_core.IoError, match="another output"):
        write_output(
            tmp_path / "X", "session", other_outputs=[tmp_path / "X"], inputs=[]
        )  # same name
    # `simulate -o X --truth X`: the second output is refused before anything is written
    with pytest.raises(_core.IoError, match="another output"):
        check_output(tmp_path / "X", other_outputs=[str(tmp_path / "sub" / ".." / "X")])


def test_failing_producer_keeps_old_file(tmp_path):
    p = tmp_path / "prog.ngc"
    p.write_text("G0 X0\nM30\n")

    def boom():
        raise _core.InvalidArgument("--length: out of range")

    with pytest.raises(_core.InvalidArgument):
        write_output(p, boom)
    assert p.read_text() == "G0 X0\nM30\n"
    write_output(p, lambda: "G0 X1\nM30\n")
    assert p.read_text() == "G0 X1\nM30\n"
    assert entries(tmp_path) == ["prog.ngc"]


def test_disk_full_keeps_old_file(tmp_path):
    with pytest.raises(_core.IoError, match="/dev/full"):
        write_output("/dev/full", "x")
