"""Sky luminance from Radiance (gensky, gendaylit) for tests/daylight_peers.rs.

Reads a JSON list of cases on stdin; each case is
  {"tool": "gensky" | "gendaylit", "args": [...], "dirs": [[x, y, z], ...]}
with directions in Radiance's frame (x east, y north, z up). Writes a JSON list, one object
per case: {"header": the generator's comment lines, "values": the sky's radiance in each
direction (rtrace -ab 0 of a glow source sky with the generator's skyfunc)}.
"""

import json
import os
import subprocess
import sys
import tempfile

import pyradiance

PKG = os.path.dirname(pyradiance.__file__)
ENV = dict(os.environ, PATH=os.path.join(PKG, "bin") + os.pathsep + os.environ["PATH"],
           RAYPATH="." + os.pathsep + os.path.join(PKG, "lib"))


def run(cmd, stdin=None):
    r = subprocess.run(cmd, input=stdin, capture_output=True, text=True, env=ENV)
    if r.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed: {r.stderr}")
    return r.stdout


def main():
    cases = json.load(sys.stdin)
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, case in enumerate(cases):
            sky = run([case["tool"], *case["args"]])
            rad = os.path.join(tmp, f"sky{i}.rad")
            with open(rad, "w") as f:
                f.write(sky)
                f.write("\nskyfunc glow skyglow\n0\n0\n4 1 1 1 0\n"
                        "skyglow source skydome\n0\n0\n4 0 0 1 360\n")
            octree = os.path.join(tmp, f"sky{i}.oct")
            with open(octree, "wb") as f:
                f.write(subprocess.run(["oconv", rad], capture_output=True, env=ENV,
                                       check=True).stdout)
            rays = "".join(f"0 0 0 {x} {y} {z}\n" for x, y, z in case["dirs"])
            vals = run(["rtrace", "-h", "-ab", "0", "-ov", "-w", octree], rays)
            values = [float(line.split()[1]) for line in vals.splitlines() if line.strip()]
            header = [line for line in sky.splitlines() if line.startswith("#")]
            out.append({"header": header, "values": values, "sky": sky})
    json.dump(out, sys.stdout)


main()
