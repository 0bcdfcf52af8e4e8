"""Fisheye luminance images and their evalglare results for tests/glare_evalglare.rs.

Usage: evalglare_cases.py OUTDIR. Builds three scenes with Radiance's own tools (a room with a
south window and a low winter sun, the same room under an overcast sky, an office lit by four
ceiling luminaires), renders angular fisheye views (rpict -vta -vh 180 -vv 180), runs
`evalglare -d` with several option sets on each, and writes each image's luminance per pixel
(cd/m², 179 × pvalue's brightness, raw little-endian doubles in Radiance's scanline order: top
row first, left to right) to OUTDIR/NAME.f64. Prints a JSON list, one object per evaluation:
{"image", "width", "height", "options", "dgp", "av_lum", "ev", "lb", "ev_dir", "dgi", "ugr",
"vcp", "cgi", "sources": [[npix, x, y, L, omega, posindex], ...]}.
"""

import json
import os
import subprocess
import sys

import pyradiance

PKG = os.path.dirname(pyradiance.__file__)
ENV = dict(os.environ, PATH=os.path.join(PKG, "bin") + os.pathsep + os.environ["PATH"],
           RAYPATH="." + os.pathsep + os.path.join(PKG, "lib"))
SIZE = 320

ROOM = """
void plastic wall 0 0 5 0.5 0.5 0.5 0 0
void plastic floor 0 0 5 0.2 0.2 0.2 0 0
void plastic ceiling 0 0 5 0.8 0.8 0.8 0 0
floor polygon fl 0 0 12 0 0 0  0 5 0  4 5 0  4 0 0
ceiling polygon ce 0 0 12 0 0 3  4 0 3  4 5 3  0 5 3
wall polygon north 0 0 12 0 5 0  0 5 3  4 5 3  4 5 0
wall polygon west 0 0 12 0 0 0  0 0 3  0 5 3  0 5 0
wall polygon east 0 0 12 4 0 0  4 5 0  4 5 3  4 0 3
"""
WINDOW_WALL = """
wall polygon sill 0 0 12 0 0 0  4 0 0  4 0 0.8  0 0 0.8
wall polygon head 0 0 12 0 0 2.5  4 0 2.5  4 0 3  0 0 3
wall polygon jl 0 0 12 0 0 0.8  0.5 0 0.8  0.5 0 2.5  0 0 2.5
wall polygon jr 0 0 12 3.5 0 0.8  4 0 0.8  4 0 2.5  3.5 0 2.5
"""
CLOSED_WALL = "wall polygon south 0 0 12 0 0 0  4 0 0  4 0 3  0 0 3\n"
SKY = """
skyfunc glow skyglow 0 0 4 1 1 1 0
skyglow source sky 0 0 4 0 0 1 180
skyfunc glow groundglow 0 0 4 1 1 1 0
groundglow source ground 0 0 4 0 0 -1 180
"""
# 5000 cd/m² luminaires (Radiance radiance × 179 lm/W), facing down.
LAMPS = "void light lamp 0 0 3 27.9 27.9 27.9\n" + "".join(
    f"lamp polygon l{i} 0 0 12 {x} {y} 2.99  {x} {y + 0.6} 2.99  {x + 0.6} {y + 0.6} 2.99  "
    f"{x + 0.6} {y} 2.99\n"
    for i, (x, y) in enumerate([(0.7, 2.2), (2.7, 2.2), (0.7, 3.7), (2.7, 3.7)]))

# name, scene parts, view point, view direction, evalglare option sets
CASES = [
    ("sun", ["gensky 12 21 12 -a 47 -o -8 -m -15 +s", SKY, ROOM, WINDOW_WALL],
     "2 2.5 1.2", "0 -1 0", [[], ["-x"]]),
    ("patch", ["gensky 12 21 12 -a 47 -o -8 -m -15 +s", SKY, ROOM, WINDOW_WALL],
     "1 4 1.2", "1 -0.3 0", [[], ["-b", "5"]]),
    ("overcast", ["gensky 3 21 12 -a 47 -o -8 -m -15 -c -B 100", SKY, ROOM, WINDOW_WALL],
     "2 3 1.2", "0.3 -1 0", [[], ["-t", "160", "120", "0.6"], ["-r", "0.4"]]),
    ("office", [LAMPS, ROOM, CLOSED_WALL], "2 0.8 1.2", "0 1 0", [[], ["-r", "0.1"]]),
]


def run(cmd, stdin=None, binary=False):
    r = subprocess.run(cmd, input=stdin, capture_output=True, env=ENV, cwd=OUT,
                       text=not binary)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr}")
    return r.stdout


def parse(text):
    lines = text.strip().splitlines()
    last = lines[-1].split(":")[1].split()
    keys = ["dgp", "av_lum", "ev", "lb", "ev_dir", "dgi", "ugr", "vcp", "cgi"]
    out = {k: float(v) for k, v in zip(keys, last)}
    sources = []
    for ln in lines[:-1]:
        f = ln.split()
        if len(f) > 6 and f[1] != "No" and int(f[0]) > 0:
            sources.append([float(v) for v in f[1:7]])
    out["sources"] = sources
    return out


def main():
    global OUT
    OUT = sys.argv[1]
    os.makedirs(OUT, exist_ok=True)
    results = []
    for name, parts, vp, vd, option_sets in CASES:
        rad = os.path.join(OUT, f"{name}.rad")
        with open(rad, "w") as f:
            for p in parts:
                f.write(run(p.split()) if p.startswith("gensky") else p)
        octree = run(["oconv", rad], binary=True)
        oct_path = os.path.join(OUT, f"{name}.oct")
        with open(oct_path, "wb") as f:
            f.write(octree)
        hdr = os.path.join(OUT, f"{name}.hdr")
        pic = run(["rpict", "-vta", "-vh", "180", "-vv", "180", "-vp", *vp.split(), "-vd",
                   *vd.split(), "-vu", "0", "0", "1", "-x", str(SIZE), "-y", str(SIZE),
                   "-ps", "1", "-pj", "0", "-ab", "1", "-ad", "128", "-as", "0", "-aa",
                   "0.15", "-ar", "64", oct_path], binary=True)
        with open(hdr, "wb") as f:
            f.write(pic)
        raw = run(["pvalue", "-h", "-H", "-o", "-b", "-dd", hdr], binary=True)
        import array
        a = array.array("d")
        a.frombytes(raw)
        assert len(a) == SIZE * SIZE, len(a)
        a = array.array("d", (179.0 * v for v in a))
        with open(os.path.join(OUT, f"{name}.f64"), "wb") as f:
            f.write(a.tobytes())
        for opts in option_sets:
            r = parse(run(["evalglare", "-d", *opts, hdr]))
            r.update(image=name, width=SIZE, height=SIZE, options=opts)
            results.append(r)
    json.dump(results, sys.stdout)


if __name__ == "__main__":
    main()
