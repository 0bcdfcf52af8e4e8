#!/usr/bin/env python3
"""Annual daylight of the shoebox (scenes/annual-shoebox.ron) by Radiance's matrix method.

    python scripts/radiance_annual.py WEATHER.epw [--mf 2] [--ab 12] [--ad 65536] [--lw 1e-7]
        [--sun-ad 1024] [--sun-disk 37] [--sun-ir hourly|patches]
        [--nproc 2] [--work DIR] > out.json

Needs Radiance 6 on PATH with RAYPATH set (pyradiance's wheel: bin/ and lib/; bench/annual.sh sets
them) and numpy.

Frame. candela's scene is y up, +z south, +x east. Radiance's skies (gendaymtx, reinhart.cal with
`u=+Y`) are z up, +y north, +x east, so the model is rotated into Radiance's frame:
(X, Y, Z) = (x, -z, y), a proper rotation (det +1). The south window (candela z = 6) is at
Y = -6 facing -Y = south; the sensors are at Z = 0.8 facing +Z.

Method: daylight coefficients for the sky; for the sun, each sunny hour's own sun, traced once
for its inter-reflected light and once, as sub-suns over its disk, for its direct light:

    E_total = DC_sky(ab N) . sky  +  (suns(ab N) - suns(ab 0))  +  disk suns(ab 0)

- sky: gendaymtx -m MF -O0 -s (-O0 is visible radiance, W sr^-1 m^-2 at 179 lm/W; -O1 would
  be full-spectrum solar radiance; sky only; patch 0 the ground, reflectance 0.2, lit by sky
  and sun).
- DC_sky: rfluxmtx, the sensors as sender rays (-I), the receiver the ground hemisphere (h=u)
  then the Reinhart sky (h=rMF, u=+Y), gendaymtx's patch order.
- suns: one `light` per sunny hour (gendaymtx -D: the direct-normal illuminance of gendaymtx's
  Perez efficacy; hours without beam dropped) at the hour's sun position (by default ladybug's
  NOAA position with refraction, as candela's, within about 0.05 degrees; gendaymtx's own
  formula is up to 1 degree off), one modifier per sun.
- Inter-reflected sun (--sun-ir hourly, the default): rcontrib with the suns at -ab N and at
  -ab 0. Both compute the direct part with the same deterministic shadow ray (-dj 0 -dc 1
  -dt 0), so their difference is the inter-reflected sun alone, free of the direct part's
  noise (subtracting a one-bounce DC from an N-bounce one, as honeybee's recipe does, leaves
  the two runs' sampling noise of the sun seen through the pane, several times the
  inter-reflected part near the window). --sun-ir patches instead traces one sun at the centre
  of each sky patch the year's sun reaches and weights them per hour as gendaymtx -d spreads
  the hour's sun over the 4 nearest patches: cheaper for a long year, but an interpolation
  (about 3 % RMS in sunny hours against the hourly suns).
- Direct sun (ASE, LM-83: direct sun, no inter-reflection; and part of the total): each sun as
  --sun-disk N sub-suns (default 37: the centre and rings of 6, 12, 18) spread over the
  0.533-degree disk with equal shares of its solid angle, rcontrib -ab 0 -dj 0: one shadow ray
  to each, so a disk partly hidden by the window's edge gives part of its light, as candela's
  integral over the disk does. --sun-disk 1 is one ray to the disk's centre.
- dctimestep applies DC_sky to the sky matrix; rmtxop -c 47.4 119.9 11.6 turns RGB irradiance
  into illuminance (lx).

Efficacy: epw2wea passes irradiances and gendaymtx converts them with the Perez (1990) efficacy
at a dew point of 11 C (a wea has none). --photometric writes the wea from the EPW's
illuminance fields instead (units 3), which for scripts/synthetic_epw.py are the Perez efficacy
at each record's dew point, as candela computes it.

Metrics over the occupied hours 8:00-18:00 local standard time, i.e. the EPW records of hours
9..18 of every day (the record of hour h covers (h-1):00-h:00): DA300, cDA300, UDI 100-3000
(with the fell-short and exceeded shares), sDA300/50 % (share of points with DA300 >= 0.5),
ASE1000,250h (share of points with more than 250 occupied hours of direct sun > 1000 lx). No
blinds are modelled.

Output: JSON on stdout with per point hourly illuminance (lx, all 8760 records), the direct-sun
illuminance, the metrics, per stage wall-clock times and the peak resident memory of the
children (the largest one, as getrusage reports it) and of this script.
"""

