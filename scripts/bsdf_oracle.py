#!/usr/bin/env python3
"""Radiance's values of the BSDF test files, for candela's parser/lookup tests.

    target/venv/bin/python scripts/bsdf_oracle.py [--dir tests/data/bsdf]   # writes *.oracle.csv
    target/venv/bin/python scripts/bsdf_oracle.py --conventions             # prints the probe table
    target/venv/bin/python scripts/bsdf_oracle.py --rtrace                  # pane under a uniform sky

Needs pyradiance 1.3.1 (scripts/setup_python.sh). Deterministic (fixed seeds).

Direction convention (the CSV columns and pyradiance.bsdf.query):
- theta, phi in degrees in the file's own frame: Z = the surface normal of Radiance's BSDF frame,
  X = the file's X axis (Radiance: X = normalize(up x Z), Y = Z x X), direction
  u = (sin(theta) cos(phi), sin(theta) sin(phi), cos(theta)); phi is measured from +X toward +Y.
  theta > 90 is the -Z side. Radiance's +Z side is WINDOW's *back* (the room side when the
  normal points into the room); WINDOW's 'Front' is Radiance's -Z side.
- "in" points from the surface toward the light source, "out" from the surface toward the
  viewer/receiver (both point away from the surface; candela's wi and wo).
- value_per_sr is Radiance's SDevalBSDF(in, out) photopic Y (the files hold Visible data only;
  query's X and Z follow from the grey chromaticity), in 1/sr, and it *includes* the Lambertian
  parts that Radiance splits off at load (extract_diffuse): it is the file's value for that
  (in, out) pair. Radiance perturbs each Klems value by a factor 1 + 6e-4 (d - 1/2), d in [0, 1)
  a hash of the patch pair (mBSDF_color), and each tree value by 1 + 1e-4 sum_i (d_i - 1/2)
  over the dimensions (SDqueryTre): compare with a relative tolerance of 1e-3.
- Block used (Radiance and the XML names): in +Z & out +Z: 'Reflection Back'; in -Z & out -Z:
  'Reflection Front'; in -Z & out +Z: 'Transmission Front'; in +Z & out -Z: 'Transmission Back'
  (if missing: 'Transmission Front' by reciprocity, i.e. in and out swapped). rtrace calls
  SDevalBSDF(view direction, source direction), i.e. with in and out exchanged: for a
  non-reciprocal file it uses the other transmission block (tests/data/bsdf/README.md).

Pairs: 200 per file and side combination (+Z/+Z, +Z/-Z, -Z/+Z, -Z/-Z; in, out), rows in that
order; in each, 100 with in and out drawn uniformly in projected solid angle (theta <= 88 deg from
the normal), then 100 with out within +-4 deg (theta and phi) of the straight-through direction
(transmission) or the mirror direction (reflection) of in; angles rounded to 0.001 deg, then kept
only if no coordinate lies near a cell border: Klems, 0.5 deg from a ring's theta bound or a
patch's phi border (phi borders at 360 (j + 1/2) / nphi; they are the same for the mirrored
index vectors since every nphi > 1 is even); trees, 0.1 cell from a border of the finest grid
(-g) in any of the 3 or 4 tree coordinates (SDqueryTre's Shirley-Chiu coordinates).
"""

import argparse
import math
import re
import sys
import tempfile
from pathlib import Path

import numpy as np
import pyradiance.bsdf as rb

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bsdf_testfiles import KLEMS, klems_xml  # noqa: E402

VALID = ["klems_quarter_diffuse.xml", "klems_quarter_sides.xml", "klems_half_lobe.xml",
         "klems_full_lobe.xml", "klems_full_clear.xml", "ttree3_lobe.xml", "ttree4_aniso.xml"]
COMBOS = [(+1, +1), (+1, -1), (-1, +1), (-1, -1)]  # (side of in, side of out)
PAIRS = 200
SEED = 20261202


def unit(theta_deg, phi_deg):
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return (math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))


def y_value(sd, ti, pi, to, po):
    return float(rb.query(sd, ti, pi, to, po)[1])


