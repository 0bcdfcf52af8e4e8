#!/usr/bin/env python3
"""Regenerate candela's spectral data tables in data/ from colour-science.

Usage (from the repository root):

    scripts/setup_python.sh                     # once: creates target/venv
    target/venv/bin/python scripts/gen_data.py  # rewrites data/*.csv

Every table except data/cornell-box.csv is written at 1 nm from 360 nm to 830 nm
(471 rows).  Source spectra that are tabulated on a different shape are aligned with
exactly the call colour-science itself uses when it integrates them against 1 nm colour
matching functions, ``sd.copy().align(SpectralShape(360, 830, 1))`` (the spectrum's own
interpolator -- linear for the CIE illuminants, Sprague (1880) for uniformly spaced
reflectances -- and constant extrapolation of the end values), so that candela and
colour-science integrate bit-identical numbers.  Values are written with Python's
shortest round-trip float repr, so parsing them in Rust gives the same f64 values.

The luminous efficiency functions are aligned with zero extrapolation, the way
colour.luminous_flux / luminous_efficacy align them (the scotopic V'(lambda) is defined
on 380-780 nm only).

data/cornell-box.csv is NOT generated from colour-science: it is transcribed from the
Cornell University Program of Computer Graphics "Cornell Box Data" page; this script
rewrites it from the constants below so that data/ is reproducible from one command.
"""

from __future__ import annotations

import os
import sys
import warnings

warnings.filterwarnings("ignore")

import colour  # noqa: E402
import numpy as np  # noqa: E402
from colour import SpectralShape  # noqa: E402
from colour.quality.datasets import SDS_TCS  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DATA = os.path.join(ROOT, "data")
SHAPE = SpectralShape(360, 830, 1)
WL = np.arange(360, 831, 1)
assert len(WL) == 471
VERSION = colour.__version__
REGEN = "target/venv/bin/python scripts/gen_data.py"

LICENCE_CIE = (
    "# licence: the CIE tables are published by the Commission Internationale de l'Eclairage\n"
    "#   (CIE) and redistributed by colour-science (BSD-3-Clause, Colour Developers);\n"
    "#   the tabulated values are factual data.\n"
)


def fmt(v: float) -> str:
    v = float(v)
    if v == 0.0:
        return "0"
    return repr(v)


def aligned(sd, zero_extrapolation=False, linear=False):
    sd = sd.copy()
    if linear:
        sd = sd.align(SHAPE, interpolator=colour.LinearInterpolator)
    elif zero_extrapolation:
        sd = sd.align(SHAPE, extrapolator_kwargs={"method": "Constant", "left": 0, "right": 0})
    else:
        sd = sd.align(SHAPE)
    assert np.array_equal(sd.wavelengths, WL), sd.name
    return sd.values


def write(name: str, header: str, columns: dict[str, np.ndarray]) -> None:
    path = os.path.join(DATA, name)
    names = list(columns)
    for n in names:
        assert "," not in n, n
        assert len(columns[n]) == len(WL), n
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(header)
        f.write(f"# regenerate: {REGEN}\n")
        f.write(f"# sampling: 360-830 nm every 1 nm ({len(WL)} rows)\n")
        f.write("nm," + ",".join(names) + "\n")
        for i, w in enumerate(WL):
            f.write(str(int(w)) + "," + ",".join(fmt(columns[n][i]) for n in names) + "\n")
    print(f"wrote {path}")