import argparse
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

# Room, materials and grid of scenes/annual-shoebox.ron in candela's frame (y up, +z south).
WALL, CEILING, FLOOR = 0.5, 0.8, 0.2
GRID_X = [0.4 + 0.8 * i for i in range(5)]
GRID_Z = [0.6 + 0.8 * j for j in range(7)]
GRID_Y = 0.8
OCCUPIED_HOURS = range(9, 19)  # EPW record hours: 8:00-18:00 local standard time
WEIGHTS = (47.4, 119.9, 11.6)  # Radiance RGB -> illuminance (lm/W)


def to_rad(p):
    """candela (x, y up, z south) -> Radiance (X east, Y north, Z up)."""
    x, y, z = p
    return (x, -z, y)


def quad(mod, name, origin, eu, ev):
    """A Radiance polygon for candela's Quad (origin, edge_u, edge_v), in Radiance's frame."""
    o = np.array(origin, float)
    u = np.array(eu, float)
    v = np.array(ev, float)
    pts = [o, o + u, o + u + v, o + v]
    coords = " ".join("%g %g %g" % to_rad(p) for p in pts)
    return "%s polygon %s\n0\n0\n12 %s\n" % (mod, name, coords)


def scene_rad():
    # Plastic with no specular; glass with transmissivity 1 (no absorption) and n = 1.52:
    # Radiance's glass parameters are transmissivity, its Fresnel reflections come on top.
    s = [
        "void plastic wall\n0\n0\n5 %g %g %g 0 0\n" % (WALL, WALL, WALL),
        "void plastic ceiling\n0\n0\n5 %g %g %g 0 0\n" % (CEILING, CEILING, CEILING),
        "void plastic floor\n0\n0\n5 %g %g %g 0 0\n" % (FLOOR, FLOOR, FLOOR),
        "void glass pane\n0\n0\n4 1 1 1 1.52\n",
    ]
    # Radiance polygons are two-sided, so the winding of candela's quads does not matter here.
    s += [
        quad("floor", "floor", (0, 0, 0), (0, 0, 6), (4, 0, 0)),
        quad("ceiling", "ceiling", (0, 3, 0), (4, 0, 0), (0, 0, 6)),
        quad("wall", "west", (0, 0, 0), (0, 3, 0), (0, 0, 6)),
        quad("wall", "east", (4, 0, 0), (0, 0, 6), (0, 3, 0)),
        quad("wall", "north", (0, 0, 0), (4, 0, 0), (0, 3, 0)),
        quad("wall", "south_below", (0, 0, 6), (0, 0.9, 0), (4, 0, 0)),
        quad("wall", "south_above", (0, 2.4, 6), (0, 0.6, 0), (4, 0, 0)),
        quad("wall", "south_west", (0, 0.9, 6), (0, 1.5, 0), (0.5, 0, 0)),
        quad("wall", "south_east", (3.5, 0.9, 6), (0, 1.5, 0), (0.5, 0, 0)),
        quad("pane", "pane", (0.5, 0.9, 6), (0, 1.5, 0), (3, 0, 0)),
    ]
    return "".join(s)


def sky_receiver(mf):
    # Patch 0 the ground hemisphere, then the Reinhart patches: gendaymtx's row order.
    return (
        "#@rfluxmtx h=u u=+Y\n"
        "void glow groundglow\n0\n0\n4 1 1 1 0\n"
        "groundglow source ground\n0\n0\n4 0 0 -1 180\n"
        "#@rfluxmtx h=r%d u=+Y\n"
        "void glow skyglow\n0\n0\n4 1 1 1 0\n"
        "skyglow source skydome\n0\n0\n4 0 0 1 180\n" % mf
    )


