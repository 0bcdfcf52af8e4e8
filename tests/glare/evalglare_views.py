"""Pictures in tilted, rolled and other views, with their evalglare results, for
tests/glare_views.rs.

Usage: evalglare_views.py OUTDIR. Writes Radiance pictures to OUTDIR and prints a JSON list,
one object per evaluation: {"kind", "picture", "view", "options", "dgp", "av_lum", "ev", "lb",
"ev_dir", "dgi", "ugr", "vcp", "cgi", "sources": [[npix, x, y, L, omega, posindex, xdir,
ydir, zdir], ...]}. Kinds:
- "sources": a 240 × 240 angular fisheye picture written pixel by pixel (a graded background,
  bright blocks at known places, one with three luminance levels for peak extraction) under
  level, tilted (26.6° down, 45° up) and rolled views (`-vu` tilted sideways), evaluated with
  evalglare's defaults and with -q and -Y;
- "rendered": the rooms of evalglare_cases.py rendered by rpict in tilted and rolled views;
- "uniform": a uniform 100 cd/m² picture in each view type, for E_v.
"""

import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import evalglare_cases as cases  # noqa: E402

ENV = cases.ENV


def run(cmd, cwd, binary=False):
    r = subprocess.run(cmd, capture_output=True, env=ENV, cwd=cwd, text=not binary)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr}")
    return r.stdout


def rgbe(v):
    """Radiance's RGBE bytes of a grey value v (brightness, W/sr/m²)."""
    if v <= 1e-32:
        return bytes(4)
    m, e = math.frexp(v)
    c = int(m * 256.0)
    return bytes((c, c, c, e + 128))


def write_picture(path, width, height, lum, view):
    """lum(col, row) in cd/m², row 0 at the top; flat (unencoded) scanlines."""
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1\n")
        f.write(f"VIEW= {view}\n\n-Y {height} +X {width}\n".encode())
        for row in range(height):
            f.write(b"".join(rgbe(lum(col, row) / 179.0) for col in range(width)))


def parse(text):
    lines = [ln for ln in text.strip().splitlines() if ln.strip()]
    last = [ln for ln in lines if ln.startswith("dgp,")][-1].split(":")[1].split()
    keys = ["dgp", "av_lum", "ev", "lb", "ev_dir", "dgi", "ugr", "vcp", "cgi"]
    out = {k: float(v) for k, v in zip(keys, last)}
    sources = []
    for ln in lines:
        f = ln.split()
        if len(f) > 15 and f[0].isdigit() and f[1] != "No" and float(f[1]) > 0:
            sources.append([float(f[i]) for i in (1, 2, 3, 4, 5, 6, 13, 14, 15)])
    out["sources"] = sources
    return out


def evalglare(path, opts, cwd):
    r = subprocess.run(["evalglare", "-d", *opts, path], capture_output=True, text=True,
                       env=ENV, cwd=cwd)
    if r.returncode != 0:
        sys.exit(f"evalglare {opts} {path} failed: {r.stderr}")
    return parse(r.stdout)


N = 240
# Blocks: (col, row, half size, luminance); the last has three levels for -Y.
BLOCKS = [(120, 120, 1, 20000.0), (120, 50, 1, 8000.0), (120, 190, 1, 12000.0),
          (50, 120, 1, 15000.0), (190, 120, 1, 9000.0), (60, 60, 1, 30000.0),
          (180, 180, 1, 6000.0), (70, 175, 1, 25000.0), (175, 65, 2, 5000.0)]


def block_luminance(col, row):
    for c, r, h, l in BLOCKS:
        if abs(col - c) <= h and abs(row - r) <= h:
            if (c, r) == (175, 65):
                d = max(abs(col - c), abs(row - r))
                return [90000.0, 30000.0, 5000.0][d]
            return l
    u, v = col / N, row / N
    return 20.0 + 300.0 * u ** 3 + 60.0 * v


