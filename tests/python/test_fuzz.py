"""Seeded fuzzing of every public entry point of the Python package: mutated scene text, dict
scenes with values of the wrong type or range, byte-mutated EXR and state files (the state's
checksum recomputed, so its decoder is reached), colour arrays of every shape, dtype and
value, render and merge arguments, scene names and paths. Each call must return or raise one
of the documented exceptions (CandelaError and its FileError, TypeError, ValueError, OSError)
within its time bound, never anything else (a PanicException, RecursionError, MemoryError,
AttributeError, …) and never an "internal error". The whole file runs in well under 60 s."""

import copy
import math
import os
import random
import struct
import threading
import time
import warnings

import numpy as np
import pytest

import candela
from candela import colour

from conftest import DATA

DOCUMENTED = (candela.CandelaError, TypeError, ValueError, OSError)
# A longer or different run: CANDELA_FUZZ_SEED shifts every seed, CANDELA_FUZZ_SCALE multiplies
# the number of cases (the default run takes about 20 s).
SEED = int(os.environ.get("CANDELA_FUZZ_SEED", "0"))
SCALE = float(os.environ.get("CANDELA_FUZZ_SCALE", "1"))


def n(cases: int) -> int:
    return max(1, round(cases * SCALE))
# Seconds one call may take: renders are 1 spp of a 8×6 image, reads of files of kB.
CALL_BOUND_S = 5.0


def tiny_text() -> str:
    """data/small-room.ron at 8×6 pixels: a render of it takes milliseconds."""
    return (DATA / "small-room.ron").read_text().replace("(48, 36)", "(8, 6)")


def call(label, f, *args, **kwargs):
    """f(*args, **kwargs), which must return or raise a documented exception in time; returns
    the result or the exception."""
    t0 = time.monotonic()
    try:
        r = f(*args, **kwargs)
    except DOCUMENTED as e:
        r = e
        assert "internal error" not in str(e), f"{label}: {e}"
        assert str(e), f"{label}: {type(e).__name__} without a message"
    except BaseException as e:  # noqa: B902 - anything else is the failure looked for
        pytest.fail(f"{label}: undocumented {type(e).__name__}: {str(e)[:300]}")
    dt = time.monotonic() - t0
    assert dt < CALL_BOUND_S, f"{label}: took {dt:.1f} s"
    return r


# Values of the wrong kind, range or size for anything.
NASTY = [
    None, True, False, 0, -1, 1, 2**31, 2**32, 2**63, 2**64, -(2**63), 2**200,
    0.0, -0.0, 1.5, -1e308, 1e308, 5e-324, math.nan, math.inf, -math.inf,
    "", "x", "é\x00\x1b[2J", "\ud800", "9" * 400, b"bytes", [], [1], [1, 2, 3], [[]],
    {}, {"Bogus": 1}, {"": None}, (1, 2), np.float32(2.5), np.int64(-3), np.array([1.0, 2.0]),
    np.array([]), object(), {1, 2}, complex(1, 1),
]


def mutate_text(rng: random.Random, text: str) -> str:
    """One to four edits of scene text: special numbers, deleted or duplicated lines, swapped
    brackets, inserted control or non-ASCII characters, a truncation."""
    specials = ["nan", "inf", "-inf", "-1", "0", "1e308", "-1e308", "4294967296", "1e-320",
                "18446744073709551616", "0.0", "\"\"", "None", "Some(", "[", "(", "{"]
    for _ in range(rng.randint(1, 4)):
        op = rng.randrange(6)
        if op == 0:
            # A number replaced by a special value.
            spots = [i for i, c in enumerate(text) if c.isdigit()]
            if spots:
                i = rng.choice(spots)
                j = i
                while j < len(text) and (text[j].isdigit() or text[j] == "."):
                    j += 1
                text = text[:i] + rng.choice(specials) + text[j:]
        elif op == 1:
            lines = text.split("\n")
            del lines[rng.randrange(len(lines))]
            text = "\n".join(lines)
        elif op == 2:
            lines = text.split("\n")
            k = rng.randrange(len(lines))
            lines.insert(k, lines[k])
            text = "\n".join(lines)
        elif op == 3:
            i = rng.randrange(len(text) + 1)
            text = text[:i] + rng.choice("()[]{},:\"\\\x00\x1b\u202e\U0001f600é") + text[i:]
        elif op == 4 and text:
            i = rng.randrange(len(text))
            text = text[:i] + text[i + 1:]
        else:
            text = text[: rng.randrange(len(text) + 1)]
    return text


