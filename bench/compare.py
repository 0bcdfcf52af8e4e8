#!/usr/bin/env python3
"""Side-by-side benchmark of candela against Mitsuba 3 on scenes/bench-cornell.ron.

Run it through bench/mitsuba.sh (which installs Mitsuba into target/bench-venv and builds
candela first); see bench/README.md for what is measured and how. Outline:

  1. converged references, cached in target/bench/refs/ (keyed by a hash of the scene files):
     candela and Mitsuba llvm_ad_spectral, each at --ref-spp split into --ref-parts independent
     seeds (their spread gives the variance of region means);
  2. agreement check of the two references, region by region, in units of sigma;
  3. one warm-up render per renderer (Mitsuba's LLVM backend JIT-compiles its kernels on first
     use and caches them in ~/.drjit);
  4. --reps rounds of: candela, Mitsuba llvm_ad_spectral, Mitsuba scalar_spectral, all at --spp,
     then --reps rounds of candela at the spp that matches Mitsuba LLVM's render time, alternated
     with Mitsuba LLVM at --spp; every render is its own process (wall time, peak RSS);
  5. summary (medians, min-max, ratios), JSON in target/bench/mitsuba-results.json and a
     Markdown table on stdout.
"""
import argparse
import datetime
import hashlib
import json
import os
import platform
import re
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

BENCH = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(BENCH)
OUT = os.path.join(ROOT, "target", "bench")
CANDELA = os.path.join(ROOT, "target", "release", "candela")
SCENE_RON = os.path.join(ROOT, "scenes", "bench-cornell.ron")
MITSUBA_DIR = os.path.join(BENCH, "mitsuba")
MITSUBA_RENDER = os.path.join(MITSUBA_DIR, "render.py")
TIME = "/usr/bin/time"  # GNU time (Debian package `time`), for the peak RSS

# Mitsuba's spectral film stores spectrum_to_srgb(L) = mean_i(rgb_cmf(l_i) L(l_i) / p(l_i)) / 106.75026
# (include/mitsuba/core/spectrum.h: MI_CIE_Y_NORMALIZATION = 1/106.7502593994140625) and its "xyz"
# pixel format maps that back with srgb_to_xyz (round trip exact to 1.2e-6). So Mitsuba's
# Y = int(ybar_M L dl) / 106.75026 with L in whatever unit the scene uses (here W m^-2 sr^-1 nm^-1),
# while candela's Y = 683 lm/W * int(ybar L dl) in cd/m^2. Hence:
MITSUBA_Y_TO_CD_M2 = 683.0 * 106.7502593994140625  # = 72910.43 cd/m^2 per unit of Mitsuba Y

W = H = 256
# Pixel rectangles (row0, row1, col0, col1), half-open, inside the projection of each surface
# (computed from the camera and the RON geometry; red wall on the image's left in both renderers).
REGIONS = {
    "light": (34, 39, 108, 146),
    "ceiling": (12, 28, 70, 185),
    "back wall": (62, 100, 62, 195),
    "red wall (left)": (90, 170, 12, 45),
    "green wall (right)": (90, 170, 212, 245),
    "floor (front left)": (226, 248, 40, 120),
    "gold block (front face)": (115, 215, 82, 128),
    "glass sphere": (175, 210, 145, 180),
}
# The directly visible light and a margin around it, left out of the RMSE: its pixels are
# 10 000 cd/m^2 with wavelength noise and its edge pixels mix light and ceiling, so they would
# dominate the error of a 112 cd/m^2 image without saying anything about light transport.
LIGHT_EXCLUDE = (30, 44, 103, 152)


# --------------------------------------------------------------------------- processes
def log(msg):
    print(msg, file=sys.stderr, flush=True)


def run_process(cmd):
    """Run cmd as its own process under /usr/bin/time; return (stdout, stderr, wall seconds,
    peak RSS in MiB). The RSS comes from GNU time (%M, the child's ru_maxrss) because a child
    forked straight from this Python process would count this process's own pages, copied at
    fork, in its high-water mark."""
    with tempfile.NamedTemporaryFile("r", suffix=".rss") as rss_file:
        t0 = time.perf_counter()
        p = subprocess.run([TIME, "-f", "%M", "-o", rss_file.name] + cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if p.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr[-3000:]}")
        rss_kib = float(rss_file.read().strip().splitlines()[-1])
    return p.stdout, p.stderr, wall, rss_kib / 1024.0