def main() -> int:
    os.makedirs(DATA, exist_ok=True)

    # --- colour-matching functions -------------------------------------------------
    for key, fname in (
        ("CIE 1931 2 Degree Standard Observer", "cmfs-cie1931-2.csv"),
        ("CIE 1964 10 Degree Standard Observer", "cmfs-cie1964-10.csv"),
    ):
        cmfs = colour.MSDS_CMFS[key]
        assert cmfs.shape == SHAPE, cmfs.shape  # native 360-830 nm, 1 nm: no resampling
        write(
            fname,
            f"# {key} colour-matching functions x_bar, y_bar, z_bar\n"
            f"# source: colour-science {VERSION}, colour.MSDS_CMFS['{key}']\n"
            "#   (native 360-830 nm at 1 nm; values copied unchanged)\n" + LICENCE_CIE,
            {"x_bar": cmfs.values[:, 0], "y_bar": cmfs.values[:, 1], "z_bar": cmfs.values[:, 2]},
        )

    # --- luminous efficiency functions ---------------------------------------------
    lefs = colour.colorimetry.SDS_LEFS_PHOTOPIC
    lefs_s = colour.colorimetry.SDS_LEFS_SCOTOPIC
    v = lefs["CIE 1924 Photopic Standard Observer"]
    vs = lefs_s["CIE 1951 Scotopic Standard Observer"]
    write(
        "luminous-efficiency.csv",
        "# CIE photopic V(lambda) and scotopic V'(lambda) luminous efficiency functions\n"
        f"# source: colour-science {VERSION},\n"
        "#   photopic: colour.colorimetry.SDS_LEFS_PHOTOPIC['CIE 1924 Photopic Standard Observer']"
        " (native 360-830 nm, 1 nm)\n"
        "#   scotopic: colour.colorimetry.SDS_LEFS_SCOTOPIC['CIE 1951 Scotopic Standard Observer']"
        " (native 380-780 nm, 1 nm;\n"
        "#   zero outside, as colour.luminous_flux aligns it with Constant(left=0, right=0))\n"
        + LICENCE_CIE,
        {"photopic": aligned(v, True), "scotopic": aligned(vs, True)},
    )

    # --- illuminants -----------------------------------------------------------------
    names = (
        ["A", "D50", "D55", "D65", "D75", "E"]
        + [f"FL{i}" for i in range(1, 13)]
        + [f"LED-B{i}" for i in range(1, 6)]
        + ["LED-BH1", "LED-RGB1", "LED-V1", "LED-V2"]
    )
    cols = {}
    shapes = []
    for n in names:
        sd = colour.SDS_ILLUMINANTS[n]
        shapes.append(f"#   {n}: native {sd.shape.start:g}-{sd.shape.end:g} nm every "
                      f"{sd.shape.interval:g} nm, {sd.interpolator.__name__}\n")
        cols[n] = aligned(sd)
    write(
        "illuminants.csv",
        "# CIE illuminants (relative spectral power distributions)\n"
        f"# source: colour-science {VERSION}, colour.SDS_ILLUMINANTS[NAME]"
        ".copy().align(SpectralShape(360, 830, 1))\n"
        "#   (the spectrum's own interpolator; constant extrapolation of the end values)\n"
        + "".join(shapes)
        + "#   CIE 15:2018 tables (A, D series, E, FL1-FL12, LED-*)\n" + LICENCE_CIE,
        cols,
    )

    # --- daylight basis --------------------------------------------------------------
    # colour-science's sd_CIE_illuminant_D_series combines S0 + M1 S1 + M2 S2 at the basis'
    # native 5 nm and returns a spectrum with LinearInterpolator, so a 1 nm D-series
    # illuminant is the *linear* interpolation of the 5 nm combination.  Linear interpolation
    # commutes with the linear combination, so the basis is aligned with LinearInterpolator
    # here (not with the basis' own Sprague default) to reproduce that exactly.
    basis = colour.colorimetry.SDS_BASIS_FUNCTIONS_CIE_ILLUMINANT_D_SERIES
    write(
        "daylight-basis.csv",
        "# CIE daylight basis functions S0, S1, S2\n"
        f"# source: colour-science {VERSION}, "
        "colour.colorimetry.SDS_BASIS_FUNCTIONS_CIE_ILLUMINANT_D_SERIES[S0|S1|S2]"
        ".copy().align(SpectralShape(360, 830, 1), interpolator=LinearInterpolator)\n"
        + "".join(
            f"#   {k}: native {s.shape.start:g}-{s.shape.end:g} nm every {s.shape.interval:g} nm\n"
            for k, s in basis.items()
        )
        + "#   linear interpolation, as colour.sd_CIE_illuminant_D_series(xy).align(shape)\n"
        "#   interpolates the 5 nm D-series spectrum it builds from these functions\n"
        + LICENCE_CIE,
        {k: aligned(s, linear=True) for k, s in basis.items()},
    )

    # colour-science's CIE 2017 colour fidelity index builds its daylight reference with
    # sd_CIE_illuminant_D_series(xy, shape=...), which reshapes the basis itself with its own
    # (Sprague) interpolator before combining; colour/tm30.rs uses these for exact agreement.
    write(
        "daylight-basis-sprague.csv",
        "# CIE daylight basis functions S0, S1, S2, Sprague-interpolated to 1 nm\n"
        f"# source: colour-science {VERSION}, "
        "colour.colorimetry.SDS_BASIS_FUNCTIONS_CIE_ILLUMINANT_D_SERIES[S0|S1|S2]"
        ".copy().align(SpectralShape(360, 830, 1))\n"
        "#   (the basis' own SpragueInterpolator), as sd_CIE_illuminant_D_series(xy, shape)\n"
        "#   reshapes them for colour.quality.colour_fidelity_index_CIE2017\n" + LICENCE_CIE,
        {k: aligned(s) for k, s in basis.items()},
    )

    # --- ColorChecker ---------------------------------------------------------------
    cc = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]
    first = next(iter(cc.values()))
    write(
        "colorchecker-ohta.csv",
        "# ColorChecker (N Ohta measurement) spectral reflectances, patches 1-24 in chart order\n"
        f"# source: colour-science {VERSION}, colour.SDS_COLOURCHECKERS['ColorChecker N Ohta']"
        "[PATCH].copy().align(SpectralShape(360, 830, 1))\n"
        f"#   native {first.shape.start:g}-{first.shape.end:g} nm every {first.shape.interval:g} nm, "
        f"{first.interpolator.__name__} interpolation, constant extrapolation of the end values\n"
        "# origin: N. Ohta's measurements as distributed by colour-science (BSD-3-Clause)\n",
        {k: aligned(s) for k, s in cc.items()},
    )

    # --- CIE 13.3 test colour samples --------------------------------------------------
    tcs = SDS_TCS["CIE 1995"]
    first = next(iter(tcs.values()))
    write(
        "tcs-cie13.3.csv",
        "# CIE 13.3-1995 test colour samples TCS01-TCS14 (spectral radiance factors)\n"
        f"# source: colour-science {VERSION}, colour.quality.datasets.SDS_TCS['CIE 1995']"
        "[TCSnn].copy().align(SpectralShape(360, 830, 1))\n"
        f"#   native {first.shape.start:g}-{first.shape.end:g} nm every {first.shape.interval:g} nm, "
        f"{first.interpolator.__name__} interpolation\n" + LICENCE_CIE,
        {k: aligned(s) for k, s in tcs.items() if k in [f"TCS{i:02d}" for i in range(1, 15)]},
    )

    write_alpha_opic()
    write_ces()
    write_vs()
    write_cornell()
    return 0


