#!/usr/bin/env python3
"""colour-science reference values for candela's validation test (tests/colour_science.rs).

Reads a JSON document {"cases": [...]} on stdin, writes {"colour_science": "<version>",
"results": [...]} on stdout (one result object per case, same order).  Spectra named in a
case are taken from colour-science's own datasets (not from candela's data/ files) and
aligned to 360-830 nm at 1 nm with ``sd.copy().align(SpectralShape(360, 830, 1))``, so the
comparison also checks candela's data tables.

Case schema (all keys written by the Rust test):
  id:        free text
  kind:      "emissive" | "object" | "daylight"
  observer:  "1931" | "1964"
  spectrum:  {"named": NAME} | {"blackbody": T_K} | {"values": [471 floats, 360..830 nm]}
             (daylight: {"cct": T_K})
  illuminant (object only): spectrum spec of the illuminant
  next       (object only): spectrum spec of a second reflectance (CIEDE2000 partner)
  cct, cri, photometry (emissive only): booleans, compute those quantities
  rgb: [{"space": colour-science colourspace name, "cat": CAT name or null,
         "illuminant_xy": [x, y] or null (emissive; object cases use the illuminant's white)}]

Run: target/venv/bin/python scripts/colour_reference.py < cases.json > results.json
"""

from __future__ import annotations

import json
import sys
import warnings

warnings.filterwarnings("ignore")

import colour  # noqa: E402
import numpy as np  # noqa: E402
from colour import SpectralDistribution, SpectralShape  # noqa: E402
from colour.quality.datasets import SDS_TCS  # noqa: E402

SHAPE = SpectralShape(360, 830, 1)
WL = np.arange(360, 831, 1, dtype=float)
CMFS = {
    "1931": colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"],
    "1964": colour.MSDS_CMFS["CIE 1964 10 Degree Standard Observer"],
}
LEF_SCOTOPIC = colour.colorimetry.SDS_LEFS_SCOTOPIC["CIE 1951 Scotopic Standard Observer"]
CHECKER = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]
_CACHE: dict = {}


def spectrum(spec) -> SpectralDistribution:
    if "named" in spec:
        name = spec["named"]
        if name in _CACHE:
            return _CACHE[name]
        if name.lower().startswith("colorchecker:"):
            sd = list(CHECKER.values())[int(name.split(":")[1]) - 1]
        elif name.upper().startswith("TCS"):
            sd = SDS_TCS["CIE 1995"][name.upper()]
        else:
            sd = colour.SDS_ILLUMINANTS[name]
        sd = sd.copy().align(SHAPE)
        _CACHE[name] = sd
        return sd
    if "blackbody" in spec:
        return colour.sd_blackbody(spec["blackbody"], SHAPE)
    if "values" in spec:
        return SpectralDistribution(np.array(spec["values"], dtype=float), WL)
    raise ValueError(f"bad spectrum spec {spec}")


def tolist(a):
    return [float(v) for v in np.ravel(a)]


def rgb_results(xyz1, specs, white_xy):
    out = []
    for s in specs:
        ill = s.get("illuminant_xy") or white_xy
        kw = dict(
            illuminant=None if ill is None else np.array(ill),
            chromatic_adaptation_transform=s.get("cat"),
        )
        lin = colour.XYZ_to_RGB(xyz1, s["space"], apply_cctf_encoding=False, **kw)
        enc = colour.XYZ_to_RGB(xyz1, s["space"], apply_cctf_encoding=True, **kw)
        out.append({"linear": tolist(lin), "encoded": tolist(enc)})
    return out


def emissive(case):
    cmfs = CMFS[case["observer"]]
    if case["kind"] == "daylight":
        xy_d = colour.temperature.CCT_to_xy_CIE_D(case["spectrum"]["cct"])
        sd = colour.colorimetry.sd_CIE_illuminant_D_series(xy_d).align(SHAPE)
    else:
        sd = spectrum(case["spectrum"])
    r = {}
    if case["kind"] == "daylight":
        r["spd"] = tolist(sd.values)
    xyz = colour.sd_to_XYZ(sd, cmfs, method="Integration")
    r["xyz"] = tolist(xyz)
    r["xyz_astm"] = tolist(colour.sd_to_XYZ(sd, cmfs))
    # With k given, sd_to_XYZ_integration returns k * sum(S xbar) * d_w (no percentage).
    r["xyz_abs"] = tolist(colour.sd_to_XYZ(sd, cmfs, k=683, method="Integration"))
    r["xy"] = tolist(colour.XYZ_to_xy(xyz))
    uv = colour.UCS_to_uv(colour.XYZ_to_UCS(xyz))
    r["uv"] = tolist(uv)
    r["upvp"] = tolist(colour.xy_to_Luv_uv(colour.XYZ_to_xy(xyz)))
    if case.get("cct"):
        r["cct_ohno"] = tolist(colour.temperature.uv_to_CCT_Ohno2013(uv))
        r["cct_robertson"] = tolist(colour.temperature.uv_to_CCT_Robertson1968(uv))
    if case.get("photometry"):
        r["flux_trapz"] = float(colour.luminous_flux(sd))
        r["efficiency_trapz"] = float(colour.luminous_efficiency(sd))
        r["scotopic_efficiency_trapz"] = float(colour.luminous_efficiency(sd, LEF_SCOTOPIC))
    if case.get("cri"):
        spec = colour.colour_rendering_index(sd, additional_data=True)
        r["ra"] = float(spec.Q_a)
        r["ri"] = [float(spec.Q_as[i].Q_a) for i in range(1, 15)]
    xyz1 = xyz / xyz[1] if xyz[1] != 0 else xyz
    r["rgb"] = rgb_results(xyz1, case.get("rgb", []), None)
    return r


def obj(case):
    cmfs = CMFS[case["observer"]]
    refl = spectrum(case["spectrum"])
    ill = spectrum(case["illuminant"])
    r = {}
    xyz = colour.sd_to_XYZ(refl, cmfs, ill, method="Integration")
    r["xyz"] = tolist(xyz)
    r["xyz_astm"] = tolist(colour.sd_to_XYZ(refl, cmfs, ill))
    r["xy"] = tolist(colour.XYZ_to_xy(xyz))
    r["upvp"] = tolist(colour.xy_to_Luv_uv(colour.XYZ_to_xy(xyz)))
    white_xy = colour.XYZ_to_xy(colour.sd_to_XYZ(ill, cmfs, method="Integration"))
    r["white_xy"] = tolist(white_xy)
    lab = colour.XYZ_to_Lab(xyz / 100, white_xy)
    r["lab"] = tolist(lab)
    if "next" in case:
        xyz2 = colour.sd_to_XYZ(spectrum(case["next"]), cmfs, ill, method="Integration")
        lab2 = colour.XYZ_to_Lab(xyz2 / 100, white_xy)
        r["de2000"] = float(colour.delta_E(lab, lab2, method="CIE 2000"))
    r["rgb"] = rgb_results(xyz / 100, case.get("rgb", []), tolist(white_xy))
    return r


def main() -> int:
    doc = json.load(sys.stdin)
    results = []
    for case in doc["cases"]:
        try:
            results.append(obj(case) if case["kind"] == "object" else emissive(case))
        except Exception as e:  # report, never silently drop a case
            results.append({"error": f"{type(e).__name__}: {e}"})
    json.dump({"colour_science": colour.__version__, "results": results}, sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