def read_candela_exr(path):
    """(Y, stderr.Y) of a candela EXR, via Mitsuba's EXR reader."""
    import mitsuba as mi
    if mi.variant() is None:
        mi.set_variant("scalar_spectral")
    bmp = mi.Bitmap(path)
    names = [bmp.struct_()[i].name for i in range(bmp.channel_count())]
    a = np.array(bmp, dtype=np.float64)
    return a[:, :, names.index("Y")], a[:, :, names.index("stderr.Y")]


def run_candela(spp, seed, stem, threads, caustics="light-tracing"):
    """One candela render in its own process; timings from its report.json. `caustics`:
    candela's default light-traced caustics, or "path-tracing" (camera paths only, the same
    algorithm as Mitsuba's path integrator)."""
    cmd = [CANDELA, "render", SCENE_RON, "--out", stem, "--spp", str(spp), "--threads",
           str(threads), "--seed", str(seed), "--quiet", "--checkpoint-interval", "0s",
           "--caustics", caustics]
    _, err, wall, rss = run_process(cmd)
    m = re.search(r"rendered .* in ([0-9.]+) s", err)
    with open(stem + ".report.json", encoding="utf-8") as f:
        report = json.load(f)
    render_s = report["timing"]["render_seconds"]
    y, se = read_candela_exr(stem + ".exr")
    return {"renderer": "candela", "variant": "candela", "spp": spp, "seed": seed,
            "render_s": render_s, "render_s_stderr_line": float(m.group(1)) if m else None,
            "wall_s": wall, "peak_rss_mib": rss, "rr_depth": report["settings"]["rr_depth"],
            "max_depth": report["settings"]["max_depth"], "Y": y, "var": se ** 2}


def run_mitsuba(variant, spp, seed, out, args, parts=1, sampler=None):
    """One Mitsuba render (or `parts` independent ones) in its own process."""
    cmd = [sys.executable, MITSUBA_RENDER, "--variant", variant, "--spp", str(spp), "--seed",
           str(seed), "--threads", str(args.threads), "--parts", str(parts), "--sampler",
           sampler or args.mitsuba_sampler, "--rr-depth", str(args.mitsuba_rr_depth), "--out", out]
    stdout, _, wall, rss = run_process(cmd)
    info = json.loads([l for l in stdout.splitlines() if l.startswith("{")][-1])
    ys = np.load(out) * MITSUBA_Y_TO_CD_M2
    return {"renderer": "mitsuba", "variant": variant, "sampler": sampler or args.mitsuba_sampler,
            "spp": spp, "seed": seed,
            "render_s": info["render_s"], "load_s": info["load_s"], "wall_s": wall,
            "peak_rss_mib": rss, "Y": ys.mean(axis=0), "parts": ys}


# --------------------------------------------------------------------------- references
def files_hash(paths, extra):
    """sha256 over the given files' bytes and an extra string."""
    h = hashlib.sha256(extra.encode())
    for p in sorted(paths):
        h.update(os.path.relpath(p, ROOT).encode())
        with open(p, "rb") as f:
            h.update(f.read())
    return h.hexdigest()[:16]


def candela_scene_files():
    data = [os.path.join(ROOT, "data", f) for f in
            ("cornell-box.csv", "cmfs-cie1931-2.csv", "luminous-efficiency.csv")]
    return [SCENE_RON, os.path.join(ROOT, "data", "ior", "Au.csv")] + data


def mitsuba_scene_files():
    out = []
    for d, _, fs in os.walk(MITSUBA_DIR):
        # The Cornell scene's files only (not the diffuse interior's, bench/mitsuba/interior.*).
        out += [os.path.join(d, f) for f in fs
                if f.endswith((".xml", ".obj", ".spd")) and "interior" not in os.path.relpath(os.path.join(d, f), MITSUBA_DIR)]
    return out


