"""Shards and light-and-health channels from Python: a render split into shards merges, in any
order, into the same bits as the command line's merge and into the samples of one render; the
melanopic and mesopic channels reach Python as the command line writes them."""

import subprocess

import numpy as np
import pytest

import candela


def test_python_shards_merge_like_the_command_line(tmp_path, scene_path, candela_bin):
    py = tmp_path / "py"
    cli = tmp_path / "cli"
    py.mkdir()
    cli.mkdir()
    n = 3
    for i in (2, 0, 1):
        r = candela.render(scene_path, out=py / "room", spp=4, seed=5, threads=2, shard=(i, n))
        assert r.samples_per_pixel == 4
        spec = f"{i}/{n}"
        subprocess.run(
            [str(candela_bin), "render", str(scene_path), "--out", str(cli / "room"), "--spp",
             "4", "--seed", "5", "--threads", "2", "--quiet", "--shard", spec],
            check=True, stdout=subprocess.DEVNULL,
        )
    states = [py / f"room.shard-{i}-of-{n}.state" for i in range(n)]
    a = candela.merge(states, py / "merged")
    b = candela.merge(list(reversed(states)), py / "merged-reversed")
    subprocess.run(
        [str(candela_bin), "merge", *[str(cli / f"room.shard-{i}-of-{n}.state") for i in (1, 2, 0)],
         "--out", str(cli / "merged")],
        check=True, stdout=subprocess.DEVNULL,
    )
    c = candela.read_exr(cli / "merged.exr")
    assert a.shards["merged"] == [0, 1, 2] and a.shards["missing"] == []
    assert not a.shards["partial"] and a.samples_per_pixel == 12
    assert sorted(a.channels) == sorted(c["channels"])
    for name, arr in c["channels"].items():
        assert np.array_equal(arr, a.channels[name]), name
        assert np.array_equal(arr, b.channels[name]), name
    assert a.report["meters"] == b.report["meters"]

    # One render at 3 × 4 spp takes the same samples: equal but for the order of additions.
    one = candela.render(scene_path, out=tmp_path / "one", spp=12, seed=5, threads=2)
    y, y1 = a.Y.astype(np.float64), one.Y.astype(np.float64)
    assert np.max(np.abs(y - y1) / np.maximum(np.abs(y1), 1e-30)) < 1e-5

    # A missing shard is named, and merged on request as a partial estimate.
    with pytest.raises(candela.CandelaError, match="missing"):
        candela.merge(states[:2], py / "two")
    p = candela.merge(states[:2], py / "two", partial=True)
    assert p.shards["partial"] and p.shards["missing"] == [2] and p.samples_per_pixel == 8


def test_health_channels_equal_the_command_line(tmp_path, scene_path, candela_bin):
    cli = tmp_path / "cli"
    cli.mkdir()
    subprocess.run(
        [str(candela_bin), "render", str(scene_path), "--out", str(cli), "--spp", "4", "--seed",
         "2", "--threads", "2", "--quiet", "--illuminance", "--alpha-opic", "--mesopic"],
        check=True, stdout=subprocess.DEVNULL,
    )
    r = candela.render(scene_path, out=tmp_path / "py.exr", spp=4, seed=2, threads=2,
                       illuminance=True, alpha_opic=True, mesopic=True)
    exr = candela.read_exr(cli / "small-room.exr")
    for name in ("melanopic.EDL", "stderr.melanopic.EDL", "melanopic.EDI", "stderr.melanopic.EDI",
                 "scotopic.L", "mesopic.L", "stderr.mesopic.L", "mesopic.m"):
        assert name in r.channels, name
    assert sorted(exr["channels"]) == sorted(r.channels)
    for name, arr in exr["channels"].items():
        assert np.array_equal(arr, r.channels[name]), name


def test_bad_shard_raises_naming_it(tmp_path, scene_path):
    with pytest.raises(candela.CandelaError, match="shard"):
        candela.render(scene_path, out=tmp_path / "x", spp=2, shard=(3, 3))
    with pytest.raises(candela.CandelaError, match="shard"):
        candela.render(scene_path, out=tmp_path / "x", spp=2, shard="a/b")
