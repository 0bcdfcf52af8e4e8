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

# Models that name files outside their folder, read a library 5000 times, or place a vertex
# beyond the coordinate limit; each model in a folder of its own.
models = out / "models"
models.mkdir(exist_ok=True)
import json


def gltf_with(buffer_uri=None, image_uri=None, position_accessor=0, scale=None):
    tri = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, **({"scale": scale} if scale else {})}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": position_accessor}}]}],
        "buffers": [
            {
                "byteLength": len(tri),
                "uri": buffer_uri
                or "data:application/octet-stream;base64," + __import__("base64").b64encode(tri).decode(),
            }
        ],
        "bufferViews": [{"buffer": 0, "byteLength": len(tri)}],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": 3,
                "type": "VEC3",
                "min": [0, 0, 0],
                "max": [1, 1, 0],
            }
        ],
    }
    if image_uri:
        doc["images"] = [{"uri": image_uri}]
        doc["textures"] = [{"source": 0}]
        doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
        doc["meshes"][0]["primitives"][0]["material"] = 0
    return json.dumps(doc)


def model_scene(name, model_file, text):
    d = models / name
    d.mkdir(exist_ok=True)
    (d / model_file).write_text(text)
    (out / f"{name}.ron").write_text(
        (out / "coincident-1e5.ron")
        .read_text()
        .replace('(shape: Obj("coincident-1e5.obj"), material: "grey")',
                 f'(shape: Model(file: "models/{name}/{model_file}"), material: "grey")')
    )


