#!/usr/bin/env python3
"""Generate the Mitsuba 3 twin of scenes/bench-cornell.ron from candela's own files.

Writes, next to this script:
  cornell.xml       the scene (camera, film, integrator, materials, shapes, emitter)
  meshes/*.obj      the RON's triangle lists and the light quad, vertex positions copied verbatim
  spectra/*.spd     reflectances, Au n and k, and the light's absolute spectral radiance
                    (W m^-2 sr^-1 nm^-1), sampled at 1 nm over 360-830 nm

Every spectrum is baked exactly as candela bakes it (scene/build.rs: DenseSpectrum::from_fn at
1 nm, linear interpolation of the tabulated data, zero outside the tabulated range), so that
Mitsuba's piecewise-linear 'irregular' spectrum evaluates to the same function of wavelength.
The light's scale factor is candela's photometric_scale: L = amount / (683 * sum V(lambda) S(lambda)
* 1 nm) with V from data/luminous-efficiency.csv.

Standard library only (runs with any python3). Usage:
  python3 bench/mitsuba/gen_scene.py           # (re)write the files
  python3 bench/mitsuba/gen_scene.py --check   # exit 1 if the committed files are out of date
"""
import argparse
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", ".."))
RON = os.path.join(ROOT, "scenes", "bench-cornell.ron")
# The diffuse interior (no glass, no metal), written by hand in candela's format.
INTERIOR_RON = os.path.join(HERE, "interior.ron")
K_M = 683.0  # lm/W, src/photometry.rs
NM = list(range(360, 831))  # candela's dense grid (src/spectrum/mod.rs)

# Candela max_depth counts scattering events, Mitsuba's counts path segments (camera segment
# included): candela's longest path has max_depth + 1 segments (src/integrator/path.rs).
MITSUBA_DEPTH_OFFSET = 1


# --------------------------------------------------------------------------- RON parsing
def tokenize(text):
    """Split RON text into tokens (comments dropped)."""
    text = re.sub(r"//[^\n]*", "", text)
    pattern = r'\s*(?:("(?:[^"\\]|\\.)*")|([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)|([A-Za-z_][A-Za-z0-9_]*)|([()\[\]{}:,]))'
    pos, out = 0, []
    while pos < len(text):
        m = re.compile(pattern).match(text, pos)
        if not m or m.end() == pos:
            if text[pos:].strip() == "":
                break
            raise ValueError(f"RON: cannot parse near {text[pos:pos + 40]!r}")
        s, num, ident, punct = m.groups()
        if s is not None:
            out.append(("str", s[1:-1]))
        elif num is not None:
            out.append(("num", float(num)))
        elif ident is not None:
            out.append(("id", ident))
        elif punct is not None:
            out.append(("p", punct))
        pos = m.end()
    return out


class RonParser:
    """Tiny recursive-descent RON reader: structs/maps -> dict, tuples/lists -> list,
    `Variant(...)` -> dict with key '$type' (struct fields, or positional args in '$args')."""

    def __init__(self, tokens):
        self.t, self.i = tokens, 0

    def peek(self, k=0):
        return self.t[self.i + k] if self.i + k < len(self.t) else (None, None)

    def take(self, kind=None, value=None):
        tok = self.peek()
        if (kind and tok[0] != kind) or (value is not None and tok[1] != value):
            raise ValueError(f"RON: expected {value or kind}, found {tok}")
        self.i += 1
        return tok

    def value(self):
        kind, v = self.peek()
        if kind in ("num", "str"):
            self.i += 1
            return v
        if kind == "id":
            self.i += 1
            if v in ("true", "false"):
                return v == "true"
            if self.peek() == ("p", "("):
                body = self.paren()
                return dict(body, **{"$type": v}) if isinstance(body, dict) else {"$type": v, "$args": body}
            return {"$type": v}
        if (kind, v) == ("p", "("):
            return self.paren()
        if (kind, v) == ("p", "["):
            return self.seq("[", "]")
        if (kind, v) == ("p", "{"):
            return self.map()
        raise ValueError(f"RON: unexpected {self.peek()}")

    def paren(self):
        """`( ... )`: a struct body if it starts with `ident:`, else a tuple."""
        if self.peek(1)[0] == "id" and self.peek(2) == ("p", ":"):
            self.take("p", "(")
            out = {}
            while self.peek() != ("p", ")"):
                key = self.take("id")[1]
                self.take("p", ":")
                out[key] = self.value()
                if self.peek() == ("p", ","):
                    self.i += 1
            self.take("p", ")")
            return out
        return self.seq("(", ")")

    def seq(self, open_, close):
        self.take("p", open_)
        out = []
        while self.peek() != ("p", close):
            out.append(self.value())
            if self.peek() == ("p", ","):
                self.i += 1
        self.take("p", close)
        return out

    def map(self):
        self.take("p", "{")
        out = {}
        while self.peek() != ("p", "}"):
            key = self.value()
            self.take("p", ":")
            out[key] = self.value()
            if self.peek() == ("p", ","):
                self.i += 1
        self.take("p", "}")
        return out