# name, -vd, -vu
VIEWS = [("level", "0 1 0", "0 0 1"),
         ("down26", "0 2 -1", "0 0 1"),
         ("up45", "0 1 1", "0 0 1"),
         ("rolled", "0 2 -1", "0.5 0 1"),
         ("roll_only", "0 1 0", "0.5 0 1")]
OPTION_SETS = {"down26": [[], ["-q", "1"], ["-q", "2"], ["-Y", "20000"], ["-Y", "100000"]],
               "level": [[], ["-q", "1"], ["-Y", "20000"]]}

# Rendered rooms: scene of evalglare_cases.CASES, view point, -vd, -vu.
RENDERED = [("patch_down26", "patch", "1 4 1.2", "1 -0.3 -0.522", "0 0 1"),
            ("overcast_up45", "overcast", "2 3 1.2", "0.3 -1 1.044", "0 0 1"),
            ("office_rolled", "office", "2 0.8 1.2", "0 1 -0.5", "0.4 0 1")]

# Uniform pictures: view options, width, height.
UNIFORM = [("-vta -vh 180 -vv 180", 200, 200), ("-vta -vh 360 -vv 360", 200, 200),
           ("-vta -vh 270 -vv 180", 300, 200), ("-vta -vh 120 -vv 120", 200, 200),
           ("-vth -vh 180 -vv 180", 200, 200), ("-vth -vh 120 -vv 120", 200, 200),
           ("-vth -vh 180 -vv 106.260205", 250, 200),
           ("-vts -vh 180 -vv 180", 200, 200), ("-vts -vh 240 -vv 240", 200, 200),
           ("-vtv -vh 90 -vv 90", 200, 200), ("-vtv -vh 170 -vv 170", 200, 200)]


def main():
    out_dir = sys.argv[1]
    os.makedirs(out_dir, exist_ok=True)
    results = []
    for name, vd, vu in VIEWS:
        pic = f"sources_{name}.hdr"
        view = f"-vta -vp 0 0 0 -vd {vd} -vu {vu} -vh 180 -vv 180"
        write_picture(os.path.join(out_dir, pic), N, N, block_luminance, view)
        for opts in OPTION_SETS.get(name, [[]]):
            r = evalglare(pic, opts, out_dir)
            r.update(kind="sources", picture=pic, view=view, options=opts)
            results.append(r)
    scenes = {c[0]: c for c in cases.CASES}
    cases.OUT = out_dir
    for name, scene, vp, vd, vu in RENDERED:
        parts = scenes[scene][1]
        rad = os.path.join(out_dir, f"{name}.rad")
        with open(rad, "w") as f:
            for p in parts:
                f.write(run(p.split(), out_dir) if p.startswith("gensky") else p)
        octree = run(["oconv", rad], out_dir, binary=True)
        oct_path = os.path.join(out_dir, f"{name}.oct")
        with open(oct_path, "wb") as f:
            f.write(octree)
        view = ["-vta", "-vh", "180", "-vv", "180", "-vp", *vp.split(), "-vd", *vd.split(),
                "-vu", *vu.split()]
        pic = run(["rpict", *view, "-x", "320", "-y", "320", "-ps", "1", "-pj", "0", "-ab",
                   "1", "-ad", "128", "-as", "0", "-aa", "0.15", "-ar", "64", oct_path],
                  out_dir, binary=True)
        with open(os.path.join(out_dir, f"{name}.hdr"), "wb") as f:
            f.write(pic)
        r = evalglare(f"{name}.hdr", [], out_dir)
        r.update(kind="rendered", picture=f"{name}.hdr", view=" ".join(view), options=[])
        results.append(r)
    for k, (view, w, h) in enumerate(UNIFORM):
        pic = f"uniform_{k}.hdr"
        write_picture(os.path.join(out_dir, pic), w, h, lambda c, r: 100.0,
                      f"{view.split()[0]} -vp 0 0 0 -vd 0 1 0 -vu 0 0 1 {' '.join(view.split()[1:])}")
        r = evalglare(pic, [], out_dir)
        r.update(kind="uniform", picture=pic, view=view, options=[])
        results.append(r)
    json.dump(results, sys.stdout)


if __name__ == "__main__":
    main()