def tool_version(cmd):
    return subprocess.run(cmd, capture_output=True, text=True).stdout.strip()


def reference(parts, var, path, cached, render_s):
    """A converged reference from its independent parts: mean, per-pixel variance of the mean
    (given, or from the spread of the parts), and the parts themselves."""
    if var is None:
        var = parts.var(axis=0, ddof=1) / len(parts)
    return {"Y": parts.mean(axis=0), "parts": parts, "var": var, "path": path, "cached": cached,
            "render_s": render_s}


def cached_reference(name, files, settings, args, render_parts):
    """The converged reference of one renderer: loaded from target/bench/refs/ when cached
    under a hash of its scene files and `settings` (unless --fresh-refs), else rendered by
    `render_parts(spp)` -> (parts, per-pixel variance of the mean or None, render seconds) at
    --ref-parts × (--ref-spp / --ref-parts) spp and cached."""
    key = files_hash(files, settings)
    path = os.path.join(OUT, "refs", f"{name.lower()}-{key}.npz")
    if os.path.exists(path) and not args.fresh_refs:
        log(f"reference: {name}, cached {os.path.relpath(path, ROOT)}")
        z = np.load(path)
        return reference(z["parts"], z["var"] if "var" in z.files else None, path, True,
                         float(z["render_s"]))
    spp = args.ref_spp // args.ref_parts
    log(f"reference: {name} {args.ref_parts} x {spp} spp ...")
    parts, var, render_s = render_parts(spp)
    extra = {} if var is None else {"var": var}
    np.savez(path, parts=parts, render_s=render_s, **extra)
    log(f"  {render_s:.1f} s")
    return reference(parts, var, path, False, render_s)


def candela_reference(args):
    """Converged candela image from --ref-parts independent seeds (as Mitsuba's): mean, per-pixel
    variance of the mean from the renders' stderr.Y, and the parts, whose spread gives honest
    region sigmas also where the noise is heavy-tailed (the caustic-lit ceiling)."""
    def render_parts(spp):
        parts, var, render_s = [], 0.0, 0.0
        for k in range(args.ref_parts):
            r = run_candela(spp, 1_000_003 + k, os.path.join(OUT, "refs", "candela-ref"), args.threads)
            parts.append(r["Y"])
            var = var + r["var"]
            render_s += r["render_s"]
        return np.array(parts), var / args.ref_parts ** 2, render_s

    settings = f"candela {tool_version([CANDELA, '--version'])} {args.ref_spp} {args.ref_parts} light-tracing"
    return cached_reference("candela", candela_scene_files(), settings, args, render_parts)


def mitsuba_reference(args):
    """Converged Mitsuba llvm_ad_spectral image from --ref-parts independent seeds: mean and
    per-pixel variance of the mean (spread of the parts / parts), and the parts themselves."""
    import mitsuba as mi

    def render_parts(spp):
        r = run_mitsuba("llvm_ad_spectral", spp, 1_000_000, os.path.join(OUT, "refs", "mitsuba-ref.npy"),
                        args, parts=args.ref_parts)
        return r["parts"], None, r["render_s"]

    settings = (f"mitsuba {mi.__version__} {args.ref_spp} {args.ref_parts} {args.mitsuba_sampler} "
                f"{args.mitsuba_rr_depth}")
    return cached_reference("Mitsuba", mitsuba_scene_files(), settings, args, render_parts)


# --------------------------------------------------------------------------- statistics
def rmse_mask():
    """True for the pixels that count in the RMSE (all but the light and its margin)."""
    m = np.ones((H, W), bool)
    r0, r1, c0, c1 = LIGHT_EXCLUDE
    m[r0:r1, c0:c1] = False
    return m


def error_stats(img, ref, ref_var, mask):
    """RMSE of img against ref over mask, with the reference's own noise removed:
    E[(img - ref)^2] = var(img) + var(ref) + bias^2, and var(ref) is known per pixel."""
    d2 = ((img - ref) ** 2)[mask].mean()
    mse = max(d2 - ref_var[mask].mean(), 1e-30)
    return {"mse": mse, "rmse": mse ** 0.5, "rel_rmse": mse ** 0.5 / ref[mask].mean(),
            "rmse_raw": d2 ** 0.5}


