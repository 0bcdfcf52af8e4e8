#!/usr/bin/env python3
"""Write the BSDF XML test files of tests/data/bsdf/ (Klems matrices, tensor trees, broken files).

    target/venv/bin/python scripts/bsdf_testfiles.py [--out tests/data/bsdf]

Needs pyradiance 1.3.1 in the interpreter running this script (its wheel ships bsdf2klems,
bsdf2ttree and checkBSDF; scripts/setup_python.sh installs it). Deterministic: bsdf2klems and
bsdf2ttree draw their samples from an unseeded (so fixed) generator, checked by running twice;
everything else is written here. Then run scripts/bsdf_oracle.py for the expected values.

Functions are in Radiance's convention (bsdf2klems(1)): f(ix,iy,iz, ox,oy,oz) in 1/sr, both
vectors pointing away from the surface (i toward the source), iz*oz > 0 is reflection. Every
function here is symmetric in (i, o), hence reciprocal; the files are reciprocal up to the
sampling of bsdf2klems -n (checkBSDF's reciprocity error, README.md).

Files (README.md lists sizes and checkBSDF's sums):
- klems_quarter_diffuse.xml  Klems Quarter, R = 0.2 both sides, T = 0.5, all Lambertian.
- klems_half_lobe.xml        Klems Half, R = 0.05 both sides, T = 0.3 Lambertian + 0.2 Phong
                             lobe (exponent 28) around the straight-through direction.
- klems_full_lobe.xml        Klems Full, the same function, *only* the 'Transmission Front'
                             block (four full-basis blocks would be 930 KB), written back as
                             WINDOW 6 does: one line per outgoing patch, comma-separated.
                             Tests: Back transmission by reciprocity, no reflection.
- klems_full_clear.xml       Klems Full, a clear opening: T = diag(1/Lambda_j) Front and Back,
                             no reflection blocks (Lambda_j: projected solid angle of patch j).
- klems_quarter_sides.xml    Klems Quarter, constant blocks: hemispherical Reflection Front 0.1,
                             Transmission Front 0.4, Reflection Back 0.3, Transmission Back 0.2
                             (which block a side uses; deliberately not reciprocal).
- ttree3_lobe.xml            TensorTree3 (isotropic), a wider lobe (exponent 8), -g 5.
- ttree4_aniso.xml           TensorTree4 (anisotropic), terms in (ix+ox) and (iy+oy), -g 3.
- broken_*.xml               error cases (quarter basis or a small tree), see BROKEN below.
"""

import argparse
import math
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pyradiance

PYRAD = Path(os.path.dirname(pyradiance.__file__))

DIFFUSE = "diff(ix,iy,iz,ox,oy,oz) = if(iz*oz, 0.2/PI, 0.5/PI)"
LOBE28 = ("lobe(ix,iy,iz,ox,oy,oz) = if(iz*oz, 0.05/PI, "
          "0.3/PI + 0.2*30/(2*PI)*max(0,-(ix*ox+iy*oy+iz*oz))^28)")
LOBE8 = ("lobe(ix,iy,iz,ox,oy,oz) = if(iz*oz, 0.05/PI, "
         "0.3/PI + 0.2*10/(2*PI)*max(0,-(ix*ox+iy*oy+iz*oz))^8)")
# Anisotropic and sensitive to the sign of X and of Y: a mirrored or rotated frame changes it.
ANISO = ("an(ix,iy,iz,ox,oy,oz) = if(iz*oz, 0.1/PI*(1 + 0.3*(ix+ox) + 0.15*(iy+oy)), "
         "0.2/PI*(1 + 0.3*(ix+ox) + 0.15*(iy+oy)) "
         "+ 0.4/PI*3*exp(-((ix+ox)^2/0.2 + (iy+oy)^2/1.0)))")