# ---------------------------------------------------------------- Klems
def klems_index(basis, v):
    """fo_getndx: patch of a direction with v.z >= 0."""
    bounds, nphi = KLEMS[basis]
    pol = math.degrees(math.acos(max(-1.0, min(1.0, v[2]))))
    azi = math.degrees(math.atan2(v[1], v[0]))
    if azi < 0:
        azi += 360
    ring = max(k for k in range(len(nphi)) if bounds[k] <= pol)
    j = int(azi * nphi[ring] / 360 + 0.5)
    if j >= nphi[ring]:
        j = 0
    return sum(nphi[:ring]) + j


def klems_far_from_border(basis, theta, phi, margin=0.5):
    bounds, nphi = KLEMS[basis]
    t = theta if theta <= 90 else 180 - theta
    if any(abs(t - b) < margin for b in bounds[1:-1]):
        return False
    ring = max(k for k in range(len(nphi)) if bounds[k] <= t)
    n = nphi[ring]
    if n == 1:
        return True
    w = 360 / n
    frac = (phi % w) / w  # borders at (j + 1/2) w
    return abs(frac - 0.5) * w >= margin


# ---------------------------------------------------------------- trees
def disk2square(x, y):
    """Radiance disk2square.c (Shirley-Chiu concentric map), disk -> [0,1]^2."""
    r = math.hypot(x, y)
    phi = math.atan2(y, x)
    if phi < -math.pi / 4:
        phi += 2 * math.pi
    if phi < math.pi / 4:
        a, b = r, phi * r / (math.pi / 4)
    elif phi < 3 * math.pi / 4:
        b = r
        a = -(phi - math.pi / 2) * b / (math.pi / 4)
    elif phi < 5 * math.pi / 4:
        a = -r
        b = (phi - math.pi) * a / (math.pi / 4)
    else:
        b = -r
        a = -(phi - 3 * math.pi / 2) * b / (math.pi / 4)
    s = 0.5 / 0.9999999999999
    return a * s + 0.5, b * s + 0.5


def tree_coords(ndim, vin, vout):
    """SDqueryTre's grid position for (in, out) after its side swap (bsdf_t.c)."""
    # No swap needed: the natural (in, out) sides of each block are the ones SDqueryTre expects.
    if ndim == 3:
        ang = -math.atan2(-vin[1], -vin[0])
        c, s = math.cos(ang), math.sin(ang)
        rx, ry = c * vout[0] - s * vout[1], s * vout[0] + c * vout[1]
        x0 = 0.5 - 0.5 * math.hypot(vin[0], vin[1])
        return (x0, *disk2square(rx, ry))
    return (*disk2square(-vin[0], -vin[1]), *disk2square(vout[0], vout[1]))


def tree_far_from_border(ndim, g, vin, vout, margin=0.1):
    cells = 1 << g
    for x in tree_coords(ndim, vin, vout):
        f = x * cells
        if abs(f - round(f)) < margin:
            return False
    return True


def file_kind(path):
    text = path.read_text()
    m = re.search(r"<IncidentDataStructure>\s*(\w+)", text)
    if m.group(1) in ("TensorTree3", "TensorTree4"):
        g = int(re.search(r"-g (\d+)", text).group(1))
        return ("tree", int(m.group(1)[-1]), g)
    basis = re.search(r"<ColumnAngleBasis>([^<]+)<", text).group(1).strip()
    return ("klems", basis, None)