def region_mean(img, rect):
    r0, r1, c0, c1 = rect
    return img[r0:r1, c0:c1].mean()


def agreement(cref, mref):
    """Compare the converged images region by region and pixel by pixel, in sigma units.
    Both sigmas come from the spread of the region means over each renderer's independent
    reference parts (per-pixel variances understate the error of heavy-tailed regions)."""
    rows = []
    regions = dict(REGIONS, **{"whole image": (0, H, 0, W), "whole image without light": None})
    mask = rmse_mask()
    for name, rect in regions.items():
        if rect is None:
            cparts = np.array([p[mask].mean() for p in cref["parts"]])
            mparts = np.array([p[mask].mean() for p in mref["parts"]])
        else:
            r0, r1, c0, c1 = rect
            cparts = np.array([region_mean(p, rect) for p in cref["parts"]])
            mparts = np.array([region_mean(p, rect) for p in mref["parts"]])
        c, m = cparts.mean(), mparts.mean()
        sc = cparts.std(ddof=1) / np.sqrt(len(cparts))
        sm = mparts.std(ddof=1) / np.sqrt(len(mparts))
        sigma = np.hypot(sc, sm)
        rows.append({"region": name, "candela": c, "candela_sigma": sc, "mitsuba": m,
                     "mitsuba_sigma": sm, "diff_pct": 100 * (c - m) / m, "z": (c - m) / sigma})
    # Pixel level: sum of squared differences over the sum of the expected variances (1 if the
    # images differ by noise only; > 1 if there is a systematic difference somewhere).
    d2 = (cref["Y"] - mref["Y"]) ** 2
    v = cref["var"] + mref["var"]
    ok = v > 0
    chi = {"pixel_chi2_ratio": float(d2[ok & mask].sum() / v[ok & mask].sum()),
           "pixels_beyond_4_sigma_pct": float(100 * (d2[ok & mask] > 16 * v[ok & mask]).mean())}
    return rows, chi


def summarize(values):
    return {"median": statistics.median(values), "min": min(values), "max": max(values), "n": len(values)}


def summary_of(runs):
    """Medians and ranges of one configuration's runs."""
    def col(k):
        return summarize([r[k] for r in runs])
    s = {k: col(k) for k in ("render_s", "wall_s", "peak_rss_mib", "rmse", "rel_rmse", "mse", "efficiency",
                             "samples_per_s")}
    s["spp"] = runs[0]["spp"]
    s["label"] = runs[0]["label"]
    return s


def paired_ratios(cruns, mruns):
    """candela / Mitsuba ratios round by round (each pair ran back to back, so a change of the
    machine's load between rounds cancels), summarised as median and min-max."""
    pairs = list(zip(cruns, mruns))
    def ratio(f):
        return summarize([f(c) / f(m) for c, m in pairs])
    return {"throughput": ratio(lambda r: r["samples_per_s"]),
            "render_time": ratio(lambda r: r["render_s"]),
            "efficiency": ratio(lambda r: r["efficiency"]),
            "peak_rss": ratio(lambda r: r["peak_rss_mib"])}


# --------------------------------------------------------------------------- output
def fmt_range(s, f="{:.2f}"):
    return f"{f.format(s['median'])} ({f.format(s['min'])}–{f.format(s['max'])})"


