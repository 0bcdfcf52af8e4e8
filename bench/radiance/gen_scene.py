#!/usr/bin/env python3
"""Writes the office of the Radiance benchmark for candela and for Radiance.

The room is 8 m x 6 m x 3 m, grey and Lambertian (ceiling 0.8, walls 0.7, floor 0.2), lit by N
copies of one IES luminaire on a regular ceiling layout, with a 16 x 12 work-plane grid at
0.8 m. N = 500 is an open-plan floor instead, 60 m x 48 m x 3 m with 25 x 20 luminaires on a
2.4 m square pitch (about the N = 6 office's 8 m^2 per luminaire), the grid over the whole floor.
--n daylit is the N = 6 office without luminaires, daylit instead: an open window (no glazing)
of WINDOW in the wall at Radiance y = 0, under a CIE overcast sky of SKY_LX horizontal
illuminance over a ground of reflectance GROUND_RHO (Radiance: a brightfunc of the CIE formula,
cie_overcast.cal, at 179 lm/W; candela: Sky with the window as its portal). Radiance is z-up; candela is y-up. A Radiance point (X, Y, Z) is candela's
(X, Z, 6 - Y): a proper rotation (no mirror), so an asymmetric luminaire keeps its handedness.
Both tools put C0 along +X and C90 along Radiance's +Y (= candela's -Z), nadir down.

Outputs in --out-dir:
  office-N.ron         candela scene (grid "work plane", measure.samples = --samples)
  office-N.rad         Radiance scene: materials, room polygons, one illum sphere per luminaire
  lum.dat              ies2rad's candela table (-dm: metres; -i: small sphere), read by office-N.rad
  points.txt           the grid's points in Radiance coordinates with +z normals (rtrace -I),
                       in the order of candela's grid CSV (j outer, i inner)
"""

import argparse
import math
import os
import subprocess
import sys

OFFICE = (8.0, 6.0, 3.0)  # X (length), Y (depth), Z (height), metres
OPEN_PLAN = (60.0, 48.0, 3.0)  # the N = 500 floor
ROOM = OFFICE  # set by main() from --n
RHO = {"ceiling": 0.8, "wall": 0.7, "floor": 0.2}
GRID_NX, GRID_NY, GRID_H = 16, 12, 0.8
LUM_Z = 2.95  # luminaire centre height, m (5 cm below the ceiling)
LUM_RADIUS = 0.01  # radius of Radiance's illum sphere, m: a near point source, like candela's

# The daylit office's window in the wall y = 0 (Radiance): x from, x to, sill, head (m); its sky.
WINDOW = (1.0, 7.0, 0.9, 2.4)
SKY_LX = 10000.0
GROUND_RHO = 0.2

# Layouts: columns x rows of luminaires at the centres of equal cells of the ceiling.
LAYOUTS = {6: (3, 2), 48: (8, 6), 500: (25, 20)}
# The camera of the images (Radiance coordinates): eye 1.6 m high, 0.5 m from the wall y = 6,
# looking across the room at a point 1.2 m high on the wall y = 0; vertical field of view 60 deg.
VIEW_EYE = (4.0, 5.5, 1.6)
VIEW_TARGET = (4.0, 0.0, 1.2)
VIEW_VFOV = 60.0


def layout(n):
    if n == "daylit":
        return []
    if n not in LAYOUTS:
        sys.exit(f"no layout for N={n}; known: {sorted(LAYOUTS)}")
    cols, rows = LAYOUTS[n]
    lx, ly, _ = ROOM
    return [((c + 0.5) * lx / cols, (r + 0.5) * ly / rows, LUM_Z) for r in range(rows) for c in range(cols)]


def grid_points():
    """Radiance coordinates of the grid points, in candela's order (j outer, i inner)."""
    lx, ly, _ = ROOM
    pts = []
    # candela grid: origin (0, 0.8, 0), edge_u (8, 0, 0), edge_v (0, 0, 6); point (i, j) at
    # x = (i + 1/2) * 8/16, z = (j + 1/2) * 6/12, i.e. Radiance Y = 6 - z.
    for j in range(GRID_NY):
        for i in range(GRID_NX):
            x = (i + 0.5) * lx / GRID_NX
            z = (j + 0.5) * ly / GRID_NY
            pts.append((x, ly - z, GRID_H))
    return pts