def load_ron(path):
    """Parse a candela scene file into nested dicts/lists."""
    with open(path, encoding="utf-8") as f:
        return RonParser(tokenize(f.read())).value()


# --------------------------------------------------------------------------- spectral data
def read_csv_table(path):
    """Read one of candela's data CSVs: returns (column names, rows as lists of float|None)."""
    names, rows = None, []
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            cells = line.split(",")
            if names is None:
                names = cells
                continue
            rows.append([float(c) if c.strip() else None for c in cells])
    return names, rows


def column(path, name):
    """(wavelengths, values) of one column, skipping empty cells (candela: column_sd)."""
    names, rows = read_csv_table(path)
    j = names.index(name)
    pts = [(r[0], r[j]) for r in rows if j < len(r) and r[j] is not None]
    return [p[0] for p in pts], [p[1] for p in pts]


def sd_value(wl, vals, nm):
    """candela's SpectralDistribution::value: linear between samples, 0 outside the range."""
    if not (wl[0] <= nm <= wl[-1]):
        return 0.0
    for i in range(len(wl) - 1):
        if wl[i] <= nm <= wl[i + 1]:
            if nm == wl[i]:
                return vals[i]
            t = (nm - wl[i]) / (wl[i + 1] - wl[i])
            return vals[i] + t * (vals[i + 1] - vals[i])
    return vals[-1]


def dense(wl, vals):
    """Bake at candela's 1 nm grid (DenseSpectrum::from_fn)."""
    return [sd_value(wl, vals, nm) for nm in NM]


def named_spectrum(name):
    """The 1 nm table of a candela named spectrum (only E and the Cornell ones are needed here)."""
    if name.upper() == "E":  # CIE illuminant E: equal energy
        return [1.0 for _ in NM]
    if not name.lower().startswith("cornell-"):
        raise ValueError(f"spectrum {name!r}: only the cornell-* spectra are supported")
    return dense(*column(os.path.join(ROOT, "data", "cornell-box.csv"), name.lower()[len("cornell-"):]))


def metal_ior(metal):
    """(n, k) 1 nm tables from data/ior/<metal>.csv."""
    path = os.path.join(ROOT, "data", "ior", f"{metal}.csv")
    return dense(*column(path, "n")), dense(*column(path, "k"))


def photopic_v():
    return dense(*column(os.path.join(ROOT, "data", "luminous-efficiency.csv"), "photopic"))


def luminance_scale(spectrum, amount):
    """candela's photometric_scale: amount / (K_m * sum S V * 1 nm)."""
    return amount / (K_M * sum(s * v for s, v in zip(spectrum, photopic_v())))


def spd_text(values, header):
    """Mitsuba .spd: 'wavelength value' per line, '#' comments."""
    lines = [f"# {h}" for h in header]
    lines += [f"{nm} {v:.9g}" for nm, v in zip(NM, values)]
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- geometry
def obj_text(positions, triangles, header):
    """Wavefront OBJ with positions only (1-based faces); normals come from the winding."""
    lines = [f"# {h}" for h in header]
    lines += ["v %.9g %.9g %.9g" % tuple(p) for p in positions]
    lines += ["f %d %d %d" % tuple(i + 1 for i in t) for t in triangles]
    return "\n".join(lines) + "\n"


def quad_mesh(origin, eu, ev):
    """candela's Quad as two triangles: normal eu x ev, the side it emits on."""
    o = origin
    p = [o, [o[k] + eu[k] for k in range(3)], [o[k] + eu[k] + ev[k] for k in range(3)],
         [o[k] + ev[k] for k in range(3)]]
    return p, [[0, 1, 2], [0, 2, 3]]


def slug(name):
    return re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")


# --------------------------------------------------------------------------- XML
def fmt3(v):
    return ", ".join(repr(float(x)) for x in v)