def markdown(summary, ratios, agree, chi, meta):
    """README-ready Markdown."""
    lines = [f"Measured {meta['date']} on {meta['cpu']} ({meta['threads']} threads; {meta['load_note']}); "
             f"medians of {meta['reps']} alternated runs (min–max in brackets).", "",
             "| renderer | spp | render time (s) | process wall (s) | Msamples/s | peak RSS (MiB) | RMSE Y (cd/m²) | rel. RMSE | efficiency 1/(MSE·t) |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for key in ("candela", "candela-pt", "mitsuba-llvm", "mitsuba-scalar", "mitsuba-llvm-independent", "candela-equal-time",
                "mitsuba-llvm-equal-time"):
        if key not in summary:
            continue
        s = summary[key]
        lines.append(f"| {s['label']} | {s['spp']} | {fmt_range(s['render_s'])} | {fmt_range(s['wall_s'])} | "
                     f"{s['samples_per_s']['median'] / 1e6:.3f} | {s['peak_rss_mib']['median']:.0f} | "
                     f"{fmt_range(s['rmse'])} | {100 * s['rel_rmse']['median']:.1f} % | "
                     f"{s['efficiency']['median']:.3g} |")
    lines += ["", "candela ÷ Mitsuba, per round (median, min–max):", "",
              "| candela ÷ Mitsuba | throughput (samples/s) | render time at equal spp | "
              "efficiency at equal error | peak RSS |", "|---|---:|---:|---:|---:|"]
    for name, r in ratios.items():
        cells = [f"{fmt_range(r[k], '{:.2f}')}×" for k in ("throughput", "render_time", "efficiency", "peak_rss")]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    parts = f"{meta['ref_parts']} × {meta['ref_spp'] // meta['ref_parts']} spp"
    lines += ["", f"Agreement of the converged references (candela {parts}; Mitsuba "
              f"llvm_ad_spectral {parts}), luminance in cd/m² ± 1σ (σ from the spread of the "
              "parts' region means):", "",
              "| region | candela | Mitsuba (× 683 × 106.7503) | Δ | Δ/σ |", "|---|---:|---:|---:|---:|"]
    for a in agree:
        lines.append(f"| {a['region']} | {a['candela']:.2f} ± {a['candela_sigma']:.2f} | "
                     f"{a['mitsuba']:.2f} ± {a['mitsuba_sigma']:.2f} | {a['diff_pct']:+.2f} % | {a['z']:+.1f} |")
    lines += ["", f"Per pixel (light excluded): Σ(ΔY)² / Σ(σ²_candela + σ²_Mitsuba) = "
              f"{chi['pixel_chi2_ratio']:.3f} (1 = noise only); {chi['pixels_beyond_4_sigma_pct']:.2f} % of "
              "pixels beyond 4σ."]
    return "\n".join(lines)


def machine_info():
    cpu = "unknown CPU"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "platform": platform.platform(),
            "loadavg_start": os.getloadavg()}


# --------------------------------------------------------------------------- main
def parse_args():
    ap = argparse.ArgumentParser(description="candela vs Mitsuba 3 benchmark (see bench/README.md)")
    ap.add_argument("--reps", type=int, default=3, help="alternated repetitions (default 3)")
    ap.add_argument("--spp", type=int, default=64, help="samples per pixel of the timed runs")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--ref-spp", type=int, default=1024, help="reference samples per pixel")
    ap.add_argument("--ref-parts", type=int, default=16,
                    help="independent reference renders (each renderer) of --ref-spp/--ref-parts spp each")
    ap.add_argument("--fresh-refs", action="store_true", help="re-render the cached references")
    ap.add_argument("--mitsuba-sampler", default="multijitter",
                    help="Mitsuba sampler of the main runs (default multijitter, stratified; its ldsampler "
                         "is biased on this scene, see bench/README.md)")
    ap.add_argument("--no-independent", action="store_true",
                    help="skip the extra Mitsuba llvm_ad_spectral rows with its default 'independent' sampler")
    ap.add_argument("--mitsuba-rr-depth", type=int, default=5, help="Mitsuba rr_depth (default: its default 5)")
    ap.add_argument("--no-scalar", action="store_true", help="skip Mitsuba scalar_spectral")
    ap.add_argument("--no-candela-pt", action="store_true",
                    help="skip the candela rows with --caustics path-tracing (camera paths only)")
    ap.add_argument("--check", action="store_true",
                    help="exit 1 if the converged images disagree beyond noise (a region with |z| > 4 and |diff| > 0.1 %%)")
    ap.add_argument("--json", default=os.path.join(OUT, "mitsuba-results.json"))
    return ap.parse_args()