def write_vs() -> None:
    """The 15 NIST CQS 9.0 test colour samples VS1-VS15 (colour.quality.cqs integrates them
    after the same align call)."""
    from colour.quality.datasets.vs import SDS_VS

    vs = SDS_VS["NIST CQS 9.0"]
    first = vs["VS1"]
    write(
        "vs-nist-cqs9.csv",
        "# NIST Colour Quality Scale 9.0 test colour samples VS1-VS15 (spectral reflectance factors)\n"
        f"# source: colour-science {VERSION}, colour.quality.datasets.vs.SDS_VS['NIST CQS 9.0']"
        "[VSn].copy().align(SpectralShape(360, 830, 1))\n"
        "#   (from the NIST CQS 9.0 spreadsheet, Ohno & Davis; Davis & Ohno, Opt. Eng. 49(3) 033602)\n"
        f"#   native {first.shape.start:g}-{first.shape.end:g} nm every {first.shape.interval:g} nm, "
        f"{first.interpolator.__name__} interpolation\n"
        "# licence: published by NIST (a US government work); redistributed by colour-science\n"
        "#   (BSD-3-Clause); the tabulated values are factual data.\n",
        {f"VS{i}": aligned(vs[f"VS{i}"]) for i in range(1, 16)},
    )


def write_alpha_opic() -> None:
    """CIE S 026 action spectra from luxpy's copy of the CIE S 026 table (read as a file, so
    the script does not import luxpy itself)."""
    import importlib.util

    spec = importlib.util.find_spec("luxpy")
    assert spec is not None, "luxpy is not installed (scripts/setup_python.sh)"
    pkg = os.path.dirname(spec.origin)
    rel = "toolboxes/photbiochem/data/S026_Table2_Data_downloaded_04062025.csv"
    src = np.genfromtxt(os.path.join(pkg, rel), delimiter=",", skip_header=1)[:, :6]
    nm = src[:, 0]
    assert nm[0] == 380 and nm[-1] == 780 and np.all(np.diff(nm) == 1)
    # File columns: nm, s-cone, m-cone, l-cone, rhodopic, melanopic; empty cells (the cone
    # functions below 390 nm) are zero, as luxpy sums them.
    cols = {}
    for i, name in enumerate(["s_cone", "m_cone", "l_cone", "rhodopic", "melanopic"]):
        v = np.zeros(len(WL))
        v[(WL >= 380) & (WL <= 780)] = np.nan_to_num(src[:, i + 1], nan=0.0)
        cols[name] = v
    write(
        "alpha-opic-cie-s026.csv",
        "# CIE S 026/E:2018 alpha-opic action spectra s_alpha(lambda), each 1 at its peak:\n"
        "#   s_cone (cyanopic), m_cone (chloropic), l_cone (erythropic), rhodopic, melanopic\n"
        "# source: the CIE S 026 Table 2 data (CIE S 026 alpha-opic toolbox, 380-780 nm at 1 nm)\n"
        f"#   as shipped by luxpy {_luxpy_version(pkg)} in luxpy/{rel}\n"
        "#   (luxpy.toolboxes.photbiochem._ACTIONSPECTRA_CIES026); values copied unchanged\n"
        "# zero outside 380-780 nm (S 026 defines them there only) and where the table has\n"
        "#   no value (the cone functions below 390 nm), as luxpy sums them\n"
        "# licence: published by the CIE; factual data\n",
        cols,
    )


