#!/usr/bin/env python3
"""Instructions per ray of candela's and Embree's traversal kernels, from callgrind profiles.

Used for the "sixth look" of bench/embree/README.md; `count_instructions.sh` runs callgrind
and then this script. Two modes:

  count_instructions.py candela CALLGRIND_OUT BINARY RAYS
      Sums `Ir` per instruction address (the profile must come from `--dump-instr=yes`), maps
      every address to its inlined call chain with `addr2line -i` and attributes it to the
      innermost of: node test, prefetch, triangle test, leaf loop, ray set-up, traversal loop.
      Prints instructions per ray for each part.

  count_instructions.py blocks CALLGRIND_OUT OBJECT RAYS [MIN_PER_RAY]
      For any object (e.g. libembree3.so.3, whose kernels have no symbols): the hot stretches of
      straight-line code, i.e. runs of consecutive instructions executed equally often, with
      their count per ray, their length and first instruction, from `objdump -d`. The node test
      of a BVH kernel is the run of vector min/max and compare that ends in `vmovmskps`; its
      count per ray is the number of node visits.
"""

import collections
import os
import re
import subprocess
import sys


def ir_per_address(path, obj=None):
    """Ir per instruction address of a callgrind profile written with --dump-instr=yes (only
    the instructions of object file `obj` if given)."""
    counts = collections.Counter()
    addr = 0
    skip = False
    objects = {}
    keep = True
    want = os.path.realpath(obj) if obj else None

    def num(s):
        return int(s, 16) if s.startswith("0x") else int(s)

    with open(path) as f:
        for line in f:
            if line.startswith("ob="):
                # `ob=(id) path` the first time, `ob=(id)` after.
                m = re.match(r"ob=\((\d+)\)\s*(.*)", line.strip())
                if m:
                    if m.group(2):
                        objects[m.group(1)] = os.path.realpath(m.group(2))
                    keep = want is None or objects.get(m.group(1)) == want
                continue
            if not line or line[0] not in "+-*0123456789":
                # The cost line after `calls=` is the inclusive cost of a call, not this
                # function's own instructions.
                skip = line.startswith("calls=")
                continue
            parts = line.split()
            a = parts[0]
            if a[0] == "+":
                addr += num(a[1:])
            elif a[0] == "-":
                addr -= num(a[1:])
            elif a != "*":
                addr = num(a)
            if skip:
                skip = False
                continue
            if keep and len(parts) >= 3:
                counts[addr] += int(parts[2])
    return counts


# (part, pattern): the first frame of an address's inline chain (innermost first) that matches
# one of these patterns decides the part.
PARTS = [
    ("node test", "node_test"),
    ("prefetch", "prefetch"),
    ("triangle test", "intersect_triangle_simd"),
    ("triangle test", "triangle_tail"),
    ("triangle test", "intersect<"),
    ("leaf loop", "leaf"),
    ("ray set-up", "NodeRay"),
    ("ray set-up", "RayPre"),
    ("ray set-up", "ray_ok"),
    ("traversal loop (child decode, stack, culling)", "traverse"),
    ("traversal loop (child decode, stack, culling)", "node_key"),
    ("traversal loop (child decode, stack, culling)", "le_mask"),
]


def candela(profile, binary, rays):
    counts = ir_per_address(profile)
    addrs = sorted(counts)
    out = subprocess.run(
        ["addr2line", "-f", "-i", "-C", "-a", "-e", binary],
        input="\n".join(hex(a) for a in addrs),
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    chains = {}
    cur = None
    for line in out.splitlines():
        if line.startswith("0x"):
            cur = int(line, 16)
            chains[cur] = []
        elif not line.startswith(("/", "??:")):
            chains[cur].append(line)
    parts = collections.Counter()
    for a, c in counts.items():
        part = "other (entry, hit record)"
        for frame in chains.get(a, []):
            hit = next(
                (p for p, pat in PARTS if re.search(r"(^|::|\b)" + re.escape(pat), frame)),
                None,
            )
            if hit:
                part = hit
                break
        parts[part] += c
    for part, c in parts.most_common():
        print(f"{part:<50} {c / rays:8.1f}")
    print(f"{'all':<50} {sum(parts.values()) / rays:8.1f}")


def blocks(profile, obj, rays, min_per_ray):
    counts = ir_per_address(profile, obj)
    hot = [a for a, c in counts.items() if c / rays >= min_per_ray]
    if not hot:
        return
    lo, hi = min(hot), max(hot) + 16
    out = subprocess.run(
        ["objdump", "-d", "--no-show-raw-insn", f"--start-address={lo:#x}",
         f"--stop-address={hi:#x}", obj],
        capture_output=True, text=True, check=True,
    ).stdout
    runs = []  # [per-ray count, length, first address, first instruction]
    for line in out.splitlines():
        m = re.match(r"\s*([0-9a-f]+):\s+(.*)", line)
        if not m:
            continue
        a = int(m.group(1), 16)
        per_ray = round(counts.get(a, 0) / rays, 2)
        if runs and runs[-1][0] == per_ray:
            runs[-1][1] += 1
        else:
            runs.append([per_ray, 1, a, m.group(2).strip()])
    print(f"{'per ray':>8} {'length':>6}  first instruction")
    for per_ray, n, a, first in sorted(runs, key=lambda r: -r[0] * r[1]):
        if per_ray >= min_per_ray and n >= 3:
            print(f"{per_ray:8.2f} {n:6d}  {a:#x}: {first}")
    total = sum(counts.values()) / rays
    print(f"all instructions per ray: {total:.1f}")


def main(argv):
    if len(argv) >= 5 and argv[1] == "candela":
        candela(argv[2], argv[3], float(argv[4]))
    elif len(argv) >= 5 and argv[1] == "blocks":
        blocks(argv[2], argv[3], float(argv[4]), float(argv[5]) if len(argv) > 5 else 1.0)
    else:
        sys.exit(__doc__)


if __name__ == "__main__":
    main(sys.argv)
