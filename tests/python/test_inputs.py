"""What the Python package refuses, and that it never overwrites or reads what it must not: a
scene name is a plain file-name stem; NAME.ron written for a scene from text or a dict never
replaces a file the package did not write; files are read as the command line reads them (no
FIFO, device or directory opened, size limits); bad arguments raise exceptions that name them."""

import errno
import os
import re
import threading
import time

import numpy as np
import pytest

import candela
from candela import colour

from conftest import DATA


def tiny_text() -> str:
    return (DATA / "small-room.ron").read_text().replace("(48, 36)", "(8, 6)")


@pytest.mark.parametrize("name", ["", ".", "..", "../x", "a/b", "a\\b", "x\x00", "a\nb", "\x9b", "x" * 211])
def test_bad_names_are_refused(name):
    with pytest.raises(candela.CandelaError, match="^name "):
        candela.Scene.from_ron(tiny_text(), name=name)
    with pytest.raises(ValueError, match="^name "):
        candela.Scene.from_dict({}, name=name)


def test_name_of_wrong_type_is_a_type_error():
    with pytest.raises(TypeError, match="^name must be a str"):
        candela.Scene.from_ron(tiny_text(), name=5)


def test_longest_name_renders(tmp_path):
    name = "é" * 105  # 210 bytes
    text = re.sub(r"grids: \[.*?\],\n", "", tiny_text(), flags=re.S)
    r = candela.render(candela.Scene.from_ron(text, name=name), out=tmp_path, spp=1,
                       illuminance=True, falsecolour=True)
    assert r.exr_path == tmp_path / f"{name}.exr" and r.exr_path.exists()
    assert (tmp_path / f"{name}.illuminance.png").exists()
    # A grid's outputs are longer still: the command line's check names the grid.
    with pytest.raises(candela.CandelaError, match='grid "work plane".*file name of 230 bytes'):
        candela.render(candela.Scene.from_ron(tiny_text(), name=name), out=tmp_path, spp=1)


def test_a_users_file_is_never_replaced(tmp_path):
    mine = tmp_path / "room.ron"
    mine.write_text("my notes")
    s = candela.Scene.from_ron(tiny_text(), name="room")
    with pytest.raises(candela.CandelaError, match="name='room'.*not written by candela"):
        candela.render(s, out=tmp_path, spp=1)
    with pytest.raises(candela.CandelaError, match="not written by candela"):
        candela.render(s, out=tmp_path, spp=1, overwrite=True)
    assert mine.read_text() == "my notes"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["room.ron"]  # nothing else written
    # A directory or a link of that name is refused too, and left as it was.
    (tmp_path / "d.ron").mkdir()
    os.symlink(mine, tmp_path / "l.ron")
    for name in ("d", "l"):
        with pytest.raises(candela.CandelaError, match="not a regular file"):
            candela.render(candela.Scene.from_ron(tiny_text(), name=name), out=tmp_path, spp=1)
    assert mine.read_text() == "my notes" and (tmp_path / "d.ron").is_dir()


def test_own_scene_file_is_reused_or_replaced(tmp_path):
    text = tiny_text()
    a = candela.render(candela.Scene.from_ron(text, name="room"), out=tmp_path, spp=1)
    written = (tmp_path / "room.ron").read_text()
    assert written.startswith(text) and written != text  # the module's mark follows the scene
    # The same scene again: the file is kept as it is.
    before = os.stat(tmp_path / "room.ron").st_ino
    candela.render(candela.Scene.from_ron(text, name="room"), out=tmp_path, spp=1)
    assert os.stat(tmp_path / "room.ron").st_ino == before
    # Another scene of the same name: the module's own file is replaced, and renders it.
    other = text.replace("Constant(0.7)", "Constant(0.2)")
    b = candela.render(candela.Scene.from_ron(other, name="room"), out=tmp_path, spp=1)
    assert (tmp_path / "room.ron").read_text().startswith(other)
    assert b.Y.mean() < a.Y.mean()


