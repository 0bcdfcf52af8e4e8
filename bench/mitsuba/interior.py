#!/usr/bin/env python3
"""candela against Mitsuba 3 on a diffuse interior (bench/mitsuba/interior.ron and .xml): the office
of the Radiance benchmark lit by six ceiling panels, no glass and no metal, so candela's light
tracing is off and both renderers path-trace with next-event estimation. See bench/README.md,
"Diffuse interior".

Run it through bench/mitsuba.sh --interior (which installs Mitsuba and builds candela). Outline:
  1. converged references, cached in target/bench/refs/ (keyed by a hash of the scene files and
     the settings): candela and Mitsuba llvm_ad_spectral, --ref-parts independent seeds each;
  2. agreement of the two references: whole image and 4 x 3 blocks, sigma from the parts' spread;
  3. --reps rounds of candela then Mitsuba llvm_ad_spectral (--mitsuba-sampler) at --spp, each
     its own process under GNU time: render time (each renderer's own), CPU time (user + system
     of the process), RMSE of Y against each renderer's own reference;
  4. medians, per-round ratios of the efficiency 1/(MSE * time); Markdown on stdout, JSON in
     target/bench/mitsuba-interior-results.json.
"""
import argparse
import datetime
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
BENCH = os.path.dirname(HERE)
ROOT = os.path.dirname(BENCH)
sys.path.insert(0, BENCH)
import compare  # noqa: E402  (MITSUBA_Y_TO_CD_M2, read_candela_exr, files_hash, machine_info)

RON = os.path.join(HERE, "interior.ron")
XML = os.path.join(HERE, "interior.xml")
OUT = os.path.join(ROOT, "target", "bench")
# Pixels brighter than this in the converged image are the directly seen panels (3000 cd/m^2):
# left out of the RMSE with a 1-pixel margin, as the Cornell benchmark leaves out its light.
PANEL_THRESHOLD = 1000.0


def log(msg):
    print(msg, file=sys.stderr, flush=True)