def leaves(d, path=()):
    """Every (path, value) in a nested dict/list."""
    yield path, d
    if isinstance(d, dict):
        for k, v in d.items():
            yield from leaves(v, path + (k,))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from leaves(v, path + (i,))


def replaced(d, path, value):
    d = copy.deepcopy(d)
    if not path:
        return value
    node = d
    for k in path[:-1]:
        node = node[k]
    node[path[-1]] = value
    return d


def mix64(x):
    m = (1 << 64) - 1
    x ^= x >> 33
    x = (x * 0xFF51AFD7ED558CCD) & m
    x ^= x >> 33
    x = (x * 0xC4CEB9FE1A85EC53) & m
    x ^= x >> 33
    return x


def checksum(data: bytes) -> int:
    """src/state.rs `checksum`: four interleaved mix64 chains over 8-byte words, folded with
    the length."""
    lanes = [0x243F6A8885A308D3, 0x13198A2E03707344, 0xA4093822299F31D0, 0x082EFA98EC4E6C89]
    full = len(data) // 32 * 32
    for off in range(0, full, 32):
        for k, w in enumerate(struct.unpack_from("<4Q", data, off)):
            lanes[k] = mix64(lanes[k] ^ w)
    rest = data[full:]
    for k in range(0, len(rest), 8):
        w = int.from_bytes(rest[k:k + 8].ljust(8, b"\0"), "little")
        lanes[k // 8] = mix64(lanes[k // 8] ^ w)
    h = len(data)
    for lane in lanes:
        h = mix64(h ^ lane)
    return h


def mutate_bytes(rng: random.Random, b: bytes) -> bytes:
    b = bytearray(b)
    for _ in range(rng.choice([1, 1, 2, 4, 16])):
        i = rng.randrange(len(b)) if b else 0
        op = rng.random()
        if op < 0.45 and b:
            b[i] = rng.randrange(256)
        elif op < 0.6 and b:
            b[i] = rng.choice([0, 0x7F, 0x80, 0xFF])
        elif op < 0.7:
            del b[i:i + rng.randrange(1, 64)]
        elif op < 0.8:
            b[i:i] = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 16)))
        elif op < 0.9 and len(b) >= 8:
            # A length or count field made huge.
            b[i:i + 8] = rng.choice([b"\xff" * 8, b"\xff\xff\xff\x7f", b"\x80" * 9])
        else:
            b = b[:i]
    return bytes(b)


@pytest.fixture(scope="module")
def rendered(tmp_path_factory):
    """A tiny render's EXR and state."""
    d = tmp_path_factory.mktemp("fuzz-render")
    candela.render(candela.Scene.from_ron(tiny_text(), name="tiny"), out=d, spp=2,
                   save_state=True, illuminance=True)
    return d


def test_scene_text_mutations(tmp_path):
    rng = random.Random(11 + SEED)
    base = tiny_text()
    rendered_ok = 0
    for k in range(n(400)):
        text = mutate_text(rng, base)
        s = call(f"from_ron #{k}", candela.Scene.from_ron, text, name=f"m{k}")
        if isinstance(s, BaseException):
            continue
        size = call(f"check #{k}", s.check)
        if isinstance(size, BaseException) or size[0] * size[1] > 64 * 64 or rendered_ok >= 12:
            continue
        d = tmp_path / f"r{k}"
        d.mkdir()
        r = call(f"render #{k}", candela.render, s, out=d, spp=1, max_time_s=1.0)
        rendered_ok += not isinstance(r, BaseException)
    assert rendered_ok > 0  # the mutations leave some scenes that render
    # Nesting far past any parser's recursion limit.
    for deep in ["Scene(objects: " + "[" * 100000,
                 'Scene(materials: {"a": ' + "NormalMapped(material: " * 100000,
                 "Scene(objects: [(material: \"a\", shape: " + "Instances(transforms: [], mesh: " * 50000]:
        call("deep text", candela.Scene.from_ron, deep)


def test_dict_scene_mutations(scene_dict):
    rng = random.Random(12 + SEED)
    scene_dict["camera"]["resolution"] = [8, 6]
    spots = list(leaves(scene_dict))
    refused = 0
    for k in range(n(1000)):
        path, _ = rng.choice(spots)
        value = rng.choice(NASTY)
        d = replaced(scene_dict, path, value)
        s = call(f"from_dict {path}={value!r:.40}", candela.Scene.from_dict, d, name="d")
        if isinstance(s, BaseException):
            refused += 1
        elif k % 10 == 0:
            call(f"check {path}={value!r:.40}", s.check)
    # Deeply nested and circular dicts.
    deep = []
    node = deep
    for _ in range(3000):
        node.append([])
        node = node[0]
    call("deep dict", candela.Scene.from_dict, {"objects": deep})
    circular = {}
    circular["render"] = circular
    call("circular dict", candela.Scene.from_dict, circular)
    assert refused > n(300)


