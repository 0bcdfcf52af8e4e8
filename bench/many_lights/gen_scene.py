#!/usr/bin/env python3
"""Writes the many-lights benchmark building for candela: a storey of COLS x ROWS closed
offices (each 6 m x 5 m x 3 m, grey Lambertian: ceiling 0.8, walls 0.7, floor 0.2), each lit
by 5 x 5 batwing luminaires (data/luminaires/batwing-office.ies, 4000 lm) just below the
ceiling: 500 luminaires with the default 5 x 4 rooms. A 12 x 10 work-plane grid at 0.8 m lies
in one room away from the outer walls; each grid point samples until its relative standard
error is below --target (measure.target_relative_error).

Usage: gen_scene.py --out FILE.ron --sampler Bvh|Power [--target 0.01] [--cols 5 --rows 4]
"""

import argparse
import os

ROOM = (6.0, 5.0, 3.0)  # x, z, height (m)
RHO = {"ceiling": 0.8, "wall": 0.7, "floor": 0.2}
PER_SIDE = 5  # luminaires per room along each axis
LUM_Y = 2.95
GRID = (12, 10, 0.8)


def quad(name, mat, origin, eu, ev):
    f = lambda v: "(" + ", ".join(f"{c:g}" for c in v) + ")"
    return f'        (name: "{name}", material: "{mat}", shape: Quad(origin: {f(origin)}, edge_u: {f(eu)}, edge_v: {f(ev)})),'


def scene(cols, rows, sampler, target, ies_rel):
    rx, rz, h = ROOM
    lx, lz = cols * rx, rows * rz
    objs = [
        quad("floor", "floor", (0, 0, 0), (0, 0, lz), (lx, 0, 0)),
        quad("ceiling", "ceiling", (0, h, 0), (lx, 0, 0), (0, 0, lz)),
    ]
    for i in range(cols + 1):
        objs.append(quad(f"wall x{i}", "wall", (i * rx, 0, 0), (0, h, 0), (0, 0, lz)))
    for j in range(rows + 1):
        objs.append(quad(f"wall z{j}", "wall", (0, 0, j * rz), (lx, 0, 0), (0, h, 0)))
    lights = []
    for j in range(rows):
        for i in range(cols):
            for b in range(PER_SIDE):
                for a in range(PER_SIDE):
                    x = i * rx + (a + 0.5) * rx / PER_SIDE
                    z = j * rz + (b + 0.5) * rz / PER_SIDE
                    lights.append(
                        f'        Goniometric(file: "{ies_rel}", position: ({x:g}, {LUM_Y}, {z:g}), '
                        f'spectrum: Blackbody(4000.0), lumens: 4000.0),'
                    )
    gi, gj = cols // 2, rows // 2  # the grid's room
    nx, ny, gy = GRID
    return f"""// Many-lights benchmark (bench/many_lights/gen_scene.py): {cols} x {rows} offices of
// {rx:g} x {rz:g} x {h:g} m, {len(lights)} luminaires, grid in room ({gi}, {gj}). Generated; do not edit.
Scene(
    camera: (position: ({gi * rx + 0.5}, 1.6, {gj * rz + 0.5}), look_at: ({gi * rx + 3}, 1.2, {gj * rz + 4}), vfov_deg: 60.0, resolution: (1, 1)),
    render: (spp: 1, light_sampler: {sampler}),
    materials: {{
        "ceiling": Diffuse(reflectance: Constant({RHO['ceiling']})),
        "wall": Diffuse(reflectance: Constant({RHO['wall']})),
        "floor": Diffuse(reflectance: Constant({RHO['floor']})),
    }},
    objects: [
{chr(10).join(objs)}
    ],
    grids: [
        (name: "work plane", origin: ({gi * rx}, {gy}, {gj * rz}), edge_u: ({rx}, 0.0, 0.0), edge_v: (0.0, 0.0, {rz}), nx: {nx}, ny: {ny}),
    ],
    measure: (samples: 256, target_relative_error: {target}, max_samples: 268435456),
    lights: [
{chr(10).join(lights)}
    ],
)
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", required=True)
    ap.add_argument("--sampler", choices=["Bvh", "Power"], required=True)
    ap.add_argument("--target", type=float, default=0.01)
    ap.add_argument("--cols", type=int, default=5)
    ap.add_argument("--rows", type=int, default=4)
    a = ap.parse_args()
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ies = os.path.join(root, "data", "luminaires", "batwing-office.ies")
    ies_rel = os.path.relpath(ies, os.path.dirname(os.path.abspath(a.out)))
    with open(a.out, "w") as f:
        f.write(scene(a.cols, a.rows, a.sampler, a.target, ies_rel))


if __name__ == "__main__":
    main()
