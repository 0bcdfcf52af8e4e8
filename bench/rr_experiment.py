#!/usr/bin/env python3
"""How much variance does Russian roulette add, in candela and in Mitsuba, with and without the
glass sphere? (Evidence for bench/README.md, "Findings"; not part of bench/mitsuba.sh.)

For each configuration two independent renders a, b at --spp give the per-pixel noise without
any reference: MSE = mean((a - b)^2) / 2 over the pixels of the RMSE (light excluded). The
variance RR adds is MSE(with RR) - MSE(without RR). Scene variants are written to
target/bench/exp/. About 5 minutes on 2 cores.

  target/bench-venv/bin/python bench/rr_experiment.py [--spp 64] [--mitsuba-sampler independent]
"""
import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import compare as C  # noqa: E402

EXP = os.path.join(C.OUT, "exp")
NO_RR = 1000  # an rr_depth beyond max_depth: no roulette
SCENE = C.SCENE_RON  # the benchmark scene (C.SCENE_RON is pointed at the variants below)


def candela_scene(rr_depth, sphere):
    """A copy of scenes/bench-cornell.ron with render.rr_depth set, optionally without the sphere."""
    with open(SCENE, encoding="utf-8") as f:
        ron = f.read()
    if not sphere:
        start = ron.index('        (\n            name: "glass sphere"')
        end = ron.index('        (\n            name: "tall block"')
        ron = ron[:start] + ron[end:]
    ron = ron.replace("render: (", f"render: (rr_depth: {rr_depth}, ", 1)
    path = os.path.join(EXP, f"candela-rr{rr_depth}-{'sphere' if sphere else 'nosphere'}.ron")
    with open(path, "w", encoding="utf-8") as f:
        f.write(ron)
    return path


def mitsuba_scene(sphere):
    """bench/mitsuba/cornell.xml, optionally without the sphere (written next to it, removed after)."""
    if sphere:
        return os.path.join(C.MITSUBA_DIR, "cornell.xml"), False
    with open(os.path.join(C.MITSUBA_DIR, "cornell.xml"), encoding="utf-8") as f:
        xml = f.read()
    s, e = xml.index("    <!-- glass sphere -->"), xml.index("    <!-- tall block -->")
    path = os.path.join(C.MITSUBA_DIR, "nosphere-tmp.xml")  # relative mesh/spectrum paths
    with open(path, "w", encoding="utf-8") as f:
        f.write(xml[:s] + xml[e:])
    return path, True


def pair_mse(a, b, mask):
    return float(((a - b) ** 2)[mask].mean() / 2)


def run_pair_candela(scene, spp, mask):
    C.SCENE_RON = scene
    rs = [C.run_candela(spp, seed, os.path.join(EXP, "pair"), 2) for seed in (21, 22)]
    return pair_mse(rs[0]["Y"], rs[1]["Y"], mask), np.mean([r["render_s"] for r in rs])


def run_pair_mitsuba(xml, rr_depth, spp, sampler, mask):
    ys, ts = [], []
    for seed in (21, 22):
        out = os.path.join(EXP, "pair.npy")
        cmd = [sys.executable, C.MITSUBA_RENDER, "--variant", "llvm_ad_spectral", "--spp", str(spp),
               "--seed", str(seed), "--sampler", sampler, "--rr-depth", str(rr_depth), "--out", out,
               "--scene", xml]
        stdout, _, _, _ = C.run_process(cmd)
        ys.append(np.load(out)[0] * C.MITSUBA_Y_TO_CD_M2)
        ts.append(json.loads([l for l in stdout.splitlines() if l.startswith("{")][-1])["render_s"])
    return pair_mse(ys[0], ys[1], mask), np.mean(ts)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--mitsuba-sampler", default="independent")
    args = ap.parse_args()
    os.makedirs(EXP, exist_ok=True)
    mask = C.rmse_mask()
    print(f"| scene | renderer | RR | RMSE (cd/m²) | render s | RMSE² added by RR |\n|---|---|---|---:|---:|---:|")
    for sphere in (True, False):
        label = "with sphere" if sphere else "without sphere"
        rows = [("candela", "rr_depth 3 (default)", lambda: run_pair_candela(candela_scene(3, sphere), args.spp, mask)),
                ("candela", "none", lambda: run_pair_candela(candela_scene(NO_RR, sphere), args.spp, mask))]
        xml, tmp = mitsuba_scene(sphere)
        rows += [(f"Mitsuba ({args.mitsuba_sampler})", "rr_depth 4 (= candela 3)",
                  lambda: run_pair_mitsuba(xml, 4, args.spp, args.mitsuba_sampler, mask)),
                 (f"Mitsuba ({args.mitsuba_sampler})", "none",
                  lambda: run_pair_mitsuba(xml, NO_RR, args.spp, args.mitsuba_sampler, mask))]
        try:
            res = [(who, rr, *fn()) for who, rr, fn in rows]
        finally:
            if tmp:
                os.remove(xml)
        for i, (who, rr, mse, t) in enumerate(res):
            added = f"{mse - res[i + 1][2]:.0f}" if i % 2 == 0 else ""
            print(f"| {label} | {who} | {rr} | {mse ** 0.5:.2f} | {t:.1f} | {added} |", flush=True)


if __name__ == "__main__":
    main()
