#!/usr/bin/env python3
"""candela against Radiance's rpict on a luminance image and an illuminance image (rpict -i) of the
office of bench/radiance/gen_scene.py; see bench/README.md, "Images: rpict".

For each N: writes the scenes (gen_scene.py --image), makes candela's converged image (luminance Y
and illuminance E, cached), checks it against Radiance's Monte Carlo mode at every 4th pixel centre
(rtrace, no ambient cache, cached), then, alternating the tools, times Radiance's `rad` pipeline
(rpict at rad's QUALITY settings, then pfilt) and candela at the samples per pixel that give the
same relative RMS error. Markdown on stdout, target/bench/radiance/images-results.json.
"""

import argparse
import hashlib
import json
import math
import os
import re
import resource
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, HERE)
import gen_scene  # noqa: E402

IES = os.path.join(ROOT, "data", "luminaires", "batwing-office.ies")
EFFICACY = 179.0  # lm/W, Radiance's white
RGB_Y = np.array([0.265, 0.670, 0.065])
# Pixels that count in the RMS: away from edges (every neighbour within this relative
# difference of the pixel in candela's converged image, beyond that image's noise: 4 sigma) and
# from the luminaires' 1 cm spheres (Radiance shows them, black; candela's point sources have no
# surface).
SMOOTH = 0.05
LUM_MARGIN_PX = 3


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def children_cpu():
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


def timed(cmd, **kw):
    c0, t0 = children_cpu(), time.perf_counter()
    p = subprocess.run(cmd, check=True, **kw)
    return p, time.perf_counter() - t0, children_cpu() - c0


def read_exr(path):
    import OpenEXR

    with OpenEXR.File(path, separate_channels=True) as f:
        ch = f.channels()
        return {k: np.asarray(v.pixels, dtype=np.float64) for k, v in ch.items()}


def read_pic(path, w, h):
    """A Radiance picture as luminance (cd/m^2 or, from rpict -i, lux), top row first."""
    raw = subprocess.run(["pvalue", "-o", "-h", "-H", "-df", path], check=True, capture_output=True).stdout
    rgb = np.frombuffer(raw, dtype=np.float32).astype(np.float64).reshape(h, w, 3)
    return EFFICACY * rgb @ RGB_Y