def pairs_for(kind, seed):
    """PAIRS per side combination: half random, half with out near the straight-through
    (transmission) or mirror (reflection) direction of in, where the lobes and a clear
    opening's diagonal are."""
    rng = np.random.default_rng(seed)
    smax = math.sin(math.radians(88)) ** 2
    rows = []
    for si, so in COMBOS:
        got = 0
        while got < PAIRS:
            u = rng.random(6)
            ti = math.degrees(math.asin(math.sqrt(u[0] * smax)))
            pi_ = 360 * u[2]
            if got < PAIRS // 2:
                to, po = math.degrees(math.asin(math.sqrt(u[1] * smax))), 360 * u[3]
            else:  # theta_out = theta_in on the other side; phi_out = phi_in + 180 (both cases)
                to = min(88.0, max(0.0, ti + 8 * (u[4] - 0.5)))
                po = (pi_ + 180 + 8 * (u[5] - 0.5)) % 360
            if si < 0:
                ti = 180 - ti
            if so < 0:
                to = 180 - to
            ti, pi_, to, po = (round(x, 3) for x in (ti, pi_, to, po))
            if kind[0] == "klems":
                ok = (klems_far_from_border(kind[1], ti, pi_)
                      and klems_far_from_border(kind[1], to, po))
            else:
                ok = tree_far_from_border(kind[1], kind[2], unit(ti, pi_), unit(to, po))
            if ok:
                rows.append((ti, pi_, to, po))
                got += 1
    return rows


def write_oracles(d):
    # All files are loaded before the first query: loading a tree after queries on other files
    # was seen to hang inside load_file (pyradiance 1.3.1, depending on the process' stdout).
    sds = {name: rb.load_file(str(d / name)) for name in VALID}
    for k, name in enumerate(VALID):
        path = d / name
        sd = sds[name]
        if sd is None:
            sys.exit(f"pyradiance could not load {path}")
        kind = file_kind(path)
        lines = ["theta_in_deg,phi_in_deg,theta_out_deg,phi_out_deg,value_per_sr"]
        for ti, pi_, to, po in pairs_for(kind, SEED + k):
            lines.append(f"{ti:.3f},{pi_:.3f},{to:.3f},{po:.3f},{y_value(sd, ti, pi_, to, po):.7g}")
        out = d / (name + ".oracle.csv")
        out.write_text("\n".join(lines) + "\n")
        print(f"{out}: {len(lines) - 1} pairs ({kind[0]} {kind[1]})")


# ---------------------------------------------------------------- convention probes
BLOCKS = ["Transmission Front", "Transmission Back", "Reflection Front", "Reflection Back"]


def klems_probe(tmp, which):
    """Quarter-basis file whose value codes (block, outgoing o or incident i)."""
    n = 41
    blocks = []
    for b, name in enumerate(BLOCKS):
        rows = [[1e-3 * (1 + (o if which == "o" else i) + 50 * b) for i in range(n)]
                for o in range(n)]
        blocks.append((name, rows, "%.6g", " "))
    p = tmp / f"probe_{which}.xml"
    p.write_text(klems_xml("LBNL/Klems Quarter", blocks, "probe"))
    return rb.load_file(str(p))


def klems_expected(vin, vout):
    """(XML block, i, o) from the index table of docs/design/fenestration.md section 3."""
    q = "LBNL/Klems Quarter"
    neg = (-vin[0], -vin[1], -vin[2])
    if vin[2] < 0 and vout[2] > 0:
        return "Transmission Front", klems_index(q, neg), klems_index(q, vout)
    if vin[2] > 0 and vout[2] < 0:
        return ("Transmission Back", klems_index(q, (-vin[0], -vin[1], vin[2])),
                klems_index(q, (vout[0], vout[1], -vout[2])))
    if vin[2] < 0:
        return "Reflection Front", klems_index(q, neg), klems_index(q, (vout[0], vout[1], -vout[2]))
    return "Reflection Back", klems_index(q, (-vin[0], -vin[1], vin[2])), klems_index(q, vout)