model_scene("gltf-buffer-etc", "m.gltf", gltf_with(buffer_uri="/etc/passwd"))
model_scene("gltf-image-up", "m.gltf", gltf_with(image_uri="../../etc/passwd"))
model_scene("gltf-no-accessor", "m.gltf", gltf_with(position_accessor=9))
model_scene("gltf-far-node", "m.gltf", gltf_with(scale=[1e13, 1e13, 1e13]))
model_scene("obj-mtllib-etc", "m.obj", "mtllib /etc/passwd\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
model_scene("obj-far-vertex", "m.obj", "v 1e18 0 0\nv 1e18 1 0\nv 1e18 0 1\nf 1 2 3\n")
model_scene(
    "obj-5000-mtllib",
    "m.obj",
    "mtllib a.mtl\n" * 5000 + "usemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
)
with open(models / "obj-5000-mtllib" / "a.mtl", "w") as f:
    f.write("newmtl m\nKd 0.5 0.5 0.5\n")
    f.write("# padding\n" * 100_000)

# Radiance pictures whose VIEW no projection can have, and one declaring 16384^2 pixels in
# 200 kB (RLE scanlines of one grey run each, far fewer than it declares).
def hdr(name, view, w, h, rows):
    line = bytes([2, 2, w >> 8, w & 255])
    for value in (128, 128, 128, 129):
        left = w
        while left > 0:
            n = min(127, left)
            line += bytes([128 + n, value])
            left -= n
    with open(out / name, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n")
        f.write(f"VIEW= {view}\n\n-Y {h} +X {w}\n".encode())
        for _ in range(rows):
            f.write(line)


hdr("view-vth-300.hdr", "-vth -vh 300 -vv 300", 64, 64, 64)
hdr("view-vtv-400.hdr", "-vtv -vh 400 -vv 400", 64, 64, 64)
hdr("big-16384.hdr", "-vta -vh 180 -vv 180", 16384, 16384, 190)

# Weather years: a valid dark year (no irradiance at all, which is possible) and its faults.
year = []
days = [31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31]
for m, n in enumerate(days, 1):
    for d in range(1, n + 1):
        for hh in range(1, 25):
            year.append(
                f"2003,{m},{d},{hh},60,A7A7E8E8*0?9?9?9?9?9?9?9A7A7A7A7A7*0*0E8E8*0*0,10.0,5.0,70,"
                "98600,0,1367,300,0,0,0,0,0,0,0,180,3.0,5,3,20.0,77777,9,999999999,0,0.2,0,88,0.0,0.0,0.0"
            )
HEAD = [
    "LOCATION,Hostile,,XXX,candela hostile input,000000,45.73,4.94,1.0,201.0",
    "DESIGN CONDITIONS,0",
    "TYPICAL/EXTREME PERIODS,0",
    "GROUND TEMPERATURES,0",
    "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0",
    "COMMENTS 1,dark year",
    "COMMENTS 2,",
    "DATA PERIODS,1,1,Data,Wednesday, 1/ 1,12/31",
]


def epw(name, head=HEAD, rows=year):
    (out / name).write_text("\n".join(head + rows) + "\n")


epw("epw-ok.epw")
epw("epw-elevation.epw", [HEAD[0].replace(",201.0", ",1e300")] + HEAD[1:])
epw("epw-timezone-comma.epw", [HEAD[0].replace(",1.0,201.0", ",5,5,201.0")] + HEAD[1:])
feb = sum(days[:1]) * 24
epw("epw-feb31.epw", rows=year[: feb + 27 * 24] + [r.replace("2003,2,28,", "2003,2,31,", 1) for r in year[feb + 27 * 24 : feb + 28 * 24]] + year[feb + 28 * 24 :])
epw("epw-repeated.epw", rows=year[:100] + [year[99]] + year[100:])
epw("epw-swapped.epw", rows=year[:100] + [year[101], year[100]] + year[102:])
epw("epw-missing.epw", rows=year[:100] + [year[100].replace(",0,0,0,0,0,0,0,180,", ",0,9999,0,0,0,0,0,180,", 1)] + year[101:])
epw("epw-night-sun.epw", rows=year[:1] + [year[1].replace(",300,0,0,0,0,0,0,0,180,", ",300,0,100,0,0,0,0,0,180,", 1)] + year[2:])
epw("epw-48-hours.epw", rows=year[:48])
(out / "annual.ron").write_text(
    "(\n"
    f"    {CAMERA},\n"
    "    render: (spp: 4),\n"
    '    materials: { "grey": Diffuse(reflectance: Constant(0.5)) },\n'
    '    objects: [(shape: Quad(origin: (-2, 0, -2), edge_u: (4, 0, 0), edge_v: (0, 0, 4)), material: "grey")],\n'
    '    lights: [Sky(model: CieOvercast, amount: HorizontalIlluminance(10000.0), spectrum: Named("D65"))],\n'
    '    grids: [(name: "desk", origin: (-1, 0.8, -1), edge_u: (2, 0, 0), edge_v: (0, 0, 2), nx: 2, ny: 2, normal: (0, 1, 0))],\n'
    ")\n"
)


# Pictures that hold what they declare in the densest scanlines the reader accepts (one pixel,
# then old-style runs): 16384² in 197 kB, and 30000² cut to 200 kB; a 7-channel EXR of 16384².
def hdr_rle(w, h, view=False):
    line, n = bytes([128, 128, 128, 129]), w - 1
    while n:
        line += bytes([1, 1, 1, n & 255])
        n >>= 8
    head = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n" + (b"VIEW= -vta -vh 180 -vv 180\n" if view else b"")
    return head + b"\n-Y %d +X %d\n" % (h, w) + line * h


(out / "hdr-16384.hdr").write_bytes(hdr_rle(16384, 16384))
(out / "hdr-16384v.hdr").write_bytes(hdr_rle(16384, 16384, view=True))
(out / "hdr-30000.hdr").write_bytes(hdr_rle(30000, 30000)[:200_000])


def exr_zeros(path, w, h, channels):
    chlist = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in sorted(channels)) + b"\0"
    header = (
        b"\x76\x2f\x31\x01"
        + struct.pack("<i", 2)
        + attr("channels", "chlist", chlist)
        + attr("compression", "compression", b"\x03")
        + attr("dataWindow", "box2i", struct.pack("<4i", 0, 0, w - 1, h - 1))
        + attr("displayWindow", "box2i", struct.pack("<4i", 0, 0, w - 1, h - 1))
        + attr("lineOrder", "lineOrder", b"\x00")
        + attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
        + attr("screenWindowCenter", "v2f", struct.pack("<2f", 0, 0))
        + attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
        + b"\0"
    )
    block = zlib.compress(bytes(w * 4 * len(channels) * 16), 9)
    blocks = (h + 15) // 16
    first = len(header) + 8 * blocks
    with open(path, "wb") as f:
        f.write(header)
        f.write(b"".join(struct.pack("<Q", first + i * (8 + len(block))) for i in range(blocks)))
        for i in range(blocks):
            f.write(struct.pack("<ii", i * 16, len(block)))
            f.write(block)


exr_zeros(out / "exr7-16384.exr", 16384, 16384, ["X", "Y", "Z", "stderr.Y", "E", "stderr.E", "mask.E"])
