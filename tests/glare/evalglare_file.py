"""evalglare (Radiance 6, from PyPI pyradiance) on one picture, for tests/glare_cli.rs.

Usage: evalglare_file.py PICTURE.hdr [evalglare options]. Prints JSON: {"dgp", "av_lum",
"ev", "lb", "ev_dir", "dgi", "ugr", "vcp", "cgi", "sources": n}.
"""

import json
import os
import subprocess
import sys

import pyradiance

PKG = os.path.dirname(pyradiance.__file__)
ENV = dict(os.environ, PATH=os.path.join(PKG, "bin") + os.pathsep + os.environ["PATH"],
           RAYPATH="." + os.pathsep + os.path.join(PKG, "lib"))

r = subprocess.run(["evalglare", "-d", *sys.argv[2:], sys.argv[1]], capture_output=True,
                   text=True, env=ENV)
if r.returncode != 0:
    sys.exit(f"evalglare failed: {r.stderr}")
lines = r.stdout.strip().splitlines()
last = lines[-1].split(":")[1].split()
keys = ["dgp", "av_lum", "ev", "lb", "ev_dir", "dgi", "ugr", "vcp", "cgi"]
out = {k: float(v) for k, v in zip(keys, last)}
out["sources"] = sum(1 for ln in lines[:-1]
                     if len(ln.split()) > 6 and ln.split()[1] != "No" and int(ln.split()[0]) > 0)
json.dump(out, sys.stdout)