class Images:
    def __init__(self, a, n):
        self.a, self.n = a, n
        self.w, self.h = (int(x) for x in a.res.split("x"))
        self.d = os.path.join(ROOT, "target", "bench", "radiance", f"img-n{n}")
        os.makedirs(self.d, exist_ok=True)
        subprocess.run([sys.executable, os.path.join(HERE, "gen_scene.py"), "--n", str(n), "--ies", IES,
                        "--out-dir", self.d, "--image", a.res], check=True)
        self.oct = f"office-{n}.oct"
        with open(os.path.join(self.d, self.oct), "wb") as f:
            subprocess.run(["oconv", f"office-{n}.rad"], cwd=self.d, stdout=f, check=True)
        self.view = gen_scene.view_args(self.w, self.h)
        h = hashlib.sha256()
        for name in (f"office-{n}-image.ron", f"office-{n}.rad", "lum.dat"):
            with open(os.path.join(self.d, name), "rb") as f:
                h.update(f.read())
        self.key_rad = h.hexdigest()[:16]  # Radiance's reference: the scene files
        if os.path.exists(a.candela):
            h.update(subprocess.run([a.candela, "--version"], capture_output=True, text=True).stdout.encode())
        self.key = h.hexdigest()[:16]  # candela's: also its version

    # ---------- candela ----------
    def scene(self, batches):
        """The image scene, or with render.pixel_batches `batches` (other than 16) a copy of it."""
        path = os.path.join(self.d, f"office-{self.n}-image.ron")
        if batches == 16:
            return path
        with open(path, encoding="utf-8") as f:
            text = f.read()
        variant = os.path.join(self.d, f"office-{self.n}-image-pixel-batches-{batches}.ron")
        with open(variant, "w", encoding="utf-8") as f:
            f.write(text.replace("render: (", f"render: (pixel_batches: {batches}, ", 1))
        return variant

    def candela(self, spp, seed, tag, illuminance, batches=16):
        out = os.path.join(self.d, "out-" + tag)
        cmd = [self.a.candela, "render", self.scene(batches), "--spp", str(spp),
               "--threads", str(self.a.threads), "--seed", str(seed), "--out", out, "--quiet", "--overwrite",
               "--checkpoint-interval", "0s"] + (["--illuminance"] if illuminance else [])
        _, wall, cpu = timed(cmd, stdout=subprocess.DEVNULL)
        ch = read_exr(out + ".exr")
        with open(out + ".report.json") as f:
            render_s = json.load(f)["timing"]["render_seconds"]
        r = {"spp": spp, "seed": seed, "wall_s": wall, "cpu_s": cpu, "render_s": render_s, "Y": ch["Y"],
             "varY": ch["stderr.Y"] ** 2}
        if illuminance:
            r["E"], r["varE"] = ch["E"], ch["stderr.E"] ** 2
        return r

    def candela_reference(self):
        a = self.a
        path = os.path.join(self.d, f"ref-candela-{self.key}-{a.ref_parts}x{a.ref_spp}.npz")
        if os.path.exists(path) and not a.fresh_refs:
            log(f"cached: {os.path.relpath(path, ROOT)}")
            z = np.load(path)
            return {k: z[k] for k in z.files}
        log(f"N={self.n}: candela reference, {a.ref_parts} x {a.ref_spp} spp with --illuminance")
        runs = [self.candela(a.ref_spp, 3000 + k, f"ref{k}", True) for k in range(a.ref_parts)]
        k = len(runs)
        ref = {"Y": sum(r["Y"] for r in runs) / k, "varY": sum(r["varY"] for r in runs) / k**2,
               "E": sum(r["E"] for r in runs) / k, "varE": sum(r["varE"] for r in runs) / k**2,
               "cpu_s": np.array(sum(r["cpu_s"] for r in runs))}
        np.savez(path, **ref)
        return ref

    # ---------- Radiance ----------
    def rad_commands(self, quality):
        """rpict and pfilt options that Radiance's `rad` chooses for this scene and QUALITY."""
        rif = os.path.join(self.d, f"{quality}.rif")
        lx, ly, lz = gen_scene.ROOM
        with open(rif, "w") as f:
            f.write(f"ZONE= Interior 0 {lx:g} 0 {ly:g} 0 {lz:g}\nscene= office-{self.n}.rad\nOCTREE= {self.oct}\n"
                    f"QUALITY= {quality}\nVARIABILITY= {self.a.variability}\nDETAIL= Medium\n"
                    f"INDIRECT= {self.a.indirect}\nPENUMBRAS= False\nRESOLUTION= {self.w} {self.h}\n"
                    f"view= img {self.view}\n")
        txt = subprocess.run(["rad", "-n", os.path.basename(rif)], cwd=self.d, check=True, capture_output=True,
                             text=True).stdout
        rp = re.search(r"rpict (.*?) " + re.escape(self.oct) + r" >", txt).group(1).split()
        pf = re.search(r"pfilt (.*?) \S+\.unf >", txt)
        return rp, (pf.group(1).split() if pf else [])

    def precomputed(self, quality, q):
        """A run made beforehand in --precomputed DIR: QUALITY-Q.hdr (rpict, then pfilt),
        QUALITY-Q.rpict.time and .pfilt.time (GNU time '%e wall %U user %S sys'), QUALITY-Q.cmd."""
        d = self.a.precomputed
        stem = os.path.join(d, f"{quality}-{q}") if d else None
        if not stem or not os.path.exists(stem + ".hdr"):
            return None
        wall = cpu = 0.0
        for part in ("rpict", "pfilt"):
            with open(f"{stem}.{part}.time") as f:
                t = f.read().split()
            wall += float(t[0])
            cpu += float(t[2]) + float(t[4])
        with open(stem + ".cmd") as f:
            cmd = f.read().strip()
        return {"wall_s": wall, "cpu_s": cpu, "rpict": cmd, "pfilt": "", "precomputed": stem,
                "img": read_pic(stem + ".hdr", self.w, self.h)}

    def radiance(self, quality, illuminance):
        pre = self.precomputed(quality, "E" if illuminance else "Y")
        if pre:
            return pre
        rp, pf = self.rad_commands(quality)
        unf, pic = os.path.join(self.d, "r.unf"), os.path.join(self.d, "r.hdr")
        cmd = ["rpict"] + (["-i"] if illuminance else []) + rp + [self.oct]
        with open(unf, "wb") as f:
            _, w1, c1 = timed(cmd, cwd=self.d, stdout=f)
        with open(pic, "wb") as f:
            _, w2, c2 = timed(["pfilt"] + pf + [unf], cwd=self.d, stdout=f)
        return {"wall_s": w1 + w2, "cpu_s": c1 + c2, "rpict": " ".join(cmd), "pfilt": " ".join(["pfilt"] + pf),
                "img": read_pic(pic, self.w, self.h)}

    def radiance_mc_reference(self, illuminance):
        """Radiance without ambient cache at every a.ref_step-th pixel centre (rtrace over vwrays'
        rays): mean and standard error over a.rad_ref_runs runs (dummy leading rays shift each
        run's random stream: rtrace has no seed option)."""
        a = self.a
        q = "E" if illuminance else "Y"
        path = os.path.join(self.d, f"ref-radiance-{q}-{self.key_rad}-{a.rad_ref_ad}-{a.rad_ref_runs}-{a.ref_step}.npz")
        if os.path.exists(path) and not a.fresh_refs:
            log(f"cached: {os.path.relpath(path, ROOT)}")
            z = np.load(path)
            return z["mean"], z["se"]
        rays = subprocess.run(["vwrays", "-fa", "-pj", "0", "-x", str(self.w), "-y", str(self.h), "-pa", "0"]
                              + self.view.split(), check=True, capture_output=True, text=True).stdout.split("\n")
        rays = [r for r in rays if r.strip()]
        assert len(rays) == self.w * self.h, len(rays)
        s = a.ref_step
        pick = [j * self.w + i for j in range(s // 2, self.h, s) for i in range(s // 2, self.w, s)]
        sub = "\n".join(rays[p] for p in pick) + "\n"
        args = f"-aa 0 -ab 16 -ad {a.rad_ref_ad} -as 0 -lw {1.0 / a.rad_ref_ad:.3g} -lr 0".split()
        log(f"N={self.n}: Radiance reference ({q}), {a.rad_ref_runs} runs of rtrace {' '.join(args)} at {len(pick)} pixel centres")
        import concurrent.futures as cf

        def one(k):
            dummy = f"{self.view.split()[2]} {self.view.split()[3]} {self.view.split()[4]} 0 -1 0\n" * (1 + 37 * k)
            p = subprocess.run(["rtrace", "-h", "-ov", "-n", "1"] + (["-i"] if illuminance else []) + args + [self.oct],
                               cwd=self.d, input=dummy + sub, capture_output=True, text=True, check=True)
            rows = p.stdout.strip().splitlines()[1 + 37 * k:]
            return np.array([EFFICACY * float(np.dot(RGB_Y, [float(c) for c in r.split()[:3]])) for r in rows])

        with cf.ThreadPoolExecutor(2) as ex:
            runs = np.array(list(ex.map(one, range(a.rad_ref_runs))))
        mean = runs.mean(axis=0).reshape(len(range(s // 2, self.h, s)), -1)
        se = (runs.std(axis=0, ddof=1) / math.sqrt(len(runs))).reshape(mean.shape)
        np.savez(path, mean=mean, se=se)
        return mean, se

    # ---------- masks ----------
    def mask(self, ref_y, var_y):
        y = ref_y
        ok = np.ones_like(y, bool)
        for dj in (-1, 0, 1):
            for di in (-1, 0, 1):
                if dj == 0 and di == 0:
                    continue
                nb = np.roll(np.roll(y, dj, 0), di, 1)
                vnb = np.roll(np.roll(var_y, dj, 0), di, 1)
                ok &= np.abs(nb - y) < SMOOTH * y + 4 * np.sqrt(var_y + vnb)
        ok[0, :] = ok[-1, :] = ok[:, 0] = ok[:, -1] = False
        # The luminaires' spheres, projected with Radiance's view (right = vd x vu).
        eye = np.array(gen_scene.VIEW_EYE)
        f = np.array(gen_scene.VIEW_TARGET) - eye
        f /= np.linalg.norm(f)
        r = np.cross(f, [0, 0, 1.0])
        r /= np.linalg.norm(r)
        u = np.cross(r, f)
        tv = math.tan(math.radians(gen_scene.VIEW_VFOV / 2))
        th = tv * self.w / self.h
        for p in gen_scene.layout(self.n):
            v = np.array(p) - eye
            z = v @ f
            if z <= 0:
                continue
            col = (0.5 + (v @ r) / z / (2 * th)) * self.w
            row = (0.5 - (v @ u) / z / (2 * tv)) * self.h
            c0, r0 = int(col), int(row)
            m = LUM_MARGIN_PX
            ok[max(r0 - m, 0):max(r0 + m + 1, 0), max(c0 - m, 0):max(c0 + m + 1, 0)] = False
        return ok


def rel_rms(x, ref, var_ref, mask):
    """Relative RMS error over the mask with the reference's own noise subtracted:
    E[((x - ref)/ref)^2] = err^2 + var_ref/ref^2. Also the mean relative difference (bias)."""
    rr = ref[mask]
    raw = np.mean(((x[mask] - rr) / rr) ** 2)
    noise = np.mean(var_ref[mask] / rr**2)
    return float(math.sqrt(max(raw - noise, 0.0))), float(np.mean((x[mask] - rr) / rr))


def agreement(cref, cvar, rmean, rse, mask, step):
    """candela's converged image at the same pixel centres as Radiance's Monte Carlo reference."""
    s = step
    c = cref[s // 2::s, s // 2::s][: rmean.shape[0], : rmean.shape[1]]
    sc = np.sqrt(cvar[s // 2::s, s // 2::s][: rmean.shape[0], : rmean.shape[1]])
    m = mask[s // 2::s, s // 2::s][: rmean.shape[0], : rmean.shape[1]]
    z = (c - rmean) / np.hypot(sc, rse)
    rel = (c - rmean) / rmean
    npts = int(m.sum())
    h = rmean.shape[0]
    out = {"points": npts, "mean_rel_diff": float(rel[m].mean()),
           "se_mean_rel_diff": float(np.sqrt(np.sum((np.hypot(sc, rse) / rmean)[m] ** 2)) / npts),
           "chi2_per_point": float(np.mean(z[m] ** 2)), "beyond_3sigma": int((np.abs(z[m]) > 3).sum()),
           "beyond_4sigma": int((np.abs(z[m]) > 4).sum()), "candela_mean": float(c[m].mean()),
           "radiance_mean": float(rmean[m].mean())}
    # Top, middle and bottom thirds of the image (ceiling, back wall, floor).
    for name, (a, b) in {"top third": (0, h // 3), "middle third": (h // 3, 2 * h // 3), "bottom third": (2 * h // 3, h)}.items():
        mm = m[a:b]
        out[name] = {"rel_diff": float(rel[a:b][mm].mean()),
                     "se": float(np.sqrt(np.sum((np.hypot(sc, rse)[a:b] / rmean[a:b])[mm] ** 2)) / max(mm.sum(), 1))}
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ns", default="6", help="luminaire counts (6, 48, 500)")
    ap.add_argument("--res", default="256x192", help="image size WxH")
    ap.add_argument("--qualities", default="Medium,High", help="rad QUALITY values to time (Low, Medium, High)")
    ap.add_argument("--quantities", default="Y,E", help="Y: luminance (rpict), E: illuminance (rpict -i)")
    ap.add_argument("--indirect", type=int, default=2, help="rad INDIRECT (rpict -ab is derived from it)")
    ap.add_argument("--variability", default="Medium", help="rad VARIABILITY")
    ap.add_argument("--reps", type=int, default=3)
    ap.add_argument("--reps-high", type=int, default=3, help="timed runs at QUALITY=High (minutes each)")
    ap.add_argument("--threads", type=int, default=2, help="candela threads (rpict is one process)")
    ap.add_argument("--candela", default=os.path.join(ROOT, "target", "release", "candela"))
    ap.add_argument("--ref-spp", type=int, default=256, help="candela reference spp per part")
    ap.add_argument("--ref-parts", type=int, default=4)
    ap.add_argument("--calib-spp", type=int, default=64, help="candela run that sets its spp")
    ap.add_argument("--pixel-batches", type=int, default=16, choices=(2, 4, 8, 16),
                    help="candela's render.pixel_batches in the calibration and timed runs (references: 16)")
    ap.add_argument("--rad-ref-ad", type=int, default=256)
    ap.add_argument("--rad-ref-runs", type=int, default=4)
    ap.add_argument("--ref-step", type=int, default=4, help="Radiance reference at every STEP-th pixel centre")
    ap.add_argument("--no-radiance-ref", action="store_true", help="skip the agreement check against Radiance")
    ap.add_argument("--fresh-refs", action="store_true")
    ap.add_argument("--precomputed", metavar="DIR", help="use the Radiance runs made beforehand in DIR "
                    "(QUALITY-Y.hdr, QUALITY-E.hdr with .rpict.time, .pfilt.time, .cmd; e.g. one long High run)")
    ap.add_argument("--results", default="images-results.json")
    ap.add_argument("--quick", action="store_true", help="smoke run: 128x96, Medium only, 1 rep, small references")
    a = ap.parse_args()
    if a.quick:
        a.res, a.qualities, a.reps, a.ref_spp, a.rad_ref_ad, a.rad_ref_runs = "128x96", "Medium", 1, 256, 64, 2
    results = {"settings": vars(a), "ns": {}}
    out = os.path.join(ROOT, "target", "bench", "radiance", a.results)
    for n in [int(x) for x in a.ns.split(",")]:
        b = Images(a, n)
        ref = b.candela_reference()
        mask = b.mask(ref["Y"], ref["varY"])
        entry = {"pixels_counted": int(mask.sum()), "pixels": int(mask.size), "reference_cpu_s": float(ref["cpu_s"]),
                 "mean_Y": float(ref["Y"][mask].mean()), "mean_E": float(ref["E"][mask].mean()), "agreement": {}, "timed": {}}
        results["ns"][str(n)] = entry
        if not a.no_radiance_ref:
            for q in a.quantities.split(","):
                rm, rse = b.radiance_mc_reference(q == "E")
                entry["agreement"][q] = agreement(ref[q], ref["var" + q], rm, rse, mask, a.ref_step)
                log(f"N={n} {q}: agreement {json.dumps(entry['agreement'][q])}")
        cal = b.candela(a.calib_spp, 7, "calib", True, a.pixel_batches)
        cal_rms = {q: rel_rms(cal[q], ref[q], ref["var" + q], mask)[0] for q in ("Y", "E")}
        entry["calibration"] = {"spp": a.calib_spp, "rel_rms": cal_rms, "pixel_batches": a.pixel_batches}
        log(f"N={n}: candela {a.calib_spp} spp: rel. RMS Y {cal_rms['Y']:.3%}, E {cal_rms['E']:.3%}")
        for quality in a.qualities.split(","):
            for q in a.quantities.split(","):
                ill = q == "E"
                rr_runs, cc_runs, spp = [], [], None
                pre = b.precomputed(quality, q) is not None
                for rep in range(a.reps_high if quality.lower() == "high" and not pre else a.reps):
                    rr = b.radiance(quality, ill)
                    rr["rel_rms"], rr["bias"] = rel_rms(rr.pop("img"), ref[q], ref["var" + q], mask)
                    rr_runs.append(rr)
                    if spp is None:
                        spp = max(1, math.ceil(a.calib_spp * (cal_rms[q] / max(rr["rel_rms"], 1e-6)) ** 2))
                    cr = b.candela(spp, 100 + rep, f"timed-{quality}-{q}", ill, a.pixel_batches)
                    cr["rel_rms"], cr["bias"] = rel_rms(cr[q], ref[q], ref["var" + q], mask)
                    for k in ("Y", "varY", "E", "varE"):
                        cr.pop(k, None)
                    cc_runs.append(cr)
                    log(f"N={n} {quality} {q} rep {rep}: Radiance CPU {rr['cpu_s']:.1f} s rel. RMS {rr['rel_rms']:.2%} "
                        f"(bias {rr['bias']:+.2%}); candela {spp} spp CPU {cr['cpu_s']:.2f} s rel. RMS {cr['rel_rms']:.2%}")
                med = statistics.median
                t = {"radiance": rr_runs, "candela": cc_runs, "candela_spp": spp,
                     "radiance_cpu": med(x["cpu_s"] for x in rr_runs), "candela_cpu": med(x["cpu_s"] for x in cc_runs),
                     "radiance_rms": med(x["rel_rms"] for x in rr_runs), "candela_rms": med(x["rel_rms"] for x in cc_runs),
                     "radiance_bias": med(x["bias"] for x in rr_runs),
                     "radiance_cpu_range": [min(x["cpu_s"] for x in rr_runs), max(x["cpu_s"] for x in rr_runs)],
                     "candela_cpu_range": [min(x["cpu_s"] for x in cc_runs), max(x["cpu_s"] for x in cc_runs)],
                     "radiance_wall": med(x["wall_s"] for x in rr_runs), "candela_wall": med(x["wall_s"] for x in cc_runs)}
                t["cpu_ratio"] = t["radiance_cpu"] / t["candela_cpu"]
                t["cpu_ratio_range"] = [t["radiance_cpu_range"][0] / t["candela_cpu_range"][1],
                                        t["radiance_cpu_range"][1] / t["candela_cpu_range"][0]]
                t["cpu_ratio_equal_rms"] = t["cpu_ratio"] * (t["radiance_rms"] / t["candela_rms"]) ** 2
                entry["timed"][f"{quality} {q}"] = t
                with open(out, "w") as f:
                    json.dump(results, f, indent=1)
    with open(out, "w") as f:
        json.dump(results, f, indent=1)
    print_table(results)


def print_table(results):
    print("| N | rad QUALITY, quantity | Radiance CPU s | Radiance rel. RMS (bias) | candela spp | candela CPU s | "
          "candela rel. RMS | CPU-time ratio | **at equal RMS** |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|---:|")
    for n, e in results["ns"].items():
        for k, t in e["timed"].items():
            rc, cc = t["radiance_cpu_range"], t["candela_cpu_range"]
            print(f"| {n} | {k} | {t['radiance_cpu']:.1f} ({rc[0]:.1f}–{rc[1]:.1f}) | {t['radiance_rms']:.2%} "
                  f"({t['radiance_bias']:+.2%}) | {t['candela_spp']} | {t['candela_cpu']:.2f} ({cc[0]:.2f}–{cc[1]:.2f}) | "
                  f"{t['candela_rms']:.2%} | {t['cpu_ratio']:.0f}× ({t['cpu_ratio_range'][0]:.0f}–{t['cpu_ratio_range'][1]:.0f}) | "
                  f"**{t['cpu_ratio_equal_rms']:.0f}×** |")


if __name__ == "__main__":
    main()