# The tools' command lines (argv after the program name); README.md quotes them.
COMMANDS = {
    "klems_quarter_diffuse.xml": ["bsdf2klems", "-q", "-p", "-n", "64", "+forward", "-e", DIFFUSE, "diff"],
    "klems_half_lobe.xml": ["bsdf2klems", "-h", "-p", "-n", "400", "+forward", "-e", LOBE28, "lobe"],
    "klems_full_lobe.xml": ["bsdf2klems", "-p", "-n", "100", "+forward", "-e", LOBE28, "lobe"],
    "ttree3_lobe.xml": ["bsdf2ttree", "-p", "-t3", "-g", "5", "-t", "90", "+forward", "-e", LOBE8, "lobe"],
    "ttree4_aniso.xml": ["bsdf2ttree", "-p", "-t4", "-g", "3", "-t", "90", "+forward", "-e", ANISO, "an"],
    "tree_small.tmp": ["bsdf2ttree", "-p", "-t3", "-g", "3", "-t", "90", "+forward", "-e", LOBE8, "lobe"],
}

# Klems bases (Radiance bsdf_m.c abase_list): ring lower theta bounds in degrees (last = 90)
# and patches per ring.
KLEMS = {
    "LBNL/Klems Full": ([0, 5, 15, 25, 35, 45, 55, 65, 75, 90], [1, 8, 16, 20, 24, 24, 24, 16, 12]),
    "LBNL/Klems Half": ([0, 6.5, 19.5, 32.5, 45.5, 58.5, 71.5, 90], [1, 8, 12, 16, 20, 12, 8]),
    "LBNL/Klems Quarter": ([0, 9, 27, 45, 63, 90], [1, 8, 12, 12, 8]),
}


def env():
    e = dict(os.environ)
    e["PATH"] = f"{PYRAD / 'bin'}:{e.get('PATH', '')}"
    e["RAYPATH"] = f".:{PYRAD / 'lib'}"
    return e


def run_tool(argv):
    """stdout of a Radiance tool; its progress output (stderr) is dropped."""
    r = subprocess.run(argv, env=env(), capture_output=True, text=True, check=False)
    if r.returncode != 0:
        sys.exit(f"{argv[0]} failed ({r.returncode}): {r.stderr[-2000:]}")
    return r.stdout


def klems_solid_angles(basis):
    """Projected solid angle of each patch, in index order (io_getohm)."""
    bounds, nphi = KLEMS[basis]
    out = []
    for k, n in enumerate(nphi):
        lo, hi = math.radians(bounds[k]), math.radians(bounds[k + 1])
        out += [math.pi * (math.cos(lo) ** 2 - math.cos(hi) ** 2) / n] * n
    return out


def basis_block_xml(basis):
    bounds, nphi = KLEMS[basis]
    parts = [f"\t\t<AngleBasis>\n\t\t\t<AngleBasisName>{basis}</AngleBasisName>\n"]
    for k, n in enumerate(nphi):
        lo, hi = bounds[k], bounds[k + 1]
        centre = 0 if k == 0 else (lo + hi) / 2
        parts.append(
            f"\t\t\t<AngleBasisBlock>\n\t\t\t\t<Theta>{centre:g}</Theta>\n\t\t\t\t<nPhis>{n}</nPhis>\n"
            f"\t\t\t\t<ThetaBounds>\n\t\t\t\t\t<LowerTheta>{lo:g}</LowerTheta>\n"
            f"\t\t\t\t\t<UpperTheta>{hi:g}</UpperTheta>\n\t\t\t\t</ThetaBounds>\n"
            f"\t\t\t</AngleBasisBlock>\n")
    parts.append("\t\t</AngleBasis>\n")
    return "".join(parts)