def test_scene_names_and_paths(tmp_path):
    rng = random.Random(13 + SEED)
    text = tiny_text()
    names = ["", ".", "..", "../x", "a/b", "a\\b", "x\x00", "\x1b[2J", "\u0085", "é" * 120,
             "x" * 211, "x" * 210, "\ud800", 5, None, b"room", "ok name", ".hidden"]
    for k, name in enumerate(names):
        s = call(f"name {name!r:.30}", candela.Scene.from_ron, text, name=name)
        if not isinstance(s, BaseException):
            d = tmp_path / f"n{k}"
            d.mkdir()
            call(f"render name {name!r:.30}", candela.render, s, out=d, spp=1)
            # Nothing was written outside the output directory.
            assert sorted(os.listdir(tmp_path)) == sorted(f"n{i}" for i in range(k + 1)
                                                          if (tmp_path / f"n{i}").exists())
    fifo = tmp_path / "fifo.ron"
    os.mkfifo(fifo)
    for p in ["/dev/zero", "/dev/null", str(tmp_path), str(fifo), "/nonexistent/x.ron", "x\x00y",
              5, b"/dev/zero", tmp_path / ("x" * 300)]:
        call(f"from_file {p!r:.40}", candela.Scene.from_file, p)
        call(f"read_exr {p!r:.40}", candela.read_exr, p)
        call(f"read_state {p!r:.40}", candela.read_state, p)
        call(f"render {p!r:.40}", candela.render, p, out=tmp_path, spp=1)
    for _ in range(20):
        name = "".join(rng.choice("ab./\\\x00\x7f\u2028é ") for _ in range(rng.randrange(1, 8)))
        call(f"name {name!r}", candela.Scene.from_ron, text, name=name)


def test_exr_and_state_mutations(rendered, tmp_path):
    rng = random.Random(14 + SEED)
    exr = (rendered / "tiny.exr").read_bytes()
    state = (rendered / "tiny.state").read_bytes()
    for k in range(n(500)):
        p = tmp_path / f"m{k}.exr"
        p.write_bytes(mutate_bytes(rng, exr))
        call(f"read_exr #{k}", candela.read_exr, p)
    decoded = 0
    for k in range(n(500)):
        b = mutate_bytes(rng, state[:-8])
        if k % 4:
            b += checksum(b).to_bytes(8, "little")  # reaches the decoder
        p = tmp_path / f"m{k}.state"
        p.write_bytes(b)
        r = call(f"read_state #{k}", candela.read_state, p)
        decoded += isinstance(r, BaseException) and "checksum" not in str(r)
    assert decoded > n(200)  # most mutations got past the checksum to the decoder
    # A mutated state merged with the intact one.
    for k in range(0, 40, 4):
        call(f"merge #{k}", candela.merge, [rendered / "tiny.state", tmp_path / f"m{k}.state"],
             tmp_path / f"merged{k}")


def random_array(rng: random.Random):
    shape = rng.choice([(), (0,), (1,), (2,), (95,), (3, 95), (2, 3), (0, 95), (95, 3), (2, 2, 95)])
    dtype = rng.choice([np.float64, np.float32, np.int32, np.bool_, np.complex128, object, "U3"])
    a = np.zeros(shape, dtype=np.float64)
    if a.size:
        a = np.asarray([rng.choice([0.0, 1.0, -1.0, 1e308, -1e-320, math.nan, math.inf, rng.random()])
                        for _ in range(a.size)]).reshape(shape)
    try:
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            a = a.astype(dtype)
    except (TypeError, ValueError):
        pass
    if a.ndim == 2 and rng.random() < 0.3:
        a = np.asfortranarray(a)
    elif a.ndim >= 1 and a.shape[-1] > 2 and rng.random() < 0.3:
        a = np.repeat(a, 2, axis=-1)[..., ::2]  # a non-contiguous view
    return a