def to_candela(p):
    x, y, z = p
    return (x, z, ROOM[1] - y)


def fmt(v):
    return "(" + ", ".join(f"{c:.6g}" for c in v) + ")"


def view_args(width, height):
    """Radiance view options of the image camera, the same view as candela's camera."""
    import math

    d = [t - e for t, e in zip(VIEW_TARGET, VIEW_EYE)]
    vh = 2 * math.degrees(math.atan(width / height * math.tan(math.radians(VIEW_VFOV / 2))))
    return (f"-vtv -vp {VIEW_EYE[0]:g} {VIEW_EYE[1]:g} {VIEW_EYE[2]:g} -vd {d[0]:g} {d[1]:g} {d[2]:g} "
            f"-vu 0 0 1 -vv {VIEW_VFOV:g} -vh {vh:.6f}")


def candela_scene(n, ies_rel, samples, max_depth, image=None):
    """The RON; with image = (width, height), a picture of the camera view and no grid."""
    lx, ly, lz = ROOM
    lights = "\n".join(
        f"        Goniometric(file: \"{ies_rel}\", position: {fmt(to_candela(p))}, spectrum: Named(\"E\")),"
        for p in layout(n)
    )
    res, spp = (image, 64) if image else ((1, 1), 1)
    grids = (f"""    grids: [
        (name: "work plane", origin: (0.0, {GRID_H}, 0.0), edge_u: ({lx}, 0.0, 0.0), edge_v: (0.0, 0.0, {ly}), nx: {GRID_NX}, ny: {GRID_NY}),
    ],
    measure: (samples: {samples}),
""" if not image else "")
    what = f"a {res[0]} x {res[1]} picture" if image else f"{GRID_NX} x {GRID_NY} work-plane grid at {GRID_H} m"
    if n == "daylit":
        x0, x1, y0, y1 = WINDOW
        # The window wall (candela z = ly) as four quads round the opening, normals inward (-z).
        window_wall = "".join(
            f"""        (name: "window wall {name}", material: "wall",
         shape: Quad(origin: {fmt(o)}, edge_u: {fmt(u)}, edge_v: {fmt(v)})),
"""
            for name, o, u, v in [
                ("below", (0, 0, ly), (0, y0, 0), (lx, 0, 0)),
                ("above", (0, y1, ly), (0, lz - y1, 0), (lx, 0, 0)),
                ("left", (0, y0, ly), (0, y1 - y0, 0), (x0, 0, 0)),
                ("right", (x1, y0, ly), (0, y1 - y0, 0), (lx - x1, 0, 0)),
            ]
        )
        portal = f"(origin: {fmt((x0, y0, ly))}, edge_u: {fmt((x1 - x0, 0, 0))}, edge_v: {fmt((0, y1 - y0, 0))})"
        lights = (f"        Sky(model: CieOvercast, amount: HorizontalIlluminance({SKY_LX}), spectrum: Named(\"E\"),\n"
                  f"            ground_reflectance: {GROUND_RHO}, portals: [{portal}]),")
        what += f", daylit through a {x1 - x0:g} m x {y1 - y0:g} m open window under a CIE overcast sky of {SKY_LX:g} lx"
    else:
        window_wall = f"""        (name: "wall z=6", material: "wall",
         shape: Quad(origin: (0.0, 0.0, {ly}), edge_u: (0.0, {lz}, 0.0), edge_v: ({lx}, 0.0, 0.0))),
"""
    # Quads in candela coordinates: x in [0, lx], y in [0, lz] (up), z in [0, ly].
    return f"""// Radiance benchmark office (bench/radiance/gen_scene.py): {lx:g} x {ly:g} x {lz:g} m, N = {n}
// luminaires, grey Lambertian surfaces, {what}. Generated; do not edit.
Scene(
    camera: (position: {fmt(to_candela(VIEW_EYE))}, look_at: {fmt(to_candela(VIEW_TARGET))}, vfov_deg: {VIEW_VFOV}, resolution: {res}),
    render: (spp: {spp}, max_depth: {max_depth}),
    materials: {{
        "ceiling": Diffuse(reflectance: Constant({RHO['ceiling']})),
        "wall": Diffuse(reflectance: Constant({RHO['wall']})),
        "floor": Diffuse(reflectance: Constant({RHO['floor']})),
    }},
    objects: [
        (name: "floor", material: "floor",
         shape: Quad(origin: (0.0, 0.0, 0.0), edge_u: (0.0, 0.0, {ly}), edge_v: ({lx}, 0.0, 0.0))),
        (name: "ceiling", material: "ceiling",
         shape: Quad(origin: (0.0, {lz}, 0.0), edge_u: ({lx}, 0.0, 0.0), edge_v: (0.0, 0.0, {ly}))),
        (name: "wall x=0", material: "wall",
         shape: Quad(origin: (0.0, 0.0, 0.0), edge_u: (0.0, {lz}, 0.0), edge_v: (0.0, 0.0, {ly}))),
        (name: "wall x=8", material: "wall",
         shape: Quad(origin: ({lx}, 0.0, 0.0), edge_u: (0.0, 0.0, {ly}), edge_v: (0.0, {lz}, 0.0))),
        (name: "wall z=0", material: "wall",
         shape: Quad(origin: (0.0, 0.0, 0.0), edge_u: ({lx}, 0.0, 0.0), edge_v: (0.0, {lz}, 0.0))),
{window_wall}    ],
{grids}    lights: [
{lights}
    ],
)
"""


