"""The Python render is the command line's render: the same images bit for bit and the same
report for the same scene and seed; dict and file scenes render alike; cancellation and Ctrl-C stop
it with a checkpoint; bad scenes raise CandelaError naming the field."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import numpy as np
import pytest

import candela

# Report entries that differ between two runs of the same render: when it was written, the
# run's times and ray counts, and the paths of the files written.
RUN_DEPENDENT = {"created_utc", "timing", "outputs"}


def comparable(report):
    """The report without what depends on the run (clock, output paths)."""
    if isinstance(report, dict):
        return {k: comparable(v) for k, v in report.items() if k not in RUN_DEPENDENT}
    if isinstance(report, list):
        return [comparable(v) for v in report]
    return report


def test_render_equals_command_line(tmp_path, scene_path, candela_bin):
    cli = tmp_path / "cli"
    py = tmp_path / "py"
    cli.mkdir()
    py.mkdir()
    args = ["--spp", "6", "--seed", "11", "--illuminance", "--threads", "2", "--quiet"]
    subprocess.run(
        [str(candela_bin), "render", str(scene_path), "--out", str(cli), *args], check=True,
        stdout=subprocess.DEVNULL,
    )
    r = candela.render(scene_path, out=py, spp=6, seed=11, illuminance=True, threads=2)
    for suffix in (".hdr", ".png", ".grid-work-plane.csv", ".grid-work-plane.png"):
        a = (cli / f"small-room{suffix}").read_bytes()
        b = (py / f"small-room{suffix}").read_bytes()
        assert a == b, f"{suffix} differs between the command line and Python"
    # The EXR: the same channels bit for bit and the same attributes (the exr crate writes
    # header attributes in its hash map's order, which changes from process to process, so
    # not even two command-line runs give the same bytes).
    exr = candela.read_exr(cli / "small-room.exr")
    exr_py = candela.read_exr(py / "small-room.exr")
    assert exr["attributes"] == exr_py["attributes"]
    assert sorted(exr["channels"]) == sorted(r.channels)
    for name, arr in exr["channels"].items():
        assert arr.dtype == np.float32 and arr.shape == (36, 48)
        assert np.array_equal(arr, r.channels[name]), name
        assert np.array_equal(arr, exr_py["channels"][name]), name
    assert exr["attributes"]["units"] == "cd/m^2"
    cli_report = json.loads((cli / "small-room.report.json").read_text())
    assert comparable(cli_report) == comparable(r.report)
    # The meters and grids reach Python with their numbers.
    desk = r.meters["desk centre"]
    assert desk["value"] > 0 and desk["stderr"] > 0 and desk["unit"] == "lx"
    grid = r.grids["work plane"]
    assert grid["values"].shape == (5, 4) and np.all(grid["values"] > 0)
    assert r.samples_per_pixel == 6
    # The illuminance channel: lx wherever a surface is seen (the whole image sees the room).
    assert r.E is not None and np.all(r.E_mask == 1) and np.all(r.E >= 0) and r.E.mean() > 0


def test_dict_scene_equals_file(tmp_path, scene_path, scene_dict):
    a = candela.render(scene_path, out=tmp_path / "file.exr", spp=4)
    (tmp_path / "dict").mkdir()
    b = candela.render(candela.Scene.from_dict(scene_dict, name="room"), out=tmp_path / "dict", spp=4)
    for name in ("X", "Y", "Z", "stderr.Y"):
        assert np.array_equal(a.channels[name], b.channels[name]), name
    assert a.meters["desk centre"]["value"] == b.meters["desk centre"]["value"]
    assert np.array_equal(a.grids["work plane"]["values"], b.grids["work plane"]["values"])
    # The dict was written as RON text the command line reads as well.
    assert (tmp_path / "dict" / "room.ron").read_text().startswith("Scene(")


def test_ron_text_scene(tmp_path, scene_path):
    s = candela.Scene.from_ron(scene_path.read_text(), name="text")
    r = candela.render(s, out=tmp_path, spp=2)
    a = candela.render(scene_path, out=tmp_path / "file", spp=2)
    assert np.array_equal(r.Y, a.Y)


def test_unknown_field_in_dict_names_it(scene_dict):
    scene_dict["render"]["fliter"] = "Box"
    with pytest.raises(candela.CandelaError, match=r"render: unknown field `fliter`"):
        candela.Scene.from_dict(scene_dict)
    del scene_dict["render"]["fliter"]
    scene_dict["objects"][4]["shape"]["Quad"]["edge_w"] = [1, 0, 0]
    with pytest.raises(candela.CandelaError, match=r"objects\[4\]\.shape\.Quad: unknown field `edge_w`"):
        candela.Scene.from_dict(scene_dict)


def test_unknown_field_in_file_names_line_and_field(tmp_path, scene_path):
    bad = tmp_path / "bad.ron"
    bad.write_text(scene_path.read_text().replace("vfov_deg", "fov_degrees"))
    with pytest.raises(candela.CandelaError) as e:
        candela.render(bad, out=tmp_path)
    msg = str(e.value)
    assert "bad.ron" in msg and "fov_degrees" in msg and ":7:" in msg, msg


def test_bad_value_names_field_path(tmp_path, scene_dict):
    scene_dict["materials"]["wall"]["Diffuse"]["reflectance"]["Constant"] = 1.5
    s = candela.Scene.from_dict(scene_dict)
    with pytest.raises(candela.CandelaError, match=r"materials.*wall.*reflectance"):
        candela.render(s, out=tmp_path)
    assert not (tmp_path / "scene.exr").exists()


def test_progress_callback_cancels(tmp_path, scene_path):
    calls = []

    def progress(done, total, elapsed_s):
        calls.append((done, total, elapsed_s))
        return len(calls) < 3  # False at the third call: after the second pass

    # max_time_s bounds the test if cancelling failed: the render would then end normally.
    with pytest.raises(candela.Cancelled, match="cancelled during the render: a checkpoint was written"):
        candela.render(scene_path, out=tmp_path, spp=1_000_000, max_time_s=60, progress=progress)
    assert len(calls) >= 3 and calls[0][0] == 0
    assert calls[1][1] == 48 * 36 * 1_000_000 and 0 < calls[1][0] < calls[2][0]
    st = candela.read_state(tmp_path / "small-room.state")
    assert st["total_samples"] == calls[-1][0] and st["width"] == 48
    assert st["pixel_batches"] == 16


def test_cancel_event_stops_render(tmp_path, scene_path):
    ev = threading.Event()
    threading.Timer(0.5, ev.set).start()
    t0 = time.monotonic()
    with pytest.raises(candela.Cancelled, match="cancelled"):
        candela.render(scene_path, out=tmp_path, spp=1_000_000, max_time_s=60, cancel=ev)
    assert time.monotonic() - t0 < 60


def test_ctrl_c_raises_keyboard_interrupt(tmp_path, scene_path):
    # In a child interpreter, so that the signal reaches only it.
    script = textwrap.dedent(
        f"""
        import os, signal, threading, candela
        threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
        try:
            candela.render({str(scene_path)!r}, out={str(tmp_path)!r}, spp=1_000_000, max_time_s=60)
        except KeyboardInterrupt:
            print("interrupted")
        """
    )
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == "interrupted"
    # As from the command line: the passes done are kept in a checkpoint.
    assert candela.read_state(tmp_path / "small-room.state")["total_samples"] > 0


def test_existing_state_is_never_replaced(tmp_path, scene_path):
    candela.render(scene_path, out=tmp_path, spp=2, save_state=True)
    with pytest.raises(candela.CandelaError, match="--resume"):
        candela.render(scene_path, out=tmp_path, spp=2)
    r = candela.render(scene_path, out=tmp_path, spp=4, resume=True)
    assert r.samples_per_pixel == 4
