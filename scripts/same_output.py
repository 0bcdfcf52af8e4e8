#!/usr/bin/env python3
"""Compare two output directories written by scripts/same-output.sh: EXR pixel data byte for
byte (the header's attributes as a set, since their order may vary between runs), PNG and CSV
files byte for byte, report JSON numbers exactly (timings and dates excepted) and the commands'
standard output with its timings removed. Prints one line per difference; exits 1 if any."""
import json
import re
import struct
import sys
from pathlib import Path

TIMING_KEYS = {"created_utc", "render_seconds", "measure_seconds", "seconds"}


def exr_parts(data: bytes):
    """(attributes as a dict name -> (type, bytes), the bytes after the header)."""
    assert data[:4] == b"\x76\x2f\x31\x01", "not an OpenEXR file"
    pos, attrs = 8, {}
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        tend = data.index(b"\0", end + 1)
        typ = data[end + 1 : tend].decode()
        (size,) = struct.unpack_from("<i", data, tend + 1)
        value = data[tend + 5 : tend + 5 + size]
        attrs[name] = (typ, value)
        pos = tend + 5 + size
    return attrs, data[pos + 1 :]


def json_diff(a, b, path, out):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k in TIMING_KEYS:
                continue
            if k not in a or k not in b:
                out.append(f"{path}.{k}: only in {'new' if k in b else 'old'}")
            else:
                json_diff(a[k], b[k], f"{path}.{k}", out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} vs {len(b)} items")
        for i, (x, y) in enumerate(zip(a, b)):
            json_diff(x, y, f"{path}[{i}]", out)
    elif a != b:
        out.append(f"{path}: {a!r} vs {b!r}")


def normalise_text(t: str, root: str) -> str:
    t = t.replace(root, "OUT")
    t = re.sub(r"in [0-9.]+ s on (\d+) threads: [0-9.]+ M samples/s, [0-9.]+ M rays/s", r"in T s on \1 threads", t)
    t = re.sub(r"after [0-9.]+ s", "after T s", t)
    t = re.sub(r"[0-9.]+ s (sky|sun|metrics|view coefficients|hourly glare)\b", r"T s \1", t)
    return t


def main():
    old, new = Path(sys.argv[1]), Path(sys.argv[2])
    problems, compared = [], 0
    names = sorted({p.relative_to(old) for p in old.rglob("*") if p.is_file()} | {p.relative_to(new) for p in new.rglob("*") if p.is_file()})
    for rel in names:
        a, b = old / rel, new / rel
        if not a.exists() or not b.exists():
            problems.append(f"{rel}: only in {'new' if b.exists() else 'old'}")
            continue
        compared += 1
        da, db = a.read_bytes(), b.read_bytes()
        if rel.suffix == ".exr":
            (ha, pa), (hb, pb) = exr_parts(da), exr_parts(db)
            ha.pop("scene", None), hb.pop("scene", None)
            if ha != hb:
                problems.append(f"{rel}: EXR attributes differ: {sorted(set(ha.items()) ^ set(hb.items()))[:4]}")
            if pa != pb:
                problems.append(f"{rel}: EXR pixel data differ")
        elif rel.name.endswith(".json"):
            out = []
            ja = json.loads(normalise_text(da.decode(), str(old)))
            jb = json.loads(normalise_text(db.decode(), str(new)))
            json_diff(ja, jb, rel.name, out)
            problems += [f"{rel}: {o}" for o in out]
        elif rel.suffix == ".html":
            # The report page embeds its report JSON: compare it without the timings.
            strip = lambda t: re.sub(r'"(created_utc|render_seconds|measure_seconds)":("[^"]*"|[0-9.e+-]+)', "", t)
            if strip(normalise_text(da.decode(), str(old))) != strip(normalise_text(db.decode(), str(new))):
                problems.append(f"{rel}: page differs")
        elif rel.suffix in (".txt", ".log"):
            if normalise_text(da.decode(), str(old)) != normalise_text(db.decode(), str(new)):
                problems.append(f"{rel}: output differs")
        elif da != db:
            problems.append(f"{rel}: bytes differ")
    for p in problems:
        print(p)
    print(f"{compared} files compared, {len(problems)} differences")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