def tree_probe(tmp, ndim):
    """TensorTree<ndim>: root with 2^ndim children, each a 2^ndim leaf grid (log2GR = 1);
    value codes (block, child, leaf)."""
    m = 1 << ndim
    head = klems_xml("LBNL/Klems Quarter", [], "probe").split("<DataDefinition>")[0]
    parts = [head, f"<DataDefinition>\n<IncidentDataStructure>TensorTree{ndim}</IncidentDataStructure>\n"
             "</DataDefinition>\n"]
    for b, name in enumerate(BLOCKS):
        kids = []
        for c in range(m):
            vals = " ".join(f"{1e-4 * (1 + 16 * c + leaf + 300 * b):.6g}" for leaf in range(m))
            kids.append("{ " + vals + " }")
        parts.append(
            "<WavelengthData>\n<LayerNumber>System</LayerNumber>\n"
            '<Wavelength unit="Integral">Visible</Wavelength>\n<WavelengthDataBlock>\n'
            f"<WavelengthDataDirection>{name}</WavelengthDataDirection>\n"
            "<AngleBasis>LBNL/Shirley-Chiu</AngleBasis>\n<ScatteringDataType>BTDF</ScatteringDataType>\n"
            "<ScatteringData>\n{\n" + "\n".join(kids) + "\n}\n</ScatteringData>\n"
            "</WavelengthDataBlock>\n</WavelengthData>\n")
    parts.append("</Layer>\n</Optical>\n</WindowElement>\n")
    p = tmp / f"probe_tree{ndim}.xml"
    p.write_text("".join(parts))
    return rb.load_file(str(p))


def tree_expected(x):
    """(child, leaf) by bsdf_t.c: child bit i <=> x_i >= 1/2 (dimension 0 the least significant
    bit); in the leaf grid the last dimension varies fastest."""
    nd = len(x)
    child = sum(1 << i for i in range(nd) if x[i] >= 0.5)
    idx = [int(2 * (x[i] - (x[i] >= 0.5) * 0.5) * 2) for i in range(nd)]
    leaf = sum(idx[i] << (nd - 1 - i) for i in range(nd))
    return child, leaf