def timed(cmd):
    """Run cmd under GNU time; (stdout, stderr, wall s, CPU s = user + system, peak RSS MiB)."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as tf:
        t0 = time.perf_counter()
        p = subprocess.run([compare.TIME, "-f", "%U %S %M", "-o", tf.name] + cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        if p.returncode != 0:
            raise RuntimeError(f"{' '.join(cmd)} failed ({p.returncode}):\n{p.stderr[-3000:]}")
        u, s, m = tf.read().strip().splitlines()[-1].split()
    return p.stdout, p.stderr, wall, float(u) + float(s), float(m) / 1024.0


def scene_with_batches(k):
    """interior.ron, or with render.pixel_batches k (other than the default 16) a copy of it in
    target/bench (the scene refers to no other file)."""
    if k == 16:
        return RON
    path = os.path.join(OUT, f"interior-pixel-batches-{k}.ron")
    with open(RON, encoding="utf-8") as f:
        text = f.read()
    with open(path, "w", encoding="utf-8") as f:
        f.write(text.replace("render: (", f"render: (pixel_batches: {k}, ", 1))
    return path


def run_candela(args, spp, seed, stem, batches=16):
    cmd = [args.candela, "render", scene_with_batches(batches), "--out", stem, "--spp", str(spp), "--threads", str(args.threads),
           "--seed", str(seed), "--quiet", "--overwrite", "--checkpoint-interval", "0s"]
    _, _, wall, cpu, rss = timed(cmd)
    with open(stem + ".report.json", encoding="utf-8") as f:
        rep = json.load(f)
    y, se = compare.read_candela_exr(stem + ".exr")
    return {"renderer": "candela", "spp": spp, "seed": seed, "render_s": rep["timing"]["render_seconds"],
            "rays_per_sample": rep["timing"]["rays"] / (y.size * spp),
            "wall_s": wall, "cpu_s": cpu, "peak_rss_mib": rss, "Y": y, "var": se ** 2}


def run_mitsuba(args, spp, seed, out, parts=1, variant="llvm_ad_spectral"):
    cmd = [sys.executable, os.path.join(HERE, "render.py"), "--scene", XML, "--variant", variant,
           "--spp", str(spp), "--seed", str(seed), "--threads", str(args.threads), "--parts", str(parts),
           "--sampler", args.mitsuba_sampler, "--out", out]
    stdout, _, wall, cpu, rss = timed(cmd)
    info = json.loads([line for line in stdout.splitlines() if line.startswith("{")][-1])
    ys = np.load(out) * compare.MITSUBA_Y_TO_CD_M2
    return {"renderer": "mitsuba" if variant == "llvm_ad_spectral" else "scalar", "spp": spp, "seed": seed, "render_s": info["render_s"], "wall_s": wall,
            "cpu_s": cpu, "peak_rss_mib": rss, "Y": ys.mean(axis=0), "parts": ys}


def reference(args, name, render):
    """(parts, per-pixel variance of the mean) of a converged image, cached."""
    files = [RON, XML, os.path.join(ROOT, "data", "luminous-efficiency.csv"), os.path.join(ROOT, "data", "cmfs-cie1931-2.csv")]
    version = subprocess.run([args.candela, "--version"], capture_output=True, text=True).stdout.strip()
    key = compare.files_hash(files, f"{name} {version} {args.ref_spp} {args.ref_parts} {args.mitsuba_sampler}")
    path = os.path.join(OUT, "refs", f"interior-{name}-{key}.npz")
    if os.path.exists(path) and not args.fresh_refs:
        log(f"reference: {name}, cached {os.path.relpath(path, ROOT)}")
        z = np.load(path)
        return {"parts": z["parts"], "var": z["var"], "render_s": float(z["render_s"]), "cpu_s": float(z["cpu_s"])}
    spp = args.ref_spp // args.ref_parts
    log(f"reference: {name}, {args.ref_parts} x {spp} spp ...")
    parts, var, render_s, cpu_s = render(spp)
    np.savez(path, parts=parts, var=var, render_s=render_s, cpu_s=cpu_s)
    log(f"  {render_s:.1f} s render, {cpu_s:.1f} s CPU")
    return {"parts": parts, "var": var, "render_s": render_s, "cpu_s": cpu_s}


def candela_reference(args):
    def render(spp):
        runs = [run_candela(args, spp, 2_000_003 + k, os.path.join(OUT, "refs", "interior-candela-ref"))
                for k in range(args.ref_parts)]
        parts = np.array([r["Y"] for r in runs])
        var = sum(r["var"] for r in runs) / args.ref_parts ** 2
        return parts, var, sum(r["render_s"] for r in runs), sum(r["cpu_s"] for r in runs)
    return reference(args, "candela", render)


def mitsuba_reference(args):
    def render(spp):
        r = run_mitsuba(args, spp, 2_000_000, os.path.join(OUT, "refs", "interior-mitsuba-ref.npy"), parts=args.ref_parts)
        parts = r["parts"]
        return parts, parts.var(axis=0, ddof=1) / len(parts), r["render_s"], r["cpu_s"]
    return reference(args, "mitsuba", render)


def panel_mask(y):
    """True for the pixels that count: all but the directly seen panels and a 1-pixel margin."""
    bright = y > PANEL_THRESHOLD
    grown = bright.copy()
    grown[1:, :] |= bright[:-1, :]
    grown[:-1, :] |= bright[1:, :]
    grown[:, 1:] |= bright[:, :-1]
    grown[:, :-1] |= bright[:, 1:]
    g2 = grown.copy()
    g2[1:, 1:] |= grown[:-1, :-1]
    g2[:-1, :-1] |= grown[1:, 1:]
    return ~g2


def agreement(cref, mref, mask):
    """Region means (whole image, 4 x 3 blocks; panels excluded) with sigma from the spread of
    each renderer's parts; per pixel, sum of squared differences over the sum of variances."""
    h, w = mask.shape
    regions = {"whole image (panels excluded)": (0, h, 0, w)}
    for j in range(3):
        for i in range(4):
            regions[f"block row {j} col {i}"] = (j * h // 3, (j + 1) * h // 3, i * w // 4, (i + 1) * w // 4)
    rows = []
    for name, (r0, r1, c0, c1) in regions.items():
        m = mask[r0:r1, c0:c1]
        cp = np.array([p[r0:r1, c0:c1][m].mean() for p in cref["parts"]])
        mp = np.array([p[r0:r1, c0:c1][m].mean() for p in mref["parts"]])
        c, mi = cp.mean(), mp.mean()
        sc, sm = cp.std(ddof=1) / np.sqrt(len(cp)), mp.std(ddof=1) / np.sqrt(len(mp))
        rows.append({"region": name, "candela": c, "candela_sigma": sc, "mitsuba": mi, "mitsuba_sigma": sm,
                     "diff_pct": 100 * (c - mi) / mi, "z": (c - mi) / np.hypot(sc, sm)})
    d2 = (cref["Y"] - mref["Y"]) ** 2
    v = cref["var"] + mref["var"]
    ok = mask & (v > 0)
    return rows, {"pixel_chi2_ratio": float(d2[ok].sum() / v[ok].sum()),
                  "pixels_beyond_4_sigma_pct": float(100 * (d2[ok] > 16 * v[ok]).mean())}


def finish(r, ref, mask):
    d2 = ((r["Y"] - ref["Y"]) ** 2)[mask].mean()
    mse = max(d2 - ref["var"][mask].mean(), 1e-30)
    r.update(mse=mse, rmse=mse ** 0.5, rel_rmse=mse ** 0.5 / ref["Y"][mask].mean(),
             eff_render=1 / (mse * r["render_s"]), eff_cpu=1 / (mse * r["cpu_s"]),
             samples_per_s=r["Y"].size * r["spp"] / r["render_s"], mean_Y=float(r["Y"][mask].mean()))
    for k in ("Y", "var", "parts"):
        r.pop(k, None)
    log(f"  {r['renderer']:<8} {r['spp']:>5} spp  render {r['render_s']:6.2f} s  CPU {r['cpu_s']:6.2f} s  "
        f"wall {r['wall_s']:6.2f} s  RMSE {r['rmse']:.3f} cd/m2  mean {r['mean_Y']:.2f}")
    return r


def med(runs, k):
    v = [r[k] for r in runs]
    return {"median": statistics.median(v), "min": min(v), "max": max(v)}


def rng(s, f="{:.2f}"):
    return f"{f.format(s['median'])} ({f.format(s['min'])}–{f.format(s['max'])})"


def markdown(res):
    meta, s = res["meta"], res["summary"]
    lines = [f"Measured {meta['date']} ({meta['threads']} threads; load average {meta['loadavg_start'][0]:.1f} at start, "
             f"{meta['loadavg_end'][0]:.1f} at end); medians of {meta['reps']} alternated rounds (min–max).", "",
             "| renderer | spp | render time (s) | CPU time (s) | Msamples/s | peak RSS (MiB) | RMSE Y (cd/m²) | rel. RMSE |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for key, label in (("candela", "candela"), ("mitsuba", f"Mitsuba {meta['mitsuba']} llvm_ad_spectral, {meta['sampler']}"),
                       ("scalar", f"Mitsuba {meta['mitsuba']} scalar_spectral, {meta['sampler']}")):
        if key not in s:
            continue
        g = s[key]
        lines.append(f"| {label} | {g['spp']} | {rng(g['render_s'])} | {rng(g['cpu_s'])} | {g['samples_per_s']['median'] / 1e6:.3f} | "
                     f"{g['peak_rss_mib']['median']:.0f} | {rng(g['rmse'], '{:.3f}')} | {100 * g['rel_rmse']['median']:.2f} % |")
    r = res["ratios"]
    lines += ["", "| candela ÷ Mitsuba, per round | throughput | efficiency at equal error, render time | "
              "efficiency at equal error, CPU time |", "|---|---:|---:|---:|",
              f"| vs llvm_ad_spectral: median (min–max) | {rng(r['throughput'])}× | {rng(r['eff_render'])}× | **{rng(r['eff_cpu'])}×** |"]
    if res.get("ratios_scalar"):
        r = res["ratios_scalar"]
        lines.append(f"| vs scalar_spectral: median (min–max) | {rng(r['throughput'])}× | {rng(r['eff_render'])}× | **{rng(r['eff_cpu'])}×** |")
    lines += ["",
              f"Converged references: candela {meta['ref_parts']} × {meta['ref_spp'] // meta['ref_parts']} spp, Mitsuba "
              f"{meta['ref_parts']} × {meta['ref_spp'] // meta['ref_parts']} spp; luminance in cd/m² ± 1σ:", "",
              "| region | candela | Mitsuba | Δ | Δ/σ |", "|---|---:|---:|---:|---:|"]
    for a in res["agreement"]["regions"]:
        lines.append(f"| {a['region']} | {a['candela']:.3f} ± {a['candela_sigma']:.3f} | {a['mitsuba']:.3f} ± "
                     f"{a['mitsuba_sigma']:.3f} | {a['diff_pct']:+.2f} % | {a['z']:+.1f} |")
    ag = res["agreement"]
    lines += ["", f"Per pixel: Σ(ΔY)² / Σ(σ²_candela + σ²_Mitsuba) = {ag['pixel_chi2_ratio']:.3f} (1 = noise only); "
              f"{ag['pixels_beyond_4_sigma_pct']:.2f} % of pixels beyond 4σ."]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description="candela vs Mitsuba 3 on a diffuse interior (see bench/README.md)")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--ref-parts", type=int, default=8)
    ap.add_argument("--fresh-refs", action="store_true")
    ap.add_argument("--mitsuba-sampler", default="multijitter")
    ap.add_argument("--pixel-batches", type=int, default=16, choices=(2, 4, 8, 16),
                    help="candela's render.pixel_batches in the timed runs (references: 16)")
    ap.add_argument("--scalar", action="store_true", help="also time Mitsuba scalar_spectral (one ray at a time)")
    ap.add_argument("--candela", default=compare.CANDELA, help="candela binary (default target/release/candela)")
    ap.add_argument("--json", default=os.path.join(OUT, "mitsuba-interior-results.json"))
    ap.add_argument("--quick", action="store_true", help="smoke run: 1 round, 8 x 64 spp references")
    args = ap.parse_args()
    if args.quick:
        args.reps, args.ref_spp, args.ref_parts = 1, 512, 8
    os.makedirs(os.path.join(OUT, "refs"), exist_ok=True)
    runs = os.path.join(OUT, "runs")
    os.makedirs(runs, exist_ok=True)
    import mitsuba as mi

    meta = dict(compare.machine_info(), date=datetime.date.today().isoformat(), reps=args.reps, spp=args.spp,
                threads=args.threads, ref_spp=args.ref_spp, ref_parts=args.ref_parts, mitsuba=mi.__version__,
                sampler=args.mitsuba_sampler, candela_binary=args.candela, pixel_batches=args.pixel_batches,
                candela=subprocess.run([args.candela, "--version"], capture_output=True, text=True).stdout.strip())
    cref, mref = candela_reference(args), mitsuba_reference(args)
    for ref in (cref, mref):
        ref["Y"] = ref["parts"].mean(axis=0)
    mask = panel_mask(cref["Y"])
    meta["pixels_counted"] = int(mask.sum())
    agree, chi = agreement(cref, mref, mask)
    for a in agree[:1]:
        log(f"agreement: {a['region']}: candela {a['candela']:.3f}, Mitsuba {a['mitsuba']:.3f} ({a['diff_pct']:+.2f} %, {a['z']:+.1f} sigma)")

    log("warm-up (not timed): candela 4 spp, Mitsuba LLVM (JIT kernel cache)")
    run_candela(args, 4, 7, os.path.join(runs, "interior-warmup"))
    run_mitsuba(args, args.spp, 7, os.path.join(runs, "interior-warmup.npy"))
    groups = {"candela": [], "mitsuba": []}
    if args.scalar:
        groups["scalar"] = []
    for rep in range(args.reps):
        log(f"round {rep + 1}/{args.reps} at {args.spp} spp")
        groups["candela"].append(finish(run_candela(args, args.spp, rep + 1, os.path.join(runs, "interior-candela"),
                                                    args.pixel_batches), cref, mask))
        groups["mitsuba"].append(finish(run_mitsuba(args, args.spp, rep + 1, os.path.join(runs, "interior-mitsuba.npy")), mref, mask))
        if args.scalar:
            # Same code as the LLVM variant, so the same converged image: the LLVM reference.
            groups["scalar"].append(finish(run_mitsuba(args, args.spp, rep + 1, os.path.join(runs, "interior-scalar.npy"),
                                                       variant="scalar_spectral"), mref, mask))
    meta["loadavg_end"] = os.getloadavg()
    summary = {}
    for k, g in groups.items():
        if k == "candela":
            meta["candela_rays_per_sample"] = statistics.median(r["rays_per_sample"] for r in g)
        summary[k] = {q: med(g, q) for q in ("render_s", "cpu_s", "wall_s", "peak_rss_mib", "rmse", "rel_rmse", "mse",
                                             "eff_render", "eff_cpu", "samples_per_s")}
        summary[k]["spp"] = args.spp

    def ratio(q, other="mitsuba"):
        v = [c[q] / m[q] for c, m in zip(groups["candela"], groups[other])]
        return {"median": statistics.median(v), "min": min(v), "max": max(v)}
    res = {"meta": meta, "agreement": {"regions": agree, **chi}, "summary": summary,
           "ratios": {q: ratio(k) for q, k in (("throughput", "samples_per_s"), ("eff_render", "eff_render"), ("eff_cpu", "eff_cpu"))},
           "ratios_scalar": ({q: ratio(k, "scalar") for q, k in (("throughput", "samples_per_s"), ("eff_render", "eff_render"),
                                                                  ("eff_cpu", "eff_cpu"))} if args.scalar else None),
           "runs": groups, "references": {"candela": {k: cref[k] for k in ("render_s", "cpu_s")},
                                          "mitsuba": {k: mref[k] for k in ("render_s", "cpu_s")}}}
    res["markdown"] = markdown(res)
    with open(args.json, "w", encoding="utf-8") as f:
        json.dump(res, f, indent=2, default=float)
    print(res["markdown"])
    log(f"wrote {os.path.relpath(args.json, ROOT)}")


if __name__ == "__main__":
    main()