def write_ces() -> None:
    """The 99 CIE 2017 / TM-30 colour evaluation samples, 380-780 nm at 1 nm (their native
    range; CIE 224:2017 evaluates on 380-780 nm only)."""
    from colour.quality.cfi2017 import load_TCS_CIE2017

    tcs = load_TCS_CIE2017(SpectralShape(380, 780, 1))
    assert tcs.values.shape == (401, 99), tcs.values.shape
    path = os.path.join(DATA, "ces-cie2017.csv")
    names = [f"CES{i + 1:02d}" for i in range(99)]
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(
            "# CIE 224:2017 / ANSI/IES TM-30 colour evaluation samples CES01-CES99 (spectral\n"
            "#   reflectance factors)\n"
            f"# source: colour-science {VERSION}, colour.quality.cfi2017.load_TCS_CIE2017("
            "SpectralShape(380, 780, 1))\n"
            "#   (colour/quality/datasets/tcs_cfi2017_1_nm.csv.gz, the CIE 224:2017 1 nm table;\n"
            "#   colour-science labels them 'TCS0'..'TCS98', here CES01..CES99 in the same order)\n"
            "# licence: published by the CIE (CIE 224:2017) and IES (TM-30); redistributed by\n"
            "#   colour-science (BSD-3-Clause); the tabulated values are factual data.\n"
            f"# regenerate: {REGEN}\n"
            "# sampling: 380-780 nm every 1 nm (401 rows; the samples are defined there only)\n"
        )
        f.write("nm," + ",".join(names) + "\n")
        for i, w in enumerate(tcs.wavelengths):
            f.write(str(int(w)) + "," + ",".join(fmt(v) for v in tcs.values[i]) + "\n")
    print(f"wrote {path}")


def _luxpy_version(pkg: str) -> str:
    import importlib.metadata

    return importlib.metadata.version("luxpy")


