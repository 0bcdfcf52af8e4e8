"""Sky vectors from Radiance's gendaymtx for tests/daylight_peers.rs.

Reads JSON on stdin: {"site": [latitude °N, longitude °W, meridian °W], "mf": MF,
"steps": [[month, day, hour, direct-normal W/m², diffuse-horizontal W/m²], ...]}. Runs
`gendaymtx -s -c 1 1 1 -m MF` (sky patches without the sun, a grey sky so that each channel is
the patch's radiance at 179 lm/W) and `gendaymtx -D -` (the suns' directions). Writes JSON:
{"suns": [[x, y, z] per step], "luminance": [[cd/m² per patch] per step]}.
"""

import array
import json
import os
import subprocess
import sys

import pyradiance

PKG = os.path.dirname(pyradiance.__file__)
ENV = dict(os.environ, PATH=os.path.join(PKG, "bin") + os.pathsep + os.environ["PATH"],
           RAYPATH="." + os.pathsep + os.path.join(PKG, "lib"))


def run(cmd, stdin):
    r = subprocess.run(cmd, input=stdin, capture_output=True, text=True, env=ENV)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr}")
    return r.stdout


def main():
    case = json.load(sys.stdin)
    lat, lon, mer = case["site"]
    wea = (f"place test\nlatitude {lat}\nlongitude {lon}\ntime_zone {mer}\n"
           f"site_elevation 0\nweather_data_file_units 1\n")
    for mo, da, hr, dn, dh in case["steps"]:
        wea += f"{mo} {da} {hr} {dn} {dh}\n"
    suns = []
    for line in run(["gendaymtx", "-D", "-"], wea).splitlines():
        f = line.split()
        if len(f) == 5 and f[0] == "4":
            suns.append([float(v) for v in f[1:4]])
    # Binary floats (the text form keeps three digits): patches are the outer order, each
    # with r, g, b per time step.
    r = subprocess.run(["gendaymtx", "-h", "-of", "-s", "-c", "1", "1", "1", "-m",
                        str(case["mf"])], input=wea.encode(), capture_output=True, env=ENV)
    if r.returncode != 0:
        sys.exit(f"gendaymtx failed: {r.stderr.decode()}")
    nsteps = len(case["steps"])
    vals = array.array("f", r.stdout)
    if sys.byteorder != "little":
        vals.byteswap()
    npatch = len(vals) // (3 * nsteps)
    if npatch * 3 * nsteps != len(vals):
        sys.exit(f"gendaymtx wrote {len(vals)} floats, not a multiple of {3 * nsteps}")
    lum = [[0.0] * npatch for _ in range(nsteps)]
    for p in range(npatch):
        for t in range(nsteps):
            r_, g, b = vals[3 * (p * nsteps + t): 3 * (p * nsteps + t) + 3]
            lum[t][p] = 179.0 * (0.265 * r_ + 0.670 * g + 0.065 * b)
    json.dump({"suns": suns, "luminance": lum}, sys.stdout)


main()