def klems_xml(basis, blocks, comment, name="test"):
    """A WINDOW 6 style Klems file (structure of bsdf2klems' output, 'Columns' order).

    blocks: list of (direction, rows, fmt, sep) with rows[o][i] the value for outgoing patch o
    and incident patch i (each text line is one outgoing patch, as WINDOW and bsdf2klems write).
    """
    head = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f"<!-- {comment} -->\n"
        '<WindowElement xmlns="http://windows.lbl.gov" '
        'xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" '
        'xsi:schemaLocation="http://windows.lbl.gov/BSDF-v1.4.xsd">\n'
        "<WindowElementType>System</WindowElementType>\n<FileType>BSDF</FileType>\n"
        "<Optical>\n<Layer>\n\t<Material>\n"
        f"\t\t<Name>{name}</Name>\n\t\t<Manufacturer>candela tests</Manufacturer>\n"
        '\t\t<Thickness unit="millimeter">0</Thickness>\n\t\t<DeviceType>Other</DeviceType>\n'
        "\t</Material>\n\t<DataDefinition>\n"
        "\t\t<IncidentDataStructure>Columns</IncidentDataStructure>\n"
        f"{basis_block_xml(basis)}\t</DataDefinition>\n")
    body = []
    for direction, rows, fmt, sep in blocks:
        text = "\n".join(sep.join(fmt % v for v in row) for row in rows)
        body.append(
            "\t<WavelengthData>\n\t\t<LayerNumber>System</LayerNumber>\n"
            '\t\t<Wavelength unit="Integral">Visible</Wavelength>\n'
            "\t\t<SourceSpectrum>CIE Illuminant D65 1nm.ssp</SourceSpectrum>\n"
            "\t\t<DetectorSpectrum>ASTM E308 1931 Y.dsp</DetectorSpectrum>\n"
            "\t\t<WavelengthDataBlock>\n"
            f"\t\t\t<WavelengthDataDirection>{direction}</WavelengthDataDirection>\n"
            f"\t\t\t<ColumnAngleBasis>{basis}</ColumnAngleBasis>\n"
            f"\t\t\t<RowAngleBasis>{basis}</RowAngleBasis>\n"
            "\t\t\t<ScatteringDataType>BTDF</ScatteringDataType>\n"
            f"\t\t\t<ScatteringData>\n{text}\n\t\t\t</ScatteringData>\n"
            "\t\t</WavelengthDataBlock>\n\t</WavelengthData>\n")
    return head + "".join(body) + "</Layer>\n</Optical>\n</WindowElement>\n"


def klems_blocks(xml_text):
    """{direction: flat list of numbers} of a Klems file written by bsdf2klems."""
    out = {}
    for m in re.finditer(r"<WavelengthDataDirection>([^<]+)</WavelengthDataDirection>"
                         r".*?<ScatteringData>(.*?)</ScatteringData>", xml_text, re.S):
        out[m.group(1).strip()] = [float(t) for t in re.split(r"[\s,]+", m.group(2).strip())]
    return out


def rows_of(flat, n):
    return [flat[o * n:(o + 1) * n] for o in range(n)]


def full_lobe(raw):
    """Transmission Front of bsdf2klems' full-basis output, WINDOW-style rows with commas.

    %.4g keeps exactly the 4 significant digits bsdf2klems printed (%.3e)."""
    flat = klems_blocks(raw)["Transmission Front"]
    cmd = shlex.join(COMMANDS["klems_full_lobe.xml"])
    return klems_xml("LBNL/Klems Full", [("Transmission Front", rows_of(flat, 145), "%.4g", ", ")],
                     f"Transmission Front of: {cmd} (scripts/bsdf_testfiles.py)", "full lobe")


def clear_opening():
    lam = klems_solid_angles("LBNL/Klems Full")
    n = len(lam)
    rows = [[(1.0 / lam[o] if o == i else 0.0) for i in range(n)] for o in range(n)]
    comment = ("clear opening: T = diag(1/Lambda_j), Lambda_j = pi (cos^2 theta_lo - cos^2 theta_hi)"
               " / nphi (scripts/bsdf_testfiles.py)")
    return klems_xml("LBNL/Klems Full",
                     [("Transmission Front", rows, "%.8g", " "),
                      ("Transmission Back", rows, "%.8g", " ")], comment, "clear opening")


def sides():
    """Constant blocks, a different hemispherical value per block, to tell the sides apart
    (not reciprocal: Transmission Front 0.4 != Back 0.2)."""
    n = 41
    vals = [("Reflection Front", 0.1), ("Transmission Front", 0.4), ("Reflection Back", 0.3),
            ("Transmission Back", 0.2)]
    blocks = [(d, [[h / math.pi] * n for _ in range(n)], "%.6g", " ") for d, h in vals]
    return klems_xml("LBNL/Klems Quarter", blocks, "sides: hemispherical RF 0.1, TF 0.4, RB 0.3, "
                     "TB 0.2, each Lambertian (scripts/bsdf_testfiles.py)", "sides")


