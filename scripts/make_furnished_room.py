#!/usr/bin/env python3
"""Writes scenes/furnished-room.glb: a 5 m x 6 m x 2.8 m room with a window opening, a
wood-plank floor texture (a generated PNG, embedded), a table, four chairs that share one mesh
(four nodes place it), and two ceiling panels that emit through KHR_materials_emissive_strength.
Standard library only. scenes/furnished-room.ron renders it under an overcast sky.

Usage: python3 scripts/make_furnished_room.py [OUT.glb]
"""
import json
import math
import struct
import sys
import zlib
from pathlib import Path

ROOM_X, ROOM_Z, ROOM_H = 5.0, 6.0, 2.8
# The window in the wall x = ROOM_X: z in [1.5, 4.5], y in [0.9, 2.3].
WIN_Z0, WIN_Z1, WIN_Y0, WIN_Y1 = 1.5, 4.5, 0.9, 2.3


def png(width, height, pixel):
    """An 8-bit RGB PNG of pixel(x, y) -> (r, g, b), top row first."""
    raw = bytearray()
    for y in range(height):
        raw.append(0)
        for x in range(width):
            raw.extend(pixel(x, y))

    def chunk(tag, data):
        body = tag + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr)
            + chunk(b"IDAT", zlib.compress(bytes(raw), 9)) + chunk(b"IEND", b""))


def planks(x, y):
    """Wood planks: 4 boards across 64 texels, each its own shade, with dark joints and grain."""
    board = x // 16
    if x % 16 == 0 or (y + 23 * board) % 64 == 0:
        return (60, 42, 28)
    shade = (0, 12, -8, 6)[board]
    grain = int(6 * math.sin(0.7 * y + 3 * board + 0.3 * (x % 16)))
    return tuple(max(0, min(255, c + shade + grain)) for c in (150, 105, 68))


class Builder:
    def __init__(self):
        self.bin = bytearray()
        self.views, self.accessors = [], []

    def add(self, data, acc):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.views.append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)})
        self.bin.extend(data)
        acc["bufferView"] = len(self.views) - 1
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def primitive(self, quads, material, uv_per_m=None):
        """Triangles of `quads` [(origin, edge_u, edge_v)], front face edge_u x edge_v."""
        pos, uv, idx = [], [], []
        for o, eu, ev in quads:
            base = len(pos)
            for s, t in ((0, 0), (1, 0), (1, 1), (0, 1)):
                p = [o[k] + s * eu[k] + t * ev[k] for k in range(3)]
                pos.append(p)
                uv.append((p[0] * (uv_per_m or 1), p[2] * (uv_per_m or 1)))
            idx += [base, base + 1, base + 2, base, base + 2, base + 3]
        lo = [min(p[k] for p in pos) for k in range(3)]
        hi = [max(p[k] for p in pos) for k in range(3)]
        attrs = {"POSITION": self.add(struct.pack(f"<{3 * len(pos)}f", *sum(pos, [])),
                                      {"componentType": 5126, "count": len(pos), "type": "VEC3",
                                       "min": lo, "max": hi})}
        if uv_per_m:
            flat = [c for t in uv for c in t]
            attrs["TEXCOORD_0"] = self.add(struct.pack(f"<{len(flat)}f", *flat),
                                           {"componentType": 5126, "count": len(uv),
                                            "type": "VEC2"})
        ind = self.add(struct.pack(f"<{len(idx)}I", *idx),
                       {"componentType": 5125, "count": len(idx), "type": "SCALAR"})
        return {"attributes": attrs, "indices": ind, "material": material}


def box(x0, y0, z0, x1, y1, z1):
    """The six outward faces of an axis-aligned box as quads."""
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    return [
        ((x0, y0, z0), (0, 0, dz), (dx, 0, 0)),  # bottom (-y)
        ((x0, y1, z0), (dx, 0, 0), (0, 0, dz)),  # top (+y)
        ((x0, y0, z0), (0, dy, 0), (0, 0, dz)),  # -x
        ((x1, y0, z0), (0, 0, dz), (0, dy, 0)),  # +x
        ((x0, y0, z0), (dx, 0, 0), (0, dy, 0)),  # -z
        ((x0, y0, z1), (0, dy, 0), (dx, 0, 0)),  # +z
    ]