def test_colour_arrays():
    rng = random.Random(15 + SEED)
    wl = np.arange(360.0, 835.0, 5.0)
    for k in range(n(2000)):
        choice = rng.randrange(5)
        w = rng.choice([wl, wl[::-1], wl[:3], np.array([500.0, 500.0]), np.array([]),
                        wl.astype(np.float32), wl[::2], [-1e308, 1e308], "wl", None,
                        np.array([[400.0, 500.0]])])
        v = random_array(rng) if rng.random() < 0.8 else rng.choice(NASTY)
        if choice == 0:
            kind = rng.choice(["absolute", "emissive", "relative", "bogus", 5])
            ill = rng.choice([None, (wl, np.ones(95)), (wl,), (wl, "x"), 5, (wl[:2], [1.0, math.nan])])
            call(f"sd_to_xyz #{k}", colour.sd_to_xyz, w, v, kind=kind, illuminant=ill,
                 observer=rng.choice(["1931", "1964", "2000", None]),
                 method=rng.choice(["integration", "astm-e308", "", 1.0]))
        elif choice == 1:
            call(f"xyz_to_xy #{k}", colour.xyz_to_xy, v)
        elif choice == 2:
            call(f"xyz_to_cct_duv #{k}", colour.xyz_to_cct_duv, v,
                 method=rng.choice(["ohno2013", "robertson1968", "x", None]))
        else:
            f = rng.choice([colour.cri, colour.tm30, colour.alpha_opic])
            call(f"{f.__name__} #{k}", f, w, v)
    for name in ["D65", "", "\x00", "d65", 5, None, "x" * 10000]:
        call(f"named_spectrum {name!r:.20}", colour.named_spectrum, name)


def test_render_and_merge_arguments(rendered, tmp_path):
    rng = random.Random(16 + SEED)
    scene = candela.Scene.from_ron(tiny_text(), name="args")
    pools = {
        "spp": [0, -1, 1, 2, 2**32, 2**40, 1.5, "4", True, None, np.int64(1)],
        "seed": [-1, 0, 2**64 - 1, 2**64, 2**100, 1.0, "1", None],
        "max_depth": [-1, 0, 3, 2**32, 0.5, None],
        "threads": [0, -1, 1, 2, 10**6, 2**70, 1.0, "2", None],
        "exposure_ev": [math.nan, math.inf, -math.inf, 1e9, 101.0, -100.0, 0.0, "1", None],
        "target_error": [None, None, 0.0, 1.0, -0.5, math.nan, 0.5, "0.1"],
        "target_fraction": [1.0, 0.0, 1.5, math.nan, -1.0, 0.5],
        "target_floor_cd_m2": [None, -1.0, math.nan, math.inf, 0.0, 1.0],
        "max_spp": [None, 0, 1, 2**40, -3, 2.0],
        "max_time_s": [0.5, 0.5, math.nan, -1.0, math.inf, 1e300, "1"],
        "checkpoint_interval_s": [None, 0.0, -1.0, math.nan, 1e-9, 1e300],
        "units": ["si", "imperial", "metric", None, 5],
        "caustics": [None, "light-tracing", "path-tracing", "x", 5],
        "shard": [None, (0, 2), (2, 2), (-1, 2), (0, 0), (1.5, 2), ("a", 2), "1/2", "x", (0,), 5],
        "spectral_bands": [0, 4, -1, 65, 10**9, 2**70, 1.5, None],
        "illuminance": [False, True, 1, None],
        "resume": [False, True, 1],
        "overwrite": [False, True, "yes"],
        "progress": [None, None, 5, lambda *a: None, lambda *a: False],
        "cancel": [None, None, 5, threading.Event()],
    }
    outcomes = {"rendered": 0, "refused": 0}
    for k in range(n(80)):
        # One to three arguments fuzzed, the others valid: the checks of each are reached.
        kwargs = {"spp": 1, "max_time_s": 0.5}
        for name in rng.sample(sorted(pools), rng.randint(1, 3)):
            kwargs[name] = rng.choice(pools[name])
        out = rng.choice([tmp_path / f"o{k}"] * 6 + [5, str(DATA / "small-room.ron"), "/dev/null",
                                                     tmp_path / "x\x00y"])
        if isinstance(out, os.PathLike) and "\0" not in str(out):
            os.makedirs(out, exist_ok=True)
        r = call(f"render #{k} {kwargs}", candela.render, scene, out=out, **kwargs)
        outcomes["refused" if isinstance(r, BaseException) else "rendered"] += 1
    assert min(outcomes.values()) >= n(5), outcomes
    state = rendered / "tiny.state"
    for k, (states, out, ev) in enumerate([
        ([state], tmp_path / "m1", None), ([state, state], tmp_path / "m2", math.nan),
        ([], tmp_path / "m3", None), (str(state), tmp_path / "m4", None),
        ([state], state, None), ([state], rendered / "tiny", None), ([5], tmp_path / "m5", None),
        ([state], tmp_path, 1e9), (None, None, None), ([state], tmp_path / "m6", "1"),
    ]):
        call(f"merge #{k}", candela.merge, states, out, exposure_ev=ev)
