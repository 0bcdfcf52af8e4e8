"""Writes the large hostile inputs of scripts/hostile.sh into a directory (argument 1).

Each is a file a careless export or an attacker could hand to candela: meshes of coincident
triangles and fans, a polygon of a million vertices, an EXR decompression bomb, a grid of a
million points, a film beyond memory, an IES file claiming billions of angles, and a state file
whose length prefix claims terabytes.
"""

import struct
import sys
import zlib
from pathlib import Path

out = Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)

CAMERA = "camera: (position: (0, 0, -3), look_at: (0, 0, 0), vfov_deg: 40, resolution: (32, 32))"
LIGHT = 'lights: [Point(position: (0, 0, -2), spectrum: Named("D65"), amount: Intensity(100.0))]'


def scene(name, objects, extra=""):
    (out / name).write_text(
        "(\n"
        f"    {CAMERA},\n"
        "    render: (spp: 4),\n"
        '    materials: { "grey": Diffuse(reflectance: Constant(0.5)) },\n'
        f"    objects: [{objects}],\n"
        f"    {LIGHT},\n"
        f"    {extra}\n"
        ")\n"
    )


def mesh_scene(name, obj):
    scene(name, f'(shape: Obj("{obj}"), material: "grey")')


# 10^5 coincident triangles: one triangle repeated.
with open(out / "coincident-1e5.obj", "w") as f:
    f.write("v -1 -1 0\nv 1 -1 0\nv 0 1 0\n")
    f.write("f 1 2 3\n" * 100_000)
mesh_scene("coincident-1e5.ron", "coincident-1e5.obj")

# A fan of 10^6 triangles round a disk's centre (a CAD export's circle).
with open(out / "fan-1e6.obj", "w") as f:
    import math

    n = 1_000_000
    f.write("v 0 0 0\n")
    for i in range(n):
        a = 2 * math.pi * i / n
        f.write(f"v {math.cos(a):.9f} {math.sin(a):.9f} 0\n")
    for i in range(n):
        f.write(f"f 1 {i + 2} {(i + 1) % n + 2}\n")
mesh_scene("fan-1e6.ron", "fan-1e6.obj")

# One polygon of 10^6 vertices (triangulated by the loader).
with open(out / "face-1e6.obj", "w") as f:
    n = 1_000_000
    for i in range(n):
        a = 2 * math.pi * i / n
        f.write(f"v {math.cos(a):.9f} {math.sin(a):.9f} 0\n")
    f.write("f " + " ".join(str(i + 1) for i in range(n)) + "\n")
mesh_scene("face-1e6.ron", "face-1e6.obj")

# A mesh and an mtllib that are /dev/zero.
mesh_scene("mesh-dev-zero.ron", "/dev/zero")
(out / "mtllib-dev-zero.obj").write_text("mtllib /dev/zero\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
mesh_scene("mtllib-dev-zero.ron", "mtllib-dev-zero.obj")

# A grid of 10^6 × 1 points and one of 10^4 × 10^4.
for name, nx, ny in [("grid-1e6x1.ron", 1_000_000, 1), ("grid-1e4x1e4.ron", 10_000, 10_000)]:
    scene(
        name,
        '(shape: Sphere(center: (0, 0, 0), radius: 1), material: "grey")',
        f'grids: [(name: "big", origin: (-1, -1, -1.5), edge_u: (2, 0, 0), edge_v: (0, 2, 0), '
        f"nx: {nx}, ny: {ny}, normal: (0, 0, -1))], measure: (samples: 1),",
    )

# A film of 65536^2 pixels.
(out / "film-65536.ron").write_text(
    (out / "coincident-1e5.ron")
    .read_text()
    .replace("resolution: (32, 32)", "resolution: (65536, 65536)")
    .replace("coincident-1e5.obj", "fan-1e6.obj")
)

# An EXR decompression bomb: 65536^2 float pixels of channel Y, ZIP-compressed zeros (~17 MB).
def attr(name, kind, value):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value


W = H = 65536
chlist = b"Y\0" + struct.pack("<iB3xii", 2, 0, 1, 1) + b"\0"
header = (
    b"\x76\x2f\x31\x01"
    + struct.pack("<i", 2)
    + attr("channels", "chlist", chlist)
    + attr("compression", "compression", b"\x03")
    + attr("dataWindow", "box2i", struct.pack("<4i", 0, 0, W - 1, H - 1))
    + attr("displayWindow", "box2i", struct.pack("<4i", 0, 0, W - 1, H - 1))
    + attr("lineOrder", "lineOrder", b"\x00")
    + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    + attr("screenWindowCenter", "v2f", struct.pack("<2f", 0.0, 0.0))
    + attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
    + b"\0"
)
lines_per_block = 16
blocks = H // lines_per_block
block = zlib.compress(bytes(W * 4 * lines_per_block), 9)
chunk_size = 8 + len(block)
first = len(header) + 8 * blocks
with open(out / "bomb-65536.exr", "wb") as f:
    f.write(header)
    f.write(b"".join(struct.pack("<Q", first + i * chunk_size) for i in range(blocks)))
    for i in range(blocks):
        f.write(struct.pack("<ii", i * lines_per_block, len(block)))
        f.write(block)

# An IES file that claims 10^9 vertical and horizontal angles.
(out / "huge-angles.ies").write_text(
    "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 1000000000 1000000000 1 2 0.5 0.5 0\n1 1 100\n0 90\n0\n100 50\n"
)
scene(
    "huge-angles.ron",
    '(shape: Sphere(center: (0, 0, 0), radius: 1), material: "grey")',
)
(out / "huge-angles.ron").write_text(
    (out / "huge-angles.ron")
    .read_text()
    .replace(
        'Point(position: (0, 0, -2), spectrum: Named("D65"), amount: Intensity(100.0))',
        'Goniometric(position: (0, 0, -2), file: "huge-angles.ies", spectrum: Named("D65"))',
    )
)