def bsdf_xml(mid, mat, files):
    """Mitsuba BSDF for one candela material; opaque ones wrapped in `twosided` because
    candela's Diffuse and Conductor reflect on both sides (bxdf/*.rs: same_hemisphere)."""
    t = mat["$type"]
    if t == "Diffuse":
        refl = mat["reflectance"]
        if refl["$type"] == "Constant":
            value = float(refl["$args"][0])
            return (f'    <bsdf type="twosided" id="{mid}">\n        <bsdf type="diffuse">\n'
                    f'            <spectrum name="reflectance" value="{value!r}"/>\n        </bsdf>\n    </bsdf>')
        assert refl["$type"] == "Named", refl
        name = refl["$args"][0]
        files[f"spectra/{name}.spd"] = spd_text(named_spectrum(name), [f"{name} reflectance, from data/cornell-box.csv (candela's 1 nm baking)"])
        inner = f'<bsdf type="diffuse">\n            <spectrum name="reflectance" filename="spectra/{name}.spd"/>\n        </bsdf>'
    elif t == "Conductor":
        metal = mat["metal"]
        alpha = float(mat.get("roughness", 0.0))
        assert "roughness_v" not in mat and mat.get("distribution", {"$type": "Ggx"})["$type"] == "Ggx"
        assert mat.get("masking", {"$type": "Smith"})["$type"] == "Smith"
        n, k = metal_ior(metal)
        src = f"data/ior/{metal}.csv (Johnson & Christy via candela)"
        files[f"spectra/{metal}-n.spd"] = spd_text(n, [f"{metal} refractive index n, {src}"])
        files[f"spectra/{metal}-k.spd"] = spd_text(k, [f"{metal} extinction coefficient k, {src}"])
        spectra = (f'<spectrum name="eta" filename="spectra/{metal}-n.spd"/>\n'
                   f'            <spectrum name="k" filename="spectra/{metal}-k.spd"/>')
        if alpha == 0.0:
            inner = f'<bsdf type="conductor">\n            {spectra}\n        </bsdf>'
        else:
            # Mitsuba's alpha is the GGX alpha, as candela's roughness (docs/scene-format.md).
            inner = (f'<bsdf type="roughconductor">\n            <string name="distribution" value="ggx"/>\n'
                     f'            <float name="alpha" value="{alpha!r}"/>\n            {spectra}\n        </bsdf>')
    elif t == "Dielectric":
        ior = mat["ior"]
        assert ior["$type"] == "Constant" and float(mat.get("roughness", 0.0)) == 0.0, mat
        eta = float(ior["$args"][0])
        # ext_ior must be given: Mitsuba's default exterior is air (1.000277), candela's is 1.
        return (f'    <bsdf type="dielectric" id="{mid}">\n'
                f'        <float name="int_ior" value="{eta!r}"/>\n'
                f'        <float name="ext_ior" value="1.0"/>\n    </bsdf>')
    else:
        raise ValueError(f"material {mid!r}: {t} not supported by this generator")
    return f'    <bsdf type="twosided" id="{mid}">\n        {inner}\n    </bsdf>'


def shape_xml(obj, files, src="scenes/bench-cornell.ron", prefix=""):
    """One <shape> per candela object (meshes become OBJ files, under meshes/PREFIX)."""
    name, shape = obj["name"], obj["shape"]
    body = f'        <ref id="{obj["material"]}"/>\n'
    emission = obj.get("emission")
    if emission:
        spec = emission["spectrum"]
        amount = emission["amount"]
        assert spec["$type"] == "Named" and amount["$type"] == "Luminance", emission
        assert not emission.get("two_sided", False)
        s = named_spectrum(spec["$args"][0])
        lum = float(amount["$args"][0])
        k = luminance_scale(s, lum)
        files[f"spectra/{prefix}light-radiance.spd"] = spd_text(
            [k * v for v in s],
            [f"{spec['$args'][0]} scaled to luminance {lum:g} cd/m2: absolute spectral radiance, W m^-2 sr^-1 nm^-1",
             f"scale k = {lum:g} / (683 * sum(S V) * 1 nm) = {k:.9g} (candela's photometric_scale)"])
        body += ('        <emitter type="area">\n'
                 f'            <spectrum name="radiance" filename="spectra/{prefix}light-radiance.spd"/>\n'
                 '        </emitter>\n')
    t = shape["$type"]
    if t == "Sphere":
        return (f'    <!-- {name} -->\n    <shape type="sphere">\n'
                f'        <point name="center" value="{fmt3(shape["center"])}"/>\n'
                f'        <float name="radius" value="{float(shape["radius"])!r}"/>\n{body}    </shape>')
    if t == "Triangles":
        assert "normals" not in shape and "uvs" not in shape
        pos, tris = shape["positions"], shape["indices"]
    elif t == "Quad":
        pos, tris = quad_mesh(shape["origin"], shape["edge_u"], shape["edge_v"])
    else:
        raise ValueError(f"object {name!r}: shape {t} not supported")
    fn = f"meshes/{prefix}{slug(name)}.obj"
    files[fn] = obj_text(pos, tris, [f'"{name}" from {src} ({t}), positions verbatim'])
    return (f'    <!-- {name} -->\n    <shape type="obj">\n        <string name="filename" value="{fn}"/>\n'
            f'        <boolean name="face_normals" value="true"/>\n{body}    </shape>')