def conventions():
    rng = np.random.default_rng(SEED)
    with tempfile.TemporaryDirectory() as td:
        tmp = Path(td)
        po, pi_ = klems_probe(tmp, "o"), klems_probe(tmp, "i")
        trees = {3: tree_probe(tmp, 3), 4: tree_probe(tmp, 4)}
        stats = {}
        for si, so in COMBOS:
            ok_k = ok_t = n = nt = 0
            for _ in range(2000):
                u = rng.random(4)
                ti = math.degrees(math.asin(math.sqrt(u[0] * 0.998)))
                to = math.degrees(math.asin(math.sqrt(u[1] * 0.998)))
                ti, to = (ti if si > 0 else 180 - ti), (to if so > 0 else 180 - to)
                pin, pout = 360 * u[2], 360 * u[3]
                if not (klems_far_from_border("LBNL/Klems Quarter", ti, pin, 0.2)
                        and klems_far_from_border("LBNL/Klems Quarter", to, pout, 0.2)):
                    continue
                vin, vout = unit(ti, pin), unit(to, pout)
                n += 1
                ko = round(y_value(po, ti, pin, to, pout) * 1000) - 1
                ki = round(y_value(pi_, ti, pin, to, pout) * 1000) - 1
                got = (BLOCKS[ko // 50], ki % 50, ko % 50)
                ok_k += got == klems_expected(vin, vout)
                block = (("Transmission Front" if si < 0 else "Transmission Back") if si != so
                         else ("Reflection Front" if si < 0 else "Reflection Back"))
                for nd, pt in trees.items():
                    kt = round(y_value(pt, ti, pin, to, pout) * 1e4) - 1
                    x = tree_coords(nd, vin, vout)
                    if all(abs(c * 4 - round(c * 4)) > 1e-3 for c in x):
                        nt += 1
                        got = (BLOCKS[kt // 300], (kt % 300) // 16, (kt % 300) % 16)
                        ok_t += got == (block, *tree_expected(x))
            side = lambda s: "+Z" if s > 0 else "-Z"  # noqa: E731
            stats[(si, so)] = (n, ok_k, nt, ok_t)
            print(f"in {side(si)} out {side(so)}: Klems (block, i, o) as the table: {ok_k} of {n}; "
                  f"trees 3+4 (block, child, leaf) as bsdf_t.c: {ok_t} of {nt}")
        return stats


RTRACE_ARGS = ["-I", "-h", "-ab", "2", "-ad", "4096", "-as", "0", "-aa", "0", "-lw", "1e-5"]


def klems_double_sum(path, direction):
    """sum_o sum_i f[o,i] Lambda_o Lambda_i of one block: E / L under a uniform sky for an
    irradiance meter behind (transmission) or in front of (reflection) an infinite pane."""
    from bsdf_testfiles import klems_blocks, klems_solid_angles
    text = path.read_text()
    blocks = klems_blocks(text)
    if direction not in blocks:
        return float("nan")
    basis = re.search(r"<ColumnAngleBasis>([^<]+)<", text).group(1).strip()
    lam = np.array(klems_solid_angles(basis))
    f = np.array(blocks[direction]).reshape(len(lam), len(lam))  # [o, i], 'Columns'
    return float(lam @ f @ lam)


def rtrace_pane(d):
    """Infinite horizontal BSDF pane (z = 0, up = +Y) under a uniform sky of radiance 1 on the
    upper hemisphere (glow, not a light source: reached by ambient rays), no ground.
    Meters 1 m below (facing up: transmission) and 1 m above (facing down: reflection).
    Prints E and the matrix double sums of the blocks rtrace is found to use."""
    import subprocess
    from bsdf_testfiles import env
    files = ["klems_quarter_diffuse.xml", "klems_quarter_sides.xml", "klems_half_lobe.xml",
             "klems_full_lobe.xml", "klems_full_clear.xml", "ttree3_lobe.xml", "ttree4_aniso.xml"]
    with tempfile.TemporaryDirectory() as td:
        tmp = Path(td)
        for name in files:
            for up_side, verts in [("+Z", "-1e3 -1e3 0 1e3 -1e3 0 1e3 1e3 0 -1e3 1e3 0"),
                                   ("-Z", "-1e3 1e3 0 1e3 1e3 0 1e3 -1e3 0 -1e3 -1e3 0")]:
                scene = tmp / "scene.rad"
                scene.write_text(
                    "void glow skyglow 0 0 4 1 1 1 0\n"
                    "skyglow source sky 0 0 4 0 0 1 180\n"
                    f"void BSDF pane 6 0 {(d / name).resolve()} 0 1 0 . 0 0\n"
                    f"pane polygon p 0 0 12 {verts}\n")
                oct_ = tmp / "scene.oct"
                with open(oct_, "wb") as f:
                    subprocess.run(["oconv", str(scene)], stdout=f, env=env(), check=True)
                cmd = ["rtrace", *RTRACE_ARGS, str(oct_)]
                out = subprocess.run(cmd, input="0 0 -1 0 0 1\n0 0 1 0 0 -1\n", env=env(),
                                     capture_output=True, text=True, check=True, cwd=td).stdout
                below, above = (float(line.split()[1]) for line in out.strip().splitlines())
                # The sky is on the up side; the meter below views the other side.
                t_view = "Transmission Front" if up_side == "+Z" else "Transmission Back"
                t_light = "Transmission Back" if up_side == "+Z" else "Transmission Front"
                r_top = "Reflection Back" if up_side == "+Z" else "Reflection Front"
                sums = ""
                if name.startswith("klems"):
                    p = d / name
                    sums = (f"; sums: {t_view} {klems_double_sum(p, t_view):.6f}, "
                            f"{t_light} {klems_double_sum(p, t_light):.6f}, "
                            f"{r_top} {klems_double_sum(p, r_top):.6f}")
                print(f"{name:26s} {up_side} up: E below {below:.6f}, E above {above:.6f}{sums}")
    print("rtrace " + " ".join(RTRACE_ARGS) + " scene.oct; meters '0 0 -1 0 0 1' (below) and "
          "'0 0 1 0 0 -1' (above)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dir", default="tests/data/bsdf")
    ap.add_argument("--conventions", action="store_true")
    ap.add_argument("--rtrace", action="store_true")
    args = ap.parse_args()
    if args.conventions:
        conventions()
    elif args.rtrace:
        rtrace_pane(Path(args.dir))
    else:
        write_oracles(Path(args.dir))


if __name__ == "__main__":
    main()