CORNELL = """\
400 0.343 0.092 0.040
404 0.445 0.096 0.046
408 0.551 0.098 0.048
412 0.624 0.097 0.053
416 0.665 0.098 0.049
420 0.687 0.095 0.050
424 0.708 0.095 0.053
428 0.723 0.097 0.055
432 0.715 0.095 0.057
436 0.710 0.094 0.056
440 0.745 0.097 0.059
444 0.758 0.098 0.057
448 0.739 0.096 0.061
452 0.767 0.101 0.061
456 0.777 0.103 0.060
460 0.765 0.104 0.062
464 0.751 0.107 0.062
468 0.745 0.109 0.062
472 0.748 0.112 0.061
476 0.729 0.115 0.062
480 0.745 0.125 0.060
484 0.757 0.140 0.059
488 0.753 0.160 0.057
492 0.750 0.187 0.058
496 0.746 0.229 0.058
500 0.747 0.285 0.058
504 0.735 0.343 0.056
508 0.732 0.390 0.055
512 0.739 0.435 0.056
516 0.734 0.464 0.059
520 0.725 0.472 0.057
524 0.721 0.476 0.055
528 0.733 0.481 0.059
532 0.725 0.462 0.059
536 0.732 0.447 0.058
540 0.743 0.441 0.059
544 0.744 0.426 0.061
548 0.748 0.406 0.061
552 0.728 0.373 0.063
556 0.716 0.347 0.063
560 0.733 0.337 0.067
564 0.726 0.314 0.068
568 0.713 0.285 0.072
572 0.740 0.277 0.080
576 0.754 0.266 0.090
580 0.764 0.250 0.099
584 0.752 0.230 0.124
588 0.736 0.207 0.154
592 0.734 0.186 0.192
596 0.741 0.171 0.255
600 0.740 0.160 0.287
604 0.732 0.148 0.349
608 0.745 0.141 0.402
612 0.755 0.136 0.443
616 0.751 0.130 0.487
620 0.744 0.126 0.513
624 0.731 0.123 0.558
628 0.733 0.121 0.584
632 0.744 0.122 0.620
636 0.731 0.119 0.606
640 0.712 0.114 0.609
644 0.708 0.115 0.651
648 0.729 0.117 0.612
652 0.730 0.117 0.610
656 0.727 0.118 0.650
660 0.707 0.120 0.638
664 0.703 0.122 0.627
668 0.729 0.128 0.620
672 0.750 0.132 0.630
676 0.760 0.139 0.628
680 0.751 0.144 0.642
684 0.739 0.146 0.639
688 0.724 0.150 0.657
692 0.730 0.152 0.639
696 0.740 0.157 0.635
700 0.737 0.159 0.642
"""
CORNELL_LIGHT = {400: "0.0", 500: "8.0", 600: "15.6", 700: "18.4"}


def write_cornell() -> None:
    path = os.path.join(DATA, "cornell-box.csv")
    rows = [line.split() for line in CORNELL.strip().splitlines()]
    assert len(rows) == 76 and rows[0][0] == "400" and rows[-1][0] == "700"
    with open(path, "w", encoding="utf-8", newline="\n") as f:
        f.write(
            "# Cornell box measured spectra\n"
            "# source: \"Cornell Box Data\", Cornell University Program of Computer Graphics,\n"
            "#   https://www.graphics.cornell.edu/online/box/data.html (measured data, shipped with\n"
            "#   attribution), transcribed via /work/shared/reference/cornell-box.md\n"
            "# white, green, red: Lambertian reflectance, 400-700 nm every 4 nm\n"
            "# light: relative emission (no absolute unit), given at 400/500/600/700 nm only;\n"
            "#   empty cells mean 'not tabulated'\n"
            "# interpolation: linear between tabulated samples, zero outside 400-700 nm\n"
            f"# regenerate: {REGEN} (values are constants in that script)\n"
            "nm,white,green,red,light\n"
        )
        for r in rows:
            light = CORNELL_LIGHT.get(int(r[0]), "")
            f.write(f"{r[0]},{r[1]},{r[2]},{r[3]},{light}\n")
    print(f"wrote {path}")


if __name__ == "__main__":
    sys.exit(main())