def reinhart_patches(mf):
    """Centre directions (Radiance frame) and solid angles (sr) of gendaymtx's patches 0..N-1
    (0 the ground), as gendaymtx's rh_init lays them out: azimuth from +Y (north) towards +X."""
    tnaz = (30, 30, 24, 24, 18, 12, 6)
    alpha = (np.pi / 2.0) / (7 * mf + 0.5)
    dirs, doms = [(0.0, 0.0, -1.0)], [2.0 * np.pi]
    for i in range(7 * mf):
        alt = alpha * (i + 0.5)
        n = tnaz[i // mf] * mf
        dom = 2.0 * np.pi * (np.sin(alpha * (i + 1)) - np.sin(alpha * i)) / n
        for j in range(n):
            azi = 2.0 * np.pi * j / n
            dirs.append((np.cos(alt) * np.sin(azi), np.cos(alt) * np.cos(azi), np.sin(alt)))
            doms.append(dom)
    dirs.append((0.0, 0.0, 1.0))
    doms.append(2.0 * np.pi * (1.0 - np.cos(alpha * 0.5)))
    return np.array(dirs), np.array(doms)


def photometric_wea(epw, out):
    """A wea in photometric units (weather_data_file_units 3: direct-normal and diffuse-horizontal
    illuminance, lx) from the EPW's illuminance fields, with epw2wea's header and hour labels."""
    with open(epw) as f:
        lines = f.read().splitlines()
    loc = lines[0].split(",")
    rows = [line.split(",") for line in lines[8:] if line.strip()]
    head = "place %s_%s\nlatitude %s\nlongitude %.6f\ntime_zone %.0f\nsite_elevation %s\n" % (
        loc[1], loc[3], loc[6], -float(loc[7]), -15.0 * float(loc[8]), loc[9])
    body = []
    for r in rows:
        dn, dh = float(r[17]), float(r[18])
        if dn >= 999999 or dh >= 999999:
            sys.exit("--photometric: the EPW has no illuminance fields (999999)")
        body.append("%d %d %.3f %.0f %.0f" % (int(r[1]), int(r[2]), int(r[3]) - 0.5, dn, dh))
    with open(out, "w") as f:
        f.write(head + "weather_data_file_units 3\n" + "\n".join(body) + "\n")


def ladybug_suns(suns_rad, lat, lon, tz):
    """Rewrite gendaymtx's -D suns with NOAA positions (ladybug, with refraction) for each
    sun's hour: gendaymtx's own formula is up to about 1 degree off."""
    from ladybug.sunpath import Sunpath
    import datetime

    sp = Sunpath(lat, lon, tz)
    text = open(suns_rad).read()

    def fix(m):
        t = (int(m.group(1)) - 30) // 60
        day = datetime.date(2017, 1, 1) + datetime.timedelta(days=t // 24)
        sun = sp.calculate_sun(day.month, day.day, t % 24 + 0.5)
        alt, az = np.radians(sun.altitude), np.radians(sun.azimuth)
        return "solar%s source sun%s\n0\n0\n4 %.6f %.6f %.6f 0.5330" % (
            m.group(1), m.group(1), np.cos(alt) * np.sin(az), np.cos(alt) * np.cos(az), np.sin(alt))

    text = re.sub(r"solar(\d+) source sun\d+\n0\n0\n4 \S+ \S+ \S+ \S+", fix, text)
    with open(suns_rad, "w") as f:
        f.write(text)


def disk_offsets(n):
    """n points over a disk of radius 1 with equal shares of its area: the centre, then rings of
    6, 12, 18, ... points (n = 1, 7, 19, 37, 61, ...), each point at the radius that halves its
    ring's area, every other ring turned by half a step. Returns (x, y) pairs."""
    rings = 0
    while 1 + 3 * rings * (rings + 1) < n:
        rings += 1
    if 1 + 3 * rings * (rings + 1) != n:
        sys.exit("--sun-disk: N must be 1 + 3k(k+1) (1, 7, 19, 37, 61, ...), not %d" % n)
    pts = [(0.0, 0.0)]
    for i in range(1, rings + 1):
        inner, outer = 1 + 3 * (i - 1) * i, 1 + 3 * i * (i + 1)
        rho = np.sqrt(0.5 * (inner + outer) / n)
        for j in range(6 * i):
            phi = 2.0 * np.pi * (j + 0.5 * (i % 2)) / (6 * i)
            pts.append((rho * np.cos(phi), rho * np.sin(phi)))
    return pts


def split_suns(suns_rad, n):
    """Replace every sun of gendaymtx -D (a 0.533-degree `source`) by n sources of the same
    modifier spread over its disk, each of 1/n of its solid angle: with -dj 0 Radiance traces
    one shadow ray to each, so the direct sun integrates the disk (its penumbra) as candela does
    instead of testing the disk's centre alone."""
    half = np.radians(0.533 / 2.0)
    # Each sub-sun's half-angle: n of them have the solid angle 2 pi (1 - cos half) of the disk.
    sub = np.degrees(2.0 * np.arccos(1.0 - (1.0 - np.cos(half)) / n))
    offsets = disk_offsets(n)
    text = open(suns_rad).read()

    def split(m):
        d = np.array([float(m.group(i)) for i in (3, 4, 5)])
        d /= np.linalg.norm(d)
        u = np.cross(d, (0.0, 0.0, 1.0) if abs(d[2]) < 0.9 else (1.0, 0.0, 0.0))
        u /= np.linalg.norm(u)
        v = np.cross(d, u)
        out = []
        for k, (a, b) in enumerate(offsets):
            e = d + np.tan(half) * (a * u + b * v)
            e /= np.linalg.norm(e)
            out.append("%s source %s_%d\n0\n0\n4 %.9f %.9f %.9f %.6f"
                       % (m.group(1), m.group(2), k, e[0], e[1], e[2], sub))
        return "\n\n".join(out)

    text = re.sub(r"(solar\d+) source (sun\d+)\n0\n0\n4 (\S+) (\S+) (\S+) \S+", split, text)
    with open(suns_rad, "w") as f:
        f.write(text)


def drop_dark_suns(work):
    """Remove gendaymtx -D's suns of zero radiance (hours without beam: overcast, or the dark
    days of a shortened year) from suns.rad and suns.mod: they add nothing but shadow rays."""
    text = open(os.path.join(work, "suns.rad")).read()
    dark = set(re.findall(r"void light (solar\d+)\n0\n0\n3 0\.000e\+00 0\.000e\+00 0\.000e\+00\n",
                          text))
    blocks = [b for b in re.split(r"\n(?=void light |solar\d+ source )", text)
              if not b.startswith(("void light ", "solar"))
              or b.split()[0 if b.startswith("solar") else 2] not in dark]
    with open(os.path.join(work, "suns.rad"), "w") as f:
        f.write("\n".join(blocks) + "\n")
    mods = [m.strip() for m in open(os.path.join(work, "suns.mod")) if m.strip()]
    with open(os.path.join(work, "suns.mod"), "w") as f:
        f.write("".join(m + "\n" for m in mods if m not in dark))


def sensors():
    """Grid points in candela's order (x fastest, then z), as Radiance rays facing up."""
    pts = [(x, GRID_Y, z) for z in GRID_Z for x in GRID_X]
    lines = ["%g %g %g 0 0 1" % to_rad(p) for p in pts]
    return pts, "\n".join(lines) + "\n"


class Runner:
    def __init__(self, work):
        self.work = work
        self.times = {}
        self.cpu = {}

    def run(self, stage, cmd, stdin=None, stdout=None):
        t0 = time.perf_counter()
        ru = resource.getrusage(resource.RUSAGE_CHILDREN)
        c0 = ru.ru_utime + ru.ru_stime
        fin = open(os.path.join(self.work, stdin), "rb") if stdin else None
        fout = open(os.path.join(self.work, stdout), "wb") if stdout else subprocess.PIPE
        try:
            p = subprocess.run(cmd, cwd=self.work, stdin=fin, stdout=fout, stderr=subprocess.PIPE)
        finally:
            if fin:
                fin.close()
            if stdout:
                fout.close()
        self.times[stage] = self.times.get(stage, 0.0) + time.perf_counter() - t0
        ru = resource.getrusage(resource.RUSAGE_CHILDREN)
        self.cpu[stage] = self.cpu.get(stage, 0.0) + ru.ru_utime + ru.ru_stime - c0
        if p.returncode != 0:
            sys.exit("%s failed (%d): %s\n%s" % (stage, p.returncode, " ".join(cmd), p.stderr.decode()))
        return p.stdout


def read_matrix(path):
    """A Radiance float matrix (header NROWS/NCOLS/NCOMP, then binary float32) as (rows, cols, comps)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"\n\n") + 2
    head = data[:end].decode(errors="replace")
    dims = {k: int(v) for k, v in re.findall(r"(NROWS|NCOLS|NCOMP)=(\d+)", head)}
    fmt = re.search(r"FORMAT=(\S+)", head).group(1)
    dtype = {"float": "<f4", "double": "<f8"}[fmt]
    a = np.frombuffer(data[end:], dtype=dtype)
    return a.reshape(dims["NROWS"], dims["NCOLS"], dims.get("NCOMP", 3)).astype(np.float64)


def metrics(total, direct, sda_fraction=0.5, ase_hours=250.0):
    """total, direct: (points, 8760) lx. Occupied records: hours 9..18 of each day."""
    hours = np.arange(8760) % 24 + 1
    occ = np.isin(hours, list(OCCUPIED_HOURS))
    e = total[:, occ]
    d = direct[:, occ]
    n_occ = int(occ.sum())
    da = (e >= 300.0).mean(axis=1)
    cda = np.minimum(e / 300.0, 1.0).mean(axis=1)
    udi_short = (e < 100.0).mean(axis=1)
    udi = ((e >= 100.0) & (e <= 3000.0)).mean(axis=1)
    udi_over = (e > 3000.0).mean(axis=1)
    sun_hours = (d > 1000.0).sum(axis=1)
    return {
        "occupied_hours": n_occ,
        "da300": da.tolist(),
        "cda300": cda.tolist(),
        "udi_100_3000": udi.tolist(),
        "udi_fell_short": udi_short.tolist(),
        "udi_exceeded": udi_over.tolist(),
        "sun_hours_over_1000lx": sun_hours.tolist(),
        "sda300_50": float((da >= sda_fraction).mean()),
        "ase1000_250h": float((sun_hours > ase_hours).mean()),
        "mean_occupied_illuminance_lx": e.mean(axis=1).tolist(),
        "mean_occupied_direct_sun_lx": d.mean(axis=1).tolist(),
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("epw")
    ap.add_argument("--mf", type=int, default=2, help="Reinhart subdivision (MF)")
    ap.add_argument("--ab", type=int, default=12, help="bounces (ambient) of the DCs")
    ap.add_argument("--ad", type=int, default=65536, help="ambient divisions of both DCs")
    ap.add_argument("--sun-ad", type=int, default=1024,
                    help="ambient divisions of the inter-reflected sun coefficients")
    ap.add_argument("--lw", type=float, default=1e-7, help="limit weight (below 1/ad)")
    ap.add_argument("--nproc", type=int, default=2)
    ap.add_argument("--work", help="keep the intermediate files here (default: a temporary dir)")
    ap.add_argument("--photometric", action="store_true",
                    help="gendaymtx from the EPW's illuminance fields (Perez efficacy with each "
                    "record's dew point) instead of epw2wea's irradiances (efficacy at 11 C)")
    ap.add_argument("--sun-disk", type=int, default=37,
                    help="direct sun: N sub-suns over the 0.533-degree disk with equal shares "
                    "(1 + 3k(k+1): 1, 7, 19, 37, 61); 1 is one ray to the disk's centre")
    ap.add_argument("--sun-ir", choices=("hourly", "patches"), default="hourly",
                    help="inter-reflected sun: each sunny hour's own sun, or suns at the sky "
                    "patches' centres weighted as gendaymtx -d spreads the hour's sun")
    ap.add_argument("--sda-fraction", type=float, default=0.5,
                    help="sDA: the fraction of occupied hours a point must reach 300 lx")
    ap.add_argument("--ase-hours", type=float, default=250.0,
                    help="ASE: hours of direct sun above 1000 lx a point may have")
    ap.add_argument("--radiance-sun-positions", action="store_true",
                    help="exact suns where gendaymtx puts them, not at ladybug's NOAA positions")
    ap.add_argument("--reuse-dc", action="store_true",
                    help="keep the sky DC and sun coefficients already in --work (same scene and "
                    "settings, another weather file): only the skies, suns and products are redone")
    ap.add_argument("--no-hourly", action="store_true", help="metrics only, no hourly arrays")
    args = ap.parse_args()

    t_start = time.perf_counter()
    work = args.work or tempfile.mkdtemp(prefix="radannual-")
    os.makedirs(work, exist_ok=True)
    r = Runner(work)
    epw = os.path.abspath(args.epw)
    with open(os.path.join(work, "scene.rad"), "w") as f:
        f.write(scene_rad())
    with open(os.path.join(work, "sky.rad"), "w") as f:
        f.write(sky_receiver(args.mf))
    pts, rays = sensors()
    with open(os.path.join(work, "grid.pts"), "w") as f:
        f.write(rays)
    npts = len(pts)

    if args.photometric:
        t0 = time.perf_counter()
        photometric_wea(epw, os.path.join(work, "weather.wea"))
        r.times["epw2wea"] = time.perf_counter() - t0
    else:
        r.run("epw2wea", ["epw2wea", epw, "weather.wea"])
    mf = ["-m", str(args.mf), "-O0", "-of"]
    r.run("gendaymtx", ["gendaymtx"] + mf + ["-s", "weather.wea"], stdout="sky.smx")
    if args.sun_ir == "patches":
        r.run("gendaymtx", ["gendaymtx"] + mf + ["-d", "weather.wea"], stdout="sun.smx")
    r.run("gendaymtx", ["gendaymtx"] + mf + ["-d", "-D", "suns.rad", "-M", "suns.mod", "weather.wea"],
          stdout="nosun.smx")
    r.run("oconv", ["oconv", "scene.rad"], stdout="scene.oct")
    drop_dark_suns(work)
    if not args.radiance_sun_positions:
        loc = open(epw).readline().split(",")
        ladybug_suns(os.path.join(work, "suns.rad"), float(loc[6]), float(loc[7]), float(loc[8]))
    shutil.copy(os.path.join(work, "suns.rad"), os.path.join(work, "suns_centre.rad"))
    if args.sun_ir == "hourly":
        r.run("oconv", ["oconv", "scene.rad", "suns_centre.rad"], stdout="suns_centre.oct")
    if args.sun_disk > 1:
        split_suns(os.path.join(work, "suns.rad"), args.sun_disk)
    r.run("oconv", ["oconv", "scene.rad", "suns.rad"], stdout="suns.oct")

    common = ["-I", "-n", str(args.nproc), "-y", str(npts), "-faf", "-lw", str(args.lw),
              "-lr", "-20", "-aa", "0"]
    def reuse(name):
        return args.reuse_dc and os.path.exists(os.path.join(work, name))

    if not reuse("dc_sky.mtx"):
        r.run("rfluxmtx sky", ["rfluxmtx", "-ab", str(args.ab), "-ad", str(args.ad)] + common
              + ["-", "sky.rad", "scene.rad"], stdin="grid.pts", stdout="dc_sky.mtx")

    direct_opts = ["-dc", "1", "-dt", "0", "-dj", "0", "-dr", "0"]
    sun_mods = [m.strip() for m in open(os.path.join(work, "suns.mod")) if m.strip()]
    if args.sun_ir == "hourly":
        # Inter-reflected sun of every sunny hour's own sun (the disk's centre: the
        # inter-reflected light does not see the disk's size), traced with -ab N and with -ab 0
        # with the same deterministic shadow rays, their difference the inter-reflected light
        # alone. No interpolation between sun positions; the cost grows with the sunny hours.
        for name, ab, ad in (("sun_ir_total", args.ab, args.sun_ad), ("sun_ir_direct", 0, 1)):
            r.run("rcontrib hourly suns", ["rcontrib", "-V+", "-ab", str(ab), "-ad", str(ad)]
                  + common + direct_opts + ["-M", "suns.mod", "suns_centre.oct"],
                  stdin="grid.pts", stdout=name + ".mtx")
    else:
        # Inter-reflected sun: a 0.533-degree sun at the centre of every patch the year's sun
        # reaches, its radiance set for a normal irradiance of 1 W/m^2. Traced with -ab N and with
        # -ab 0 with the same deterministic shadow rays (-dj 0 -dc 1 -dt 0), the difference is the
        # inter-reflected light alone, free of the direct part's sampling noise.
        sun_patch = read_matrix(os.path.join(work, "sun.smx"))[:, :, 1]  # (patches, hours)
        dirs, doms = reinhart_patches(args.mf)
        used = np.nonzero((sun_patch > 0).any(axis=1))[0]
        sun_sr = 2.0 * np.pi * (1.0 - np.cos(np.radians(0.533 / 2.0)))
        mods = "".join("psol%d\n" % p for p in used)
        if reuse("patch_suns.mod") and open(os.path.join(work, "patch_suns.mod")).read() != mods:
            sys.exit("--reuse-dc: the year's sun reaches other patches than in %s" % work)
        with open(os.path.join(work, "patch_suns.rad"), "w") as f:
            for p in used:
                f.write("void light psol%d\n0\n0\n3 %.6g %.6g %.6g\n" % ((p,) + (1.0 / sun_sr,) * 3))
                f.write("psol%d source psun%d\n0\n0\n4 %.9f %.9f %.9f 0.533\n" % ((p, p) + tuple(dirs[p])))
        with open(os.path.join(work, "patch_suns.mod"), "w") as f:
            f.write(mods)
        r.run("oconv", ["oconv", "scene.rad", "patch_suns.rad"], stdout="patch_suns.oct")
        for name, ab, ad in (("sun_coef_total", args.ab, args.sun_ad), ("sun_coef_direct", 0, 1)):
            if reuse(name + ".mtx"):
                continue
            r.run("rcontrib patch suns", ["rcontrib", "-V+", "-ab", str(ab), "-ad", str(ad)] + common
                  + direct_opts + ["-M", "patch_suns.mod", "patch_suns.oct"],
                  stdin="grid.pts", stdout=name + ".mtx")

    # Exact suns, direct only: every sun a point-sampled disk, no jitter needed for a disk of
    # 0.533 degrees; -dt 0 -dc 1 so that no source is skipped.
    r.run("rcontrib suns", ["rcontrib", "-V+", "-I", "-n", str(args.nproc), "-y", str(npts), "-faf",
                            "-ab", "0", "-dc", "1", "-dt", "0", "-dj", "0", "-dr", "0",
                            "-M", "suns.mod", "suns.oct"], stdin="grid.pts", stdout="suns.mtx")

    def timestep(stage, dc, smx, out):
        r.run(stage, ["dctimestep", "-of", dc, smx], stdout=out + ".rgb")
        r.run(stage, ["rmtxop", "-ff", "-c"] + [str(w) for w in WEIGHTS] + [out + ".rgb"],
              stdout=out + ".ill")
        return read_matrix(os.path.join(work, out + ".ill"))[:, :, 0]

    sky = timestep("dctimestep sky", "dc_sky.mtx", "sky.smx", "sky")

    # gendaymtx names each sun solarN, N the minutes since 1 January 0:00 of the hour's middle.
    cols = np.array([(int(m[len("solar"):]) - 30) // 60 for m in sun_mods], dtype=int)
    t0 = time.perf_counter()
    if args.sun_ir == "hourly":
        ir = (read_matrix(os.path.join(work, "sun_ir_total.mtx"))
              - read_matrix(os.path.join(work, "sun_ir_direct.mtx")))
        inter_sun = np.zeros((npts, 8760))
        inter_sun[:, cols] = np.tensordot(ir, np.array(WEIGHTS), axes=([2], [0]))
    else:
        coef = (read_matrix(os.path.join(work, "sun_coef_total.mtx"))
                - read_matrix(os.path.join(work, "sun_coef_direct.mtx")))
        coef = np.tensordot(coef, np.array(WEIGHTS), axes=([2], [0]))  # lx per W/m^2 normal
        # gendaymtx's sun patches: radiance x solid angle = the share of the direct-normal
        # (visible) irradiance it gave that patch.
        inter_sun = coef @ (sun_patch[used] * doms[used, None])
    r.times["inter-reflected sun"] = time.perf_counter() - t0

    t0 = time.perf_counter()
    suns = read_matrix(os.path.join(work, "suns.mtx"))  # (npts, nsuns, 3) lx/179 per sun
    direct = np.zeros((npts, 8760))
    direct[:, cols] = np.tensordot(suns, np.array(WEIGHTS), axes=([2], [0]))
    total = sky + inter_sun + direct
    m = metrics(total, direct, args.sda_fraction, args.ase_hours)
    r.times["combine + metrics"] = time.perf_counter() - t0

    self_ru = resource.getrusage(resource.RUSAGE_SELF)
    child_ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    out = {
        "tool": "Radiance " + subprocess.run(["rtrace", "-version"], capture_output=True,
                                             text=True).stdout.strip(),
        "method": "sky DC (ab N) x sky + patch-sun coefficients (ab N - ab 0) x sun patches + exact suns (ab 0)",
        "frame": "Radiance (X, Y, Z) = candela (x, -z, y): +Y north, +Z up",
        "settings": {"photometric_wea": args.photometric, "reused_dc": args.reuse_dc,
                     "sun_positions": "gendaymtx" if args.radiance_sun_positions else "ladybug NOAA",
                     "mf": args.mf, "ab": args.ab, "ad": args.ad, "sun_ad": args.sun_ad, "lw": args.lw,
                     "sun_patches": len(used) if args.sun_ir == "patches" else None,
                     "nproc": args.nproc, "sun_suns": len(sun_mods), "sun_disk": args.sun_disk,
                     "sun_ir": args.sun_ir,
                     "sda_fraction": args.sda_fraction, "ase_hours": args.ase_hours},
        "points": [list(p) for p in pts],
        "metrics": m,
        "annual_mean_lx": {
            "total": total.mean(axis=1).tolist(),
            "sky": sky.mean(axis=1).tolist(),
            "inter_reflected_sun": inter_sun.mean(axis=1).tolist(),
            "direct_sun": direct.mean(axis=1).tolist(),
        },
        "timings_s": {k: round(v, 3) for k, v in r.times.items()},
        "cpu_children_by_stage_s": {k: round(v, 3) for k, v in r.cpu.items()},
        "wall_s": round(time.perf_counter() - t_start, 3),
        "cpu_children_s": round(child_ru.ru_utime + child_ru.ru_stime, 3),
        "peak_rss_largest_child_mib": round(child_ru.ru_maxrss / 1024.0, 1),
        "peak_rss_self_mib": round(self_ru.ru_maxrss / 1024.0, 1),
        "work_dir": work,
    }
    if not args.no_hourly:
        out["hourly_lx"] = np.round(total, 2).tolist()
        out["hourly_direct_sun_lx"] = np.round(direct, 2).tolist()
    json.dump(out, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
