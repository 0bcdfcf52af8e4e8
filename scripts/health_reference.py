#!/usr/bin/env python3
"""Reference values for candela's light-and-health colour quantities (tests/colour_health.rs).

Reads {"task": ..., ...} on stdin and writes JSON on stdout:

  task "alpha_opic": {"cases": [{"id", "values": [471 floats, 360-830 nm]}]}
      -> luxpy's CIE S 026 alpha-opic irradiance, E_v, ELR, DER and EDI per case (K_m = 683
         lm/W, reference D65 = colour-science's D65 aligned to 1 nm, as candela's), plus
         "d65_elr_luxpy": luxpy's D65 ELRs with its defaults (CIE 1 nm D65, K_m = 683.002).
  task "mesopic": {"cases": [{"lp": cd/m2, "ls": cd/m2}]}
      -> luxpy get_cie_mesopic_adaptation (CIE 191:2010): L_mes, m per case.
  task "tm30": {"cases": [{"id", "values": [...]}]}
      -> colour-science colour_fidelity_index_CIE2017 and colour_fidelity_index_ANSIIESTM3018
         (R_f, R_g, CCT, per-bin R_cs, R_hs, R_fs, per-sample R_fi).
  task "cqs": {"cases": [{"id", "values": [...]}]}
      -> colour-science colour_quality_scale(method="NIST CQS 9.0"): Q_a, Q_f, Q_g, and per
         sample VS1-VS15 Q_a,i, Delta C, Delta E, Delta E'.
  task "xyz_methods": {"cases": [{"id", "values": [...]}]}
      -> colour-science sd_to_XYZ(method="Integration"), its default (ASTM E308),
         luminous_efficacy (trapezoid) of each spectrum.

Run: target/venv/bin/python scripts/health_reference.py < in.json > out.json
"""

from __future__ import annotations

import json
import sys
import warnings

warnings.filterwarnings("ignore")

import numpy as np  # noqa: E402

WL = np.arange(360, 831, 1, dtype=float)


def tolist(a):
    return [float(v) for v in np.ravel(a)]


def d65_colour_science():
    import colour

    return colour.SDS_ILLUMINANTS["D65"].copy().align(colour.SpectralShape(360, 830, 1)).values


def alpha_opic(doc):
    import luxpy as lx
    from luxpy.toolboxes import photbiochem as pb

    ref = np.vstack([WL, d65_colour_science()])
    # luxpy orders the photoreceptors l, m, s, rod, ipRGC; candela s, m, l, rod, ipRGC.
    order = [2, 1, 0, 3, 4]

    def lms(a):
        return [float(v) for v in np.ravel(a)[order]]

    out = []
    for case in doc["cases"]:
        sid = np.vstack([WL, np.array(case["values"], dtype=float)])
        ee, ev = pb.spd_to_aopicE(sid.copy(), K=683.0, out="Eeas,E")
        elr = pb.spd_to_aopicELR(sid.copy(), K=683.0)
        der = pb.spd_to_aopicDER(sid.copy(), K=683.0, ref=ref.copy())
        edi = pb.spd_to_aopicEDI(sid.copy(), K=683.0, ref=ref.copy())
        out.append(
            {
                "irradiance": lms(ee),
                "ev": float(np.ravel(ev)[0]),
                "elr": lms(elr),
                "der": lms(der),
                "edi": lms(edi),
            }
        )
    return {
        "luxpy": lx.__version__,
        "results": out,
        "d65_elr_luxpy": lms(pb.spd_to_aopicELR(lx._CIE_D65)),
    }


def mesopic(doc):
    import luxpy as lx

    out = []
    for case in doc["cases"]:
        # luxpy's iteration uses its SP argument where CIE 191 has the scotopic luminance
        # (L_s = SP * L_p), so L_s is passed as SP; that reproduces CIE 191's equations.
        # Below the mesopic range luxpy's unlimited m can make L_mes negative, and numpy then
        # raises in log10: reported as null.
        try:
            lmes, m = lx.get_cie_mesopic_adaptation(case["lp"], SP=case["ls"])
            out.append({"lmes": float(lmes[0]), "m": float(m[0])})
        except FloatingPointError:
            out.append({"lmes": None, "m": None})
    return {"luxpy": lx.__version__, "results": out}


def tm30(doc):
    import colour
    from colour import SpectralDistribution
    from colour.quality import (
        colour_fidelity_index_ANSIIESTM3018,
        colour_fidelity_index_CIE2017,
    )

    out = []
    for case in doc["cases"]:
        sd = SpectralDistribution(np.array(case["values"], dtype=float), WL)
        cie = colour_fidelity_index_CIE2017(sd, additional_data=True)
        tm = colour_fidelity_index_ANSIIESTM3018(sd, additional_data=True)
        out.append(
            {
                "rf_cie2017": float(cie.R_f),
                "rfi_cie2017": tolist(cie.R_s),
                "cct": float(cie.CCT),
                "duv": float(cie.D_uv),
                "rf": float(tm.R_f),
                "rg": float(tm.R_g),
                "rcs": tolist(tm.R_cs),
                "rhs": tolist(tm.R_hs),
                "rfs": tolist(tm.R_fs),
            }
        )
    return {"colour_science": colour.__version__, "results": out}


def cqs(doc):
    import colour
    from colour import SpectralDistribution
    from colour.quality import colour_quality_scale

    out = []
    for case in doc["cases"]:
        sd = SpectralDistribution(np.array(case["values"], dtype=float), WL)
        q = colour_quality_scale(sd, additional_data=True, method="NIST CQS 9.0")
        s = [q.Q_as[i] for i in sorted(q.Q_as)]
        out.append(
            {
                "qa": float(q.Q_a),
                "qf": float(q.Q_f),
                "qg": float(q.Q_g),
                "qp": q.Q_p,
                "qai": [float(v.Q_a) for v in s],
                "dc": [float(v.D_C_ab) for v in s],
                "de": [float(v.D_E_ab) for v in s],
                "dep": [float(v.D_Ep_ab) for v in s],
            }
        )
    return {"colour_science": colour.__version__, "results": out}


def xyz_methods(doc):
    import colour

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    out = []
    for case in doc["cases"]:
        sd = colour.SpectralDistribution(np.array(case["values"], dtype=float), WL)
        out.append(
            {
                "xyz_integration": tolist(colour.sd_to_XYZ(sd, cmfs, method="Integration")),
                "xyz_astm_e308": tolist(colour.sd_to_XYZ(sd, cmfs)),
                "efficacy_trapezoid": float(colour.luminous_efficacy(sd)),
            }
        )
    return {"colour_science": colour.__version__, "results": out}


def main() -> int:
    doc = json.load(sys.stdin)
    task = {
        "alpha_opic": alpha_opic,
        "mesopic": mesopic,
        "tm30": tm30,
        "cqs": cqs,
        "xyz_methods": xyz_methods,
    }
    json.dump(task[doc["task"]](doc), sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