def radiance_scene(n, lum_modifiers):
    lx, ly, lz = ROOM
    out = [
        f"# Radiance benchmark office (bench/radiance/gen_scene.py), N = {n}. Generated; do not edit.",
        "# Grey Lambertian: plastic with zero specularity and roughness.",
    ]
    for name, rho in RHO.items():
        out.append(f"void plastic {name}\n0\n0\n5 {rho} {rho} {rho} 0 0")

    def poly(mat, name, pts):
        coords = "\n".join(f"  {x:g} {y:g} {z:g}" for x, y, z in pts)
        out.append(f"{mat} polygon {name}\n0\n0\n{3 * len(pts)}\n{coords}")

    poly("floor", "floor", [(0, 0, 0), (0, ly, 0), (lx, ly, 0), (lx, 0, 0)])
    poly("ceiling", "ceiling", [(0, 0, lz), (lx, 0, lz), (lx, ly, lz), (0, ly, lz)])
    poly("wall", "wall_x0", [(0, 0, 0), (0, 0, lz), (0, ly, lz), (0, ly, 0)])
    poly("wall", "wall_x8", [(lx, 0, 0), (lx, ly, 0), (lx, ly, lz), (lx, 0, lz)])
    if n == "daylit":
        x0, x1, y0, y1 = WINDOW
        poly("wall", "wall_y0_below", [(0, 0, 0), (lx, 0, 0), (lx, 0, y0), (0, 0, y0)])
        poly("wall", "wall_y0_above", [(0, 0, y1), (lx, 0, y1), (lx, 0, lz), (0, 0, lz)])
        poly("wall", "wall_y0_left", [(0, 0, y0), (x0, 0, y0), (x0, 0, y1), (0, 0, y1)])
        poly("wall", "wall_y0_right", [(x1, 0, y0), (lx, 0, y0), (lx, 0, y1), (x1, 0, y1)])
    else:
        poly("wall", "wall_y0", [(0, 0, 0), (lx, 0, 0), (lx, 0, lz), (0, 0, lz)])
    poly("wall", "wall_y6", [(0, ly, 0), (0, ly, lz), (lx, ly, lz), (lx, ly, 0)])
    if n == "daylit":
        # The CIE overcast sky, L = Lz (1 + 2 sin(altitude)) / 3 with Lz = 9 E_h / (7 pi), and a
        # uniform ground of rho_g E_h / pi below the horizon, in W/sr/m^2 (179 lm/W), as glow
        # sources seen only by ambient rays. gensky -c's skybright.cal would blend sky and ground
        # over about 10 degrees either side of the horizon, which is not the CIE sky (it reads up
        # to 1.8 % low at the back of this room; bench/README.md).
        lz = 9.0 * SKY_LX / (7.0 * math.pi) / 179.0
        lg = GROUND_RHO * SKY_LX / math.pi / 179.0
        out.append(f"void brightfunc skyfunc\n2 skybr cie_overcast.cal\n0\n2 {lz:.8g} {lg:.8g}")
        out.append("skyfunc glow sky_glow\n0\n0\n4 1 1 1 0")
        out.append("sky_glow source sky\n0\n0\n4 0 0 1 180")
        out.append("sky_glow source ground\n0\n0\n4 0 0 -1 180")
        return "\n".join(out) + "\n"
    # ies2rad's modifier chain (brightdata -> illum 'lum_light') is direction-only, so every
    # luminaire is a sphere of that modifier at its own centre, none rotated.
    out.append(lum_modifiers)
    for k, (x, y, z) in enumerate(layout(n)):
        out.append(f"lum_light sphere lum_{k}\n0\n0\n4 {x:.6g} {y:.6g} {z:.6g} {LUM_RADIUS}")
    return "\n".join(out) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", required=True, help="number of luminaires (6, 48 or 500), or daylit")
    ap.add_argument("--ies", required=True, help="IES file")
    ap.add_argument("--out-dir", required=True)
    ap.add_argument("--samples", type=int, default=4096, help="candela measure.samples per grid point")
    ap.add_argument("--max-depth", type=int, default=1000, help="candela render.max_depth")
    ap.add_argument("--ies2rad", default="ies2rad")
    ap.add_argument("--name", help="file stem (default office-N)")
    ap.add_argument("--image", metavar="WxH", help="also write office-N-image.ron: a W x H picture, no grid")
    a = ap.parse_args()
    global ROOM
    if a.n != "daylit":
        a.n = int(a.n)
    ROOM = OPEN_PLAN if a.n == 500 else OFFICE

    os.makedirs(a.out_dir, exist_ok=True)
    stem = a.name or f"office-{a.n}"
    ies_abs = os.path.abspath(a.ies)
    ies_rel = os.path.relpath(ies_abs, os.path.abspath(a.out_dir))
    with open(os.path.join(a.out_dir, stem + ".ron"), "w") as f:
        f.write(candela_scene(a.n, ies_rel, a.samples, a.max_depth))
    if a.image:
        w, h = (int(x) for x in a.image.lower().split("x"))
        with open(os.path.join(a.out_dir, stem + "-image.ron"), "w") as f:
            f.write(candela_scene(a.n, ies_rel, a.samples, a.max_depth, image=(w, h)))
    # -dm: the file's dimensions and Radiance's output in metres; -i: ignore the file's luminous
    # opening (0.3 x 1.2 m) and emit from a sphere of LUM_RADIUS, as candela's point source;
    # -t default: white lamp (RGB 1 1 1), so 179 lm/W turns its radiance back into the candela.
    conv = subprocess.run(
        [a.ies2rad, "-dm", "-i", str(LUM_RADIUS), "-t", "default", "-o", "lum", "-s", ies_abs],
        cwd=a.out_dir,
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    # Keep the modifiers (brightdata, illum); drop ies2rad's own sphere at the origin.
    cut = conv.index("'lum_light' sphere")
    mods = conv[:cut].rstrip() + "\n"
    with open(os.path.join(a.out_dir, stem + ".rad"), "w") as f:
        f.write(radiance_scene(a.n, mods))
    if a.n == "daylit":
        with open(os.path.join(a.out_dir, "cie_overcast.cal"), "w") as f:
            f.write("{ CIE overcast sky above the horizon (A1: zenith radiance), uniform ground below (A2) }\n"
                    "skybr = if(Dz, A1 * (1 + 2*Dz) / 3, A2);\n")
    with open(os.path.join(a.out_dir, "points.txt"), "w") as f:
        for x, y, z in grid_points():
            f.write(f"{x:.6g} {y:.6g} {z:.6g} 0 0 1\n")


if __name__ == "__main__":
    main()
