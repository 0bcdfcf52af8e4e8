#!/usr/bin/env python3
"""Render bench/mitsuba/cornell.xml with Mitsuba 3 in its own process (one run = one process, so
the caller can measure its wall time and peak RSS), save the Y channel, print a JSON summary.

  target/bench-venv/bin/python bench/mitsuba/render.py --variant llvm_ad_spectral \
      --spp 64 --seed 1 --threads 2 --out target/bench/m.npy

Output: a float64 .npy array of shape (parts, H, W): Mitsuba's Y (unitless, see bench/README.md;
multiply by bench.compare.MITSUBA_Y_TO_CD_M2 for cd/m^2). With --parts K the spp are split into K
independent renders (seeds seed, seed+1, ...), whose spread gives the per-pixel variance.
stdout: one JSON line {"load_s", "render_s" (sum over parts, mi.render and the evaluation of its
result), "spp", "variant", "threads", "parts"}.
"""
import argparse
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "cornell.xml")


def parse_args():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--variant", default="llvm_ad_spectral")
    ap.add_argument("--spp", type=int, default=64, help="samples per pixel (per part)")
    ap.add_argument("--parts", type=int, default=1, help="independent renders of --spp each")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--sampler", default="independent", help="Mitsuba sampler plugin")
    ap.add_argument("--rr-depth", type=int, default=5, help="Mitsuba rr_depth (its default: 5)")
    ap.add_argument("--out", required=True, help=".npy file for the Y images")
    ap.add_argument("--scene", default=SCENE, help="scene file (default: bench/mitsuba/cornell.xml)")
    return ap.parse_args()


def main():
    args = parse_args()
    import drjit as dr
    import mitsuba as mi
    import numpy as np

    mi.set_variant(args.variant)
    # One thread pool serves both the LLVM backend's kernels and the scalar variants' blocks.
    dr.set_thread_count(args.threads)
    mi.set_log_level(mi.LogLevel.Warn)

    t0 = time.perf_counter()
    scene = mi.load_file(args.scene, spp=args.spp, sampler=args.sampler, rr_depth=args.rr_depth)
    load_s = time.perf_counter() - t0
    effective = scene.sensors()[0].sampler().sample_count()
    if effective != args.spp:  # e.g. ldsampler rounds to a square power of two
        sys.exit(f"render.py: sampler {args.sampler!r} would take {effective} spp instead of {args.spp}")

    images, render_s = [], 0.0
    for part in range(args.parts):
        t0 = time.perf_counter()
        img = mi.render(scene, seed=args.seed + part, spp=args.spp)
        xyz = np.array(img, dtype=np.float64)  # forces evaluation (LLVM kernels run here)
        render_s += time.perf_counter() - t0
        assert xyz.shape[2] == 3, xyz.shape  # hdrfilm pixel_format="xyz": X, Y, Z
        images.append(xyz[:, :, 1])
    np.save(args.out, np.stack(images))
    print()  # Mitsuba's log goes to stdout too: the summary is the last line
    json.dump({"variant": args.variant, "spp": args.spp, "parts": args.parts, "seed": args.seed,
               "threads": args.threads, "sampler": args.sampler, "rr_depth": args.rr_depth,
               "load_s": load_s, "render_s": render_s}, sys.stdout)
    print()


if __name__ == "__main__":
    main()