def test_own_scene_file_with_a_state_needs_overwrite(tmp_path):
    text = tiny_text()
    candela.render(candela.Scene.from_ron(text, name="room"), out=tmp_path, spp=1, save_state=True)
    state = (tmp_path / "room.state").read_bytes()
    other = text.replace("Constant(0.7)", "Constant(0.2)")
    with pytest.raises(candela.CandelaError, match="room.state.*overwrite=True"):
        candela.render(candela.Scene.from_ron(other, name="room"), out=tmp_path, spp=1)
    with pytest.raises(candela.CandelaError, match="room.state"):
        candela.render(candela.Scene.from_ron(other, name="room"), out=tmp_path, spp=1, resume=True)
    # The state and the scene it was rendered from are as they were, and resume.
    assert (tmp_path / "room.state").read_bytes() == state
    assert (tmp_path / "room.ron").read_text().startswith(text)
    r = candela.render(candela.Scene.from_ron(text, name="room"), out=tmp_path, spp=2, resume=True)
    assert r.samples_per_pixel == 2
    candela.render(candela.Scene.from_ron(other, name="room"), out=tmp_path, spp=1, overwrite=True)
    assert (tmp_path / "room.ron").read_text().startswith(other)


def test_special_files_are_refused_without_blocking(tmp_path):
    fifo = tmp_path / "scene.ron"
    os.mkfifo(fifo)
    done = []

    def attempt():
        for f in (candela.Scene.from_file, candela.read_exr, candela.read_state):
            with pytest.raises(candela.FileError, match="FIFO"):
                f(fifo)
        with pytest.raises(candela.FileError, match="FIFO"):
            candela.render(fifo, out=tmp_path, spp=1)
        done.append(True)

    t = threading.Thread(target=attempt, daemon=True)
    t.start()
    t.join(10)
    assert done == [True], "a read of a FIFO blocked or failed otherwise"
    t0 = time.monotonic()
    for f in (candela.Scene.from_file, candela.read_exr, candela.read_state):
        with pytest.raises(candela.FileError, match="device") as e:
            f("/dev/zero")
        assert e.value.errno is None and isinstance(e.value, OSError)
        with pytest.raises(candela.FileError, match="directory"):
            f(tmp_path)
    assert time.monotonic() - t0 < 2


def test_missing_files_raise_os_errors_with_errno(tmp_path):
    missing = tmp_path / "missing"
    for f in (candela.Scene.from_file, candela.read_exr, candela.read_state):
        with pytest.raises(OSError) as e:
            f(missing)
        assert e.value.errno == errno.ENOENT and isinstance(e.value, candela.CandelaError)
        assert str(missing) in str(e.value)
    with pytest.raises(candela.FileError) as e:
        candela.render(missing, out=tmp_path, spp=1)
    assert e.value.errno == errno.ENOENT


def test_a_scene_larger_than_the_limit_is_refused_unread(tmp_path):
    big = tmp_path / "big.ron"
    with open(big, "wb") as f:
        f.truncate((256 << 20) + 1)  # sparse: no disk used
    with pytest.raises(candela.FileError, match="limit of 268435456 bytes"):
        candela.Scene.from_file(big)