def finish_run(r, label, ref, common, mask):
    """Attach error statistics to a run and drop its images."""
    e = error_stats(r["Y"], ref["Y"], ref["var"], mask)
    ec = error_stats(r["Y"], common["Y"], common["var"], mask)
    r.update(e)
    r["label"] = label
    r["rmse_vs_common_ref"] = ec["rmse"]
    r["samples_per_s"] = W * H * r["spp"] / r["render_s"]
    r["efficiency"] = 1.0 / (r["mse"] * r["render_s"])
    r["mean_Y"] = float(r["Y"].mean())
    r["rmse_by_region"] = {}
    for name, (r0, r1, c0, c1) in REGIONS.items():
        d2 = ((r["Y"] - ref["Y"]) ** 2 - ref["var"])[r0:r1, c0:c1].mean()
        r["rmse_by_region"][name] = float(max(d2, 0.0) ** 0.5)
    for k in ("Y", "var", "parts"):
        r.pop(k, None)
    log(f"  {label:<34} {r['spp']:>5} spp  render {r['render_s']:7.2f} s  wall {r['wall_s']:7.2f} s  "
        f"RSS {r['peak_rss_mib']:6.0f} MiB  RMSE {r['rmse']:8.3f}  mean {r['mean_Y']:.2f}")
    return r