def broken_files(diffuse_raw, tree_raw):
    """name -> (text, what is wrong); all from the quarter diffuse file or a small tree."""
    q = "LBNL/Klems Quarter"
    b = klems_blocks(diffuse_raw)
    # Two blocks keep them small: the broken one and one more.
    order = ["Transmission Front", "Reflection Back"]

    def quarter(blocks, comment):
        return klems_xml(q, [(d, rows_of(v, 41), "%.4g", " ") for d, v in blocks], comment, "broken")

    good = [(d, b[d]) for d in order]
    out = {}
    text = quarter(good, "truncated in the ScatteringData of Transmission Front")
    cut = text.index("<ScatteringData>", text.index(">Transmission Front<")) + 16 + 2000
    out["broken_truncated.xml"] = (text[:cut], "file ends inside the ScatteringData of 'Transmission "
                                   "Front' (no closing tags)")
    few = [(d, v if d != "Transmission Front" else v[:-20]) for d, v in good]
    text = quarter(few, "Transmission Front has 1661 of 1681 values")
    out["broken_too_few_values.xml"] = (text, "'Transmission Front' has 1661 of 41*41 = 1681 values")
    text = quarter(good, "value 101 (1-based) of Transmission Front is 'abc'")
    start = text.index("<ScatteringData>", text.index(">Transmission Front<")) + 16
    toks = list(re.finditer(r"[^\s,]+", text[start:]))
    t = toks[100]
    text = text[:start + t.start()] + "abc" + text[start + t.end():]
    out["broken_non_numeric.xml"] = (text, "value 101 (1-based; outgoing patch 2, incident patch 18, "
                                     "0-based) of 'Transmission Front' is the token 'abc'")
    hot = [(d, v if d != "Transmission Front" else [x * 2.1 for x in v]) for d, v in good]
    text = quarter(hot, "transmission scaled by 2.1: hemispherical T = 1.05 for every incidence")
    out["broken_hemi_sum.xml"] = (text, "'Transmission Front' scaled by 2.1: sum_o f Lambda_o = "
                                  "1.05 > 1.01 for every incident patch")
    text = quarter(good, "ColumnAngleBasis/RowAngleBasis of Reflection Back name an undefined basis")
    pos = text.index(">Reflection Back<")
    tail = text[pos:].replace(q + "</ColumnAngleBasis>", "LBNL/Klems Eighth</ColumnAngleBasis>", 1)
    tail = tail.replace(q + "</RowAngleBasis>", "LBNL/Klems Eighth</RowAngleBasis>", 1)
    out["broken_unknown_basis.xml"] = (text[:pos] + tail, "'Reflection Back' names the basis "
                                       "'LBNL/Klems Eighth', which the file does not define")
    # Tree: drop one closing brace in the middle of 'Transmission Front'.
    start = tree_raw.index("<ScatteringData>", tree_raw.index(">Transmission Front<"))
    end = tree_raw.index("</ScatteringData>", start)
    mid = tree_raw.index("}", (start + end) // 2)
    out["broken_tree_braces.xml"] = (tree_raw[:mid] + tree_raw[mid + 1:],
                                     "TensorTree3: one '}' removed in the middle of the "
                                     "'Transmission Front' ScatteringData (one '{' left unclosed)")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="tests/data/bsdf")
    args = ap.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)

    raw = {name: run_tool(argv) for name, argv in COMMANDS.items()}
    for name in ["klems_quarter_diffuse.xml", "klems_half_lobe.xml", "ttree3_lobe.xml",
                 "ttree4_aniso.xml"]:
        (out / name).write_text(raw[name])
    (out / "klems_full_lobe.xml").write_text(full_lobe(raw["klems_full_lobe.xml"]))
    (out / "klems_full_clear.xml").write_text(clear_opening())
    (out / "klems_quarter_sides.xml").write_text(sides())
    for name, (text, _why) in broken_files(raw["klems_quarter_diffuse.xml"],
                                           raw["tree_small.tmp"]).items():
        (out / name).write_text(text)
    for f in sorted(out.glob("*.xml")):
        print(f"{f.stat().st_size:8d}  {f}")


if __name__ == "__main__":
    main()