@pytest.mark.parametrize("arg, value, message", [
    ("spp", 0, "spp must be an integer from 1 to 4294967295, got 0"),
    ("spp", 2**40, "spp must be an integer from 1 to 4294967295, got 1099511627776"),
    ("seed", -1, "seed must be an integer from 0 to 18446744073709551615, got -1"),
    ("max_depth", -1, "max_depth must be an integer from 0"),
    ("threads", 0, "threads must be an integer from 1 to"),
    ("max_spp", 0, "max_spp must be an integer from 1"),
    ("spectral_bands", -1, "spectral_bands must be an integer from 0 to 64, got -1"),
    ("exposure_ev", float("nan"), "exposure_ev must be a finite number of EV between -100 and 100, got NaN"),
    ("target_fraction", 0.0, r"target_fraction must be a fraction in \(0, 1\], got 0"),
    ("target_floor_cd_m2", -1.0, "target_floor_cd_m2 must be a luminance ≥ 0 in cd/m², got -1"),
    ("target_error", 1.0, "target_error must be strictly between 0 and 1"),
    ("max_time_s", float("inf"), "max_time_s must be a duration ≥ 0 in seconds, got inf"),
    ("checkpoint_interval_s", -1.0, "checkpoint_interval_s must be a duration ≥ 0 in seconds, got -1"),
])
def test_bad_render_arguments_name_them(tmp_path, arg, value, message):
    with pytest.raises(candela.CandelaError, match="^" + message):
        candela.render(DATA / "small-room.ron", out=tmp_path, **{arg: value})
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("arg, value", [
    ("spp", 1.5), ("spp", "4"), ("spp", True), ("seed", 1.0), ("progress", 5), ("cancel", 5),
    ("shard", (1.5, 2)), ("shard", ("a", 2)), ("out", 5), ("overwrite", "yes"),
])
def test_arguments_of_the_wrong_type_are_type_errors(tmp_path, arg, value):
    kwargs = {"out": tmp_path, arg: value}
    with pytest.raises(TypeError, match=arg):
        candela.render(DATA / "small-room.ron", **kwargs)


def test_colour_arguments_name_them():
    wl = np.arange(360.0, 835.0, 5.0)
    with pytest.raises(ValueError, match="^xyz must be an array of shape"):
        colour.xyz_to_xy([1.0, 2.0])
    with pytest.raises(TypeError, match="^values must be an array of real numbers"):
        colour.sd_to_xyz(wl, np.ones(95, dtype=complex))
    with pytest.raises(TypeError, match="^values must be an array of numbers"):
        colour.sd_to_xyz(wl, "abc")
    with pytest.raises(ValueError, match="^values must be"):
        colour.sd_to_xyz(wl, np.ones((2, 2, 95)))
    with pytest.raises(TypeError, match="^illuminant must be"):
        colour.sd_to_xyz(wl, np.ones(95), kind="relative", illuminant=5)
    with pytest.raises(TypeError, match="^kind must be a str"):
        colour.sd_to_xyz(wl, np.ones(95), kind=5)
    with pytest.raises(candela.CandelaError, match="^values: spectrum 1: .*non-finite"):
        colour.cri(wl, np.stack([np.ones(95), np.full(95, np.nan)]))
    # Non-contiguous and Fortran-ordered arrays give the same numbers as contiguous ones.
    v = np.random.default_rng(1).random((3, 95))
    a = colour.sd_to_xyz(wl, v)
    assert np.array_equal(colour.sd_to_xyz(wl, np.asfortranarray(v)), a)
    assert np.array_equal(colour.sd_to_xyz(wl, np.repeat(v, 2, axis=1)[:, ::2]), a)
    assert colour.sd_to_xyz(wl, np.zeros((0, 95))).shape == (0, 3)


def test_scene_constructor_and_text_are_checked(tmp_path):
    with pytest.raises(TypeError, match="exactly one of path= and text="):
        candela.Scene()
    with pytest.raises(TypeError, match="^text must be a str"):
        candela.Scene.from_ron(b"Scene()")
    with pytest.raises(candela.CandelaError, match="^text must be valid Unicode"):
        candela.Scene.from_ron("\ud800")


def test_unwritable_directory_is_a_file_error(tmp_path):
    if os.geteuid() == 0:
        pytest.skip("root writes into read-only directories")
    os.chmod(tmp_path, 0o500)
    try:
        with pytest.raises(candela.FileError) as e:
            candela.render(candela.Scene.from_ron(tiny_text(), name="room"), out=tmp_path, spp=1)
        assert e.value.errno == errno.EACCES
    finally:
        os.chmod(tmp_path, 0o700)


def test_a_scene_file_of_any_name_renders(tmp_path):
    # Only a scene from text is written under its name: a file's own name is the render's
    # business (its outputs are checked by the command line's rules).
    odd = tmp_path / "a\x1bb.ron"
    odd.write_text(tiny_text())
    s = candela.Scene.from_file(odd)
    assert s.name == "a\x1bb"
    r = candela.render(s, out=tmp_path, spp=1)
    assert r.exr_path == tmp_path / "a\x1bb.exr"