def legs(x0, z0, x1, z1, h, t):
    out = []
    for x in (x0, x1 - t):
        for z in (z0, z1 - t):
            out += box(x, 0, z, x + t, h, z + t)
    return out


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else \
        Path(__file__).resolve().parent.parent / "scenes" / "furnished-room.glb"
    b = Builder()
    X, Z, H = ROOM_X, ROOM_Z, ROOM_H
    materials = [
        {"name": "Floor_Oak", "pbrMetallicRoughness": {
            "baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 0.8}},
        {"name": "Wall_Paint", "pbrMetallicRoughness": {
            "baseColorFactor": [0.75, 0.73, 0.68, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}},
        {"name": "Ceiling", "pbrMetallicRoughness": {
            "baseColorFactor": [0.85, 0.85, 0.85, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}},
        {"name": "Table_Top", "pbrMetallicRoughness": {
            "baseColorFactor": [0.35, 0.2, 0.1, 1], "metallicFactor": 0.0, "roughnessFactor": 0.3}},
        {"name": "Steel", "pbrMetallicRoughness": {
            "baseColorFactor": [0.55, 0.55, 0.56, 1], "metallicFactor": 1.0, "roughnessFactor": 0.4}},
        {"name": "Chair_Fabric", "pbrMetallicRoughness": {
            "baseColorFactor": [0.1, 0.25, 0.45, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}},
        # An LED panel of 3 600 lm over 0.6 m x 0.6 m: L = 3600 / (pi 0.36) ~ 3 200 cd/m^2.
        {"name": "LED_Panel", "emissiveFactor": [1.0, 1.0, 1.0],
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 3200.0}},
         "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0.0}},
    ]
    room = [
        b.primitive([((0, 0, 0), (0, 0, Z), (X, 0, 0))], 0, uv_per_m=1.0),
        b.primitive([((0, H, 0), (X, 0, 0), (0, 0, Z))], 2),
        b.primitive([
            ((0, 0, 0), (0, H, 0), (0, 0, Z)),        # x = 0, facing +x
            ((0, 0, 0), (X, 0, 0), (0, H, 0)),        # z = 0, facing +z
            ((0, 0, Z), (0, H, 0), (X, 0, 0)),        # z = Z, facing -z
            # The window wall x = X, facing -x, around the opening.
            ((X, 0, 0), (0, 0, Z), (0, WIN_Y0, 0)),
            ((X, WIN_Y1, 0), (0, 0, Z), (0, H - WIN_Y1, 0)),
            ((X, WIN_Y0, 0), (0, 0, WIN_Z0), (0, WIN_Y1 - WIN_Y0, 0)),
            ((X, WIN_Y0, WIN_Z1), (0, 0, Z - WIN_Z1), (0, WIN_Y1 - WIN_Y0, 0)),
        ], 1),
    ]
    table = [
        b.primitive(box(-0.8, 0.72, -0.45, 0.8, 0.76, 0.45), 3),
        b.primitive(legs(-0.75, -0.4, 0.75, 0.4, 0.72, 0.05), 4),
    ]
    chair = [
        b.primitive(box(-0.22, 0.43, -0.22, 0.22, 0.47, 0.22)
                    + box(-0.22, 0.47, 0.18, 0.22, 0.9, 0.22), 5),
        b.primitive(legs(-0.21, -0.21, 0.21, 0.21, 0.43, 0.03), 4),
    ]
    # Panels 5 mm below the ceiling, emitting downward.
    panel = [b.primitive([((-0.3, 0, -0.3), (0.6, 0, 0), (0, 0, 0.6))], 6)]
    meshes = [{"name": "room", "primitives": room}, {"name": "table", "primitives": table},
              {"name": "chair", "primitives": chair}, {"name": "panel", "primitives": panel}]

    def yaw(deg):
        a = math.radians(deg) / 2
        return [0.0, math.sin(a), 0.0, math.cos(a)]

    nodes = [
        {"name": "room", "mesh": 0},
        {"name": "dining", "translation": [2.6, 0, 3.0], "children": [2, 3, 4, 5, 6]},
        {"name": "table", "mesh": 1},
        {"name": "chair N", "mesh": 2, "translation": [-0.4, 0, -0.7], "rotation": yaw(0)},
        {"name": "chair N2", "mesh": 2, "translation": [0.4, 0, -0.7], "rotation": yaw(0)},
        {"name": "chair S", "mesh": 2, "translation": [-0.4, 0, 0.7], "rotation": yaw(180)},
        {"name": "chair S2", "mesh": 2, "translation": [0.4, 0, 0.7], "rotation": yaw(180)},
        {"name": "panel A", "mesh": 3, "translation": [2.5, H - 0.005, 2.0]},
        {"name": "panel B", "mesh": 3, "translation": [2.5, H - 0.005, 4.0]},
    ]
    image = png(64, 64, planks)
    img_view = len(b.views)
    while len(b.bin) % 4:
        b.bin.append(0)
    b.views.append({"buffer": 0, "byteOffset": len(b.bin), "byteLength": len(image)})
    b.bin.extend(image)
    while len(b.bin) % 4:
        b.bin.append(0)
    doc = {
        "asset": {"version": "2.0", "generator": "candela scripts/make_furnished_room.py"},
        "extensionsUsed": ["KHR_materials_emissive_strength"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 7, 8]}],
        "nodes": nodes,
        "meshes": meshes,
        "materials": materials,
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"wrapS": 10497, "wrapT": 10497}],
        "images": [{"bufferView": img_view, "mimeType": "image/png"}],
        "accessors": b.accessors,
        "bufferViews": b.views,
        "buffers": [{"byteLength": len(b.bin)}],
    }
    text = json.dumps(doc, separators=(",", ":")).encode()
    text += b" " * (-len(text) % 4)
    glb = (b"glTF" + struct.pack("<II", 2, 12 + 8 + len(text) + 8 + len(b.bin))
           + struct.pack("<I", len(text)) + b"JSON" + text
           + struct.pack("<I", len(b.bin)) + b"BIN\0" + bytes(b.bin))
    out.write_bytes(glb)
    print(f"wrote {out} ({len(glb)} bytes)")


if __name__ == "__main__":
    main()
