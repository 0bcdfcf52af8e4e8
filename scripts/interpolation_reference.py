#!/usr/bin/env python3
"""Reference values for candela's spectral interpolation (tests/colour_interpolation.rs).

Reads {"task": ..., "cases": [...]} on stdin and writes JSON on stdout:

  task "interpolate": cases [{"id", "wavelengths", "values", "at"}]
      -> {"interpolator": the class colour-science 0.4.7's SpectralDistribution picks
         (SpragueInterpolator for uniform wavelengths, else CubicSplineInterpolator),
         "values": that interpolator at "at", and "interpolated": the values of
         sd.interpolate(SpectralShape(first, last, 1)) at its wavelengths when both ends are
         whole nanometres (else null)}.
  task "tm30_coarse": cases [{"id", "wavelengths", "values"}] with an interval above 5 nm
      -> colour_fidelity_index_CIE2017 refuses the data as given ("refused": the message);
         the spectrum interpolated to 1 nm by sd.interpolate (CIE 167) gives R_f (CIE 2017 and
         TM-30), R_g and the CCT.

Run: target/venv/bin/python scripts/interpolation_reference.py < in.json > out.json
"""

from __future__ import annotations

import json
import sys
import warnings

warnings.filterwarnings("ignore")

import numpy as np  # noqa: E402


def interpolate(doc):
    from colour import SpectralDistribution, SpectralShape

    out = []
    for case in doc["cases"]:
        w = np.array(case["wavelengths"], dtype=float)
        v = np.array(case["values"], dtype=float)
        sd = SpectralDistribution(v, w)
        f = sd.interpolator(sd.wavelengths, sd.values)
        at = np.array(case["at"], dtype=float)
        res = {
            "interpolator": sd.interpolator.__name__,
            "values": [float(x) for x in np.atleast_1d(f(at))],
            "interpolated": None,
        }
        if w[0] == np.round(w[0]) and w[-1] == np.round(w[-1]):
            i = sd.copy().interpolate(SpectralShape(w[0], w[-1], 1))
            res["interpolated"] = {
                "wavelengths": [float(x) for x in i.wavelengths],
                "values": [float(x) for x in i.values],
            }
        out.append(res)
    return out


def tm30_coarse(doc):
    from colour import SpectralDistribution, SpectralShape
    from colour.quality import (
        colour_fidelity_index_ANSIIESTM3018,
        colour_fidelity_index_CIE2017,
    )

    out = []
    for case in doc["cases"]:
        w = np.array(case["wavelengths"], dtype=float)
        sd = SpectralDistribution(np.array(case["values"], dtype=float), w)
        try:
            colour_fidelity_index_CIE2017(sd)
            refused = None
        except ValueError as e:
            refused = str(e)
        fine = sd.copy().interpolate(SpectralShape(w[0], w[-1], 1))
        cie = colour_fidelity_index_CIE2017(fine, additional_data=True)
        tm = colour_fidelity_index_ANSIIESTM3018(fine, additional_data=True)
        out.append(
            {
                "refused": refused,
                "rf_cie2017": float(cie.R_f),
                "rf": float(tm.R_f),
                "rg": float(tm.R_g),
                "cct": float(tm.CCT),
                "duv": float(tm.D_uv),
            }
        )
    return out


def main():
    import colour

    doc = json.load(sys.stdin)
    task = {"interpolate": interpolate, "tm30_coarse": tm30_coarse}[doc["task"]]
    json.dump({"colour_science": colour.__version__, "results": task(doc)}, sys.stdout)


if __name__ == "__main__":
    main()