def scene_xml(scene, files, src="scenes/bench-cornell.ron", prefix=""):
    cam, render = scene["camera"], scene["render"]
    assert render.get("filter", {"$type": "Box"})["$type"] == "Box"
    assert "aperture_radius" not in cam and "lens" not in cam
    width, height = cam["resolution"]
    # No max_depth in the scene: candela's default, unlimited (Mitsuba's -1).
    depth = render.get("max_depth")
    max_depth = -1 if depth is None else int(depth) + MITSUBA_DEPTH_OFFSET
    mats = "\n".join(bsdf_xml(mid, m, files) for mid, m in scene["materials"].items())
    shapes = "\n".join(shape_xml(o, files, src, prefix) for o in scene["objects"])
    return f"""<?xml version="1.0" encoding="utf-8"?>
<!-- GENERATED by bench/mitsuba/gen_scene.py from {src} and data/: do not edit.
     The Mitsuba 3 twin of candela's benchmark scene; see bench/README.md for every known
     difference. Parameters with defaults can be overridden from mi.load_file(..., spp=...). -->
<scene version="3.0.0">
    <default name="spp" value="{int(render['spp'])}"/>
    <default name="sampler" value="independent"/>
    <default name="rr_depth" value="5"/>
    <default name="max_depth" value="{max_depth}"/>

    <!-- candela max_depth {"unlimited" if depth is None else int(depth)} (scattering events) = Mitsuba max_depth {max_depth} (segments) -->
    <integrator type="path">
        <integer name="max_depth" value="$max_depth"/>
        <integer name="rr_depth" value="$rr_depth"/>
    </integrator>

    <sensor type="perspective">
        <string name="fov_axis" value="y"/>
        <float name="fov" value="{float(cam['vfov_deg'])!r}"/>
        <transform name="to_world">
            <lookat origin="{fmt3(cam['position'])}" target="{fmt3(cam['look_at'])}" up="{fmt3(cam['up'])}"/>
        </transform>
        <sampler type="$sampler">
            <integer name="sample_count" value="$spp"/>
        </sampler>
        <film type="hdrfilm">
            <integer name="width" value="{int(width)}"/>
            <integer name="height" value="{int(height)}"/>
            <string name="pixel_format" value="xyz"/>
            <rfilter type="box"/>
        </film>
    </sensor>

{mats}

{shapes}
</scene>
"""


def generate():
    """All output files as {relative path: text}."""
    files = {}
    files["cornell.xml"] = scene_xml(load_ron(RON), files)
    files["interior.xml"] = scene_xml(load_ron(INTERIOR_RON), files, "bench/mitsuba/interior.ron", "interior/")
    return files


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--check", action="store_true", help="only check the files are up to date")
    args = ap.parse_args()
    stale = []
    for rel, text in sorted(generate().items()):
        path = os.path.join(HERE, rel)
        old = open(path, encoding="utf-8").read() if os.path.exists(path) else None
        if old != text:
            stale.append(rel)
            if not args.check:
                os.makedirs(os.path.dirname(path), exist_ok=True)
                with open(path, "w", encoding="utf-8") as f:
                    f.write(text)
    if args.check and stale:
        print("bench/mitsuba out of date (run bench/mitsuba/gen_scene.py): " + ", ".join(stale), file=sys.stderr)
        sys.exit(1)
    print(("wrote " if stale else "up to date: ") + (", ".join(stale) if stale else "bench/mitsuba"))


if __name__ == "__main__":
    main()