def main():
    args = parse_args()
    os.makedirs(os.path.join(OUT, "refs"), exist_ok=True)
    runs_dir = os.path.join(OUT, "runs")
    os.makedirs(runs_dir, exist_ok=True)
    import mitsuba as mi
    import drjit as dr
    meta = dict(machine_info(), date=datetime.date.today().isoformat(), reps=args.reps, spp=args.spp,
                threads=args.threads, ref_spp=args.ref_spp, ref_parts=args.ref_parts,
                mitsuba=mi.__version__, drjit=dr.__version__, candela=tool_version([CANDELA, "--version"]),
                git=tool_version(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"]),
                mitsuba_sampler=args.mitsuba_sampler, mitsuba_rr_depth=args.mitsuba_rr_depth,
                mitsuba_y_to_cd_m2=MITSUBA_Y_TO_CD_M2)

    cref, mref = candela_reference(args), mitsuba_reference(args)
    common = {"Y": (cref["Y"] + mref["Y"]) / 2, "var": (cref["var"] + mref["var"]) / 4}
    agree, chi = agreement(cref, mref)
    mask = rmse_mask()

    mv = f"Mitsuba {mi.__version__}"
    samp = args.mitsuba_sampler
    # (key, label, run function of (seed, stem)) for one round at --spp, in alternation order.
    configs = [("candela", "candela", cref, lambda seed, d: run_candela(args.spp, seed, d + "candela", args.threads)),
               ("mitsuba-llvm", f"{mv} llvm_ad_spectral, {samp}", mref,
                lambda seed, d: run_mitsuba("llvm_ad_spectral", args.spp, seed, d + "llvm.npy", args))]
    if not args.no_candela_pt:
        # Same converged image (both estimators are unbiased), so the same reference.
        configs.insert(1, ("candela-pt", "candela, path tracing only", cref,
                           lambda seed, d: run_candela(args.spp, seed, d + "candela-pt", args.threads,
                                                       caustics="path-tracing")))
    if not args.no_scalar:
        configs.append(("mitsuba-scalar", f"{mv} scalar_spectral, {samp}", mref,
                        lambda seed, d: run_mitsuba("scalar_spectral", args.spp, seed, d + "scalar.npy", args)))
    if not args.no_independent and samp != "independent":
        configs.append(("mitsuba-llvm-independent", f"{mv} llvm_ad_spectral, independent", mref,
                        lambda seed, d: run_mitsuba("llvm_ad_spectral", args.spp, seed, d + "indep.npy", args,
                                                    sampler="independent")))
    groups = {c[0]: [] for c in configs}
    runs_stem = runs_dir + os.sep

    log("warm-up (not timed): candela 4 spp; each Mitsuba LLVM configuration once (JIT compile, kernel cache)")
    w = run_candela(4, 7, runs_stem + "warmup", args.threads)
    meta["candela_rr_depth"], meta["candela_max_depth"] = w["rr_depth"], w["max_depth"]
    for key, _, _, fn in configs:
        if key.startswith("mitsuba-llvm"):
            w = fn(7, runs_stem + "warmup-")
            meta[f"{key}_warmup_render_s"] = w["render_s"]
            log(f"  {key}: {w['render_s']:.1f} s (includes compilation unless ~/.drjit had the kernels)")
    for rep in range(args.reps):
        log(f"round {rep + 1}/{args.reps} at {args.spp} spp")
        for key, label, ref, fn in configs:
            groups[key].append(finish_run(fn(rep + 1, runs_stem), label, ref, common, mask))

    # Equal time: candela gets the spp that its measured throughput fits into Mitsuba LLVM's
    # median render time; alternated with Mitsuba LLVM at --spp again.
    t_m = statistics.median(r["render_s"] for r in groups["mitsuba-llvm"])
    t_c = statistics.median(r["render_s"] for r in groups["candela"])
    spp_eq = max(1, round(args.spp * t_m / t_c))
    meta["candela_equal_time_spp"] = spp_eq
    groups["candela-equal-time"], groups["mitsuba-llvm-equal-time"] = [], []
    for rep in range(args.reps):
        log(f"equal-time round {rep + 1}/{args.reps}: candela {spp_eq} spp vs Mitsuba LLVM {args.spp} spp")
        r = run_candela(spp_eq, 100 + rep, runs_stem + "candela-eq", args.threads)
        groups["candela-equal-time"].append(finish_run(r, "candela, equal time", cref, common, mask))
        r = run_mitsuba("llvm_ad_spectral", args.spp, 100 + rep, runs_stem + "llvm.npy", args)
        groups["mitsuba-llvm-equal-time"].append(finish_run(r, f"{mv} llvm_ad_spectral, {samp} (again)", mref, common, mask))
    meta["loadavg_end"] = os.getloadavg()
    meta["load_note"] = (f"load average {meta['loadavg_start'][0]:.1f} at start, {meta['loadavg_end'][0]:.1f} at end"
                         + ("; machine shared with other jobs" if max(meta["loadavg_start"][0], meta["loadavg_end"][0]) > 1.5 else ""))

    summary = {k: summary_of(v) for k, v in groups.items() if v}
    ratios = {name: paired_ratios(groups[ckey], groups[key])
              for ckey, key, name in (
                  ("candela", "mitsuba-llvm", f"candela vs llvm_ad_spectral, {samp}"),
                  ("candela", "mitsuba-scalar", f"candela vs scalar_spectral, {samp}"),
                  ("candela", "mitsuba-llvm-independent", "candela vs llvm_ad_spectral, independent"),
                  ("candela-pt", "mitsuba-llvm", f"candela path tracing only vs llvm_ad_spectral, {samp}"),
                  ("candela-pt", "mitsuba-scalar", f"candela path tracing only vs scalar_spectral, {samp}"))
              if groups.get(ckey) and groups.get(key)}
    md = markdown(summary, ratios, agree, chi, meta)
    worst = max(abs(a["z"]) for a in agree)
    disagree = [a["region"] for a in agree if abs(a["z"]) > 4 and abs(a["diff_pct"]) > 0.1]
    result = {"meta": meta, "references": {"candela": {k: cref[k] for k in ("path", "cached", "render_s")},
                                           "mitsuba": {k: mref[k] for k in ("path", "cached", "render_s")}},
              "agreement": {"regions": agree, **chi, "worst_abs_z": worst, "disagreeing_regions": disagree},
              "summary": summary, "ratios": ratios, "runs": groups, "markdown": md}
    with open(args.json, "w", encoding="utf-8") as f:
        json.dump(result, f, indent=2, default=float)
    print(md)
    log(f"wrote {os.path.relpath(args.json, ROOT)}")
    if disagree:
        log(f"agreement: the converged images DISAGREE beyond noise in: {', '.join(disagree)}")
        if args.check:
            sys.exit(1)
    else:
        log(f"agreement: ok (largest region difference {worst:.1f} sigma)")


if __name__ == "__main__":
    main()
