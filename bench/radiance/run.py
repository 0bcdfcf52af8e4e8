#!/usr/bin/env python3
"""candela against Radiance (rtrace -I) on the work-plane grid of an office; see bench/README.md.

For each N (luminaires, or "daylit": the office under an overcast sky through a window): writes the scenes (gen_scene.py), makes both converged references
(cached), checks that they agree within their errors, then times Radiance at its "medium" and
"high" ambient settings and in Monte Carlo mode against candela at the sample count that gives
the same RMS error, alternating the runs. Prints a Markdown table; writes everything to
target/bench/radiance/results.json. Progress goes to stderr.
"""

import argparse
import glob
import hashlib
import json
import math
import os
import resource
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
HERE = os.path.join(ROOT, "bench", "radiance")
IES = os.path.join(ROOT, "data", "luminaires", "batwing-office.ies")
# Radiance's luminous efficacy of its "white" (179 lm/W) and the RGB weights of its luminance.
EFFICACY = 179.0
RGB_Y = (0.265, 0.670, 0.065)

# Ambient settings of Ladybug Tools' honeybee rtrace presets (medium = detail level 1, high =
# 2), the settings its users run grids with.
PRESETS = {
    "medium": "-ab 3 -ad 2048 -as 2048 -ar 64 -aa 0.2 -dj 0.5 -ds 0.25 -dt 0.25 -dc 0.5 -dr 1 "
    "-dp 256 -st 0.5 -lr 6 -lw 0.01 -ss 0.7",
    "high": "-ab 6 -ad 4096 -as 4096 -ar 128 -aa 0.1 -dj 1 -ds 0.05 -dt 0.15 -dc 0.75 -dr 3 "
    "-dp 512 -st 0.15 -lr 8 -lw 0.005 -ss 1",
}


def mc_args(ad, ab):
    """Radiance without its ambient cache: -aa 0 is Monte Carlo path tracing from each point.
    -lw 1/ad keeps one sample per deeper bounce (a smaller -lw makes rtrace multiply them);
    -lr 0 ends paths by Russian roulette, so only -ab truncates."""
    return f"-aa 0 -ab {ab} -ad {ad} -as 0 -lw {1.0 / ad:.3g} -lr 0"


def log(*a):
    print(*a, file=sys.stderr, flush=True)


def sh(cmd, **kw):
    return subprocess.run(cmd, check=True, **kw)


def children_cpu():
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    return ru.ru_utime + ru.ru_stime


class Bench:
    def __init__(self, a):
        self.a = a
        self.out = os.path.join(ROOT, "target", "bench", "radiance")
        self.candela = a.candela
        os.makedirs(self.out, exist_ok=True)

    # ---------- scenes ----------
    def scene_dir(self, n):
        return os.path.join(self.out, f"n{n}")

    def generate(self, n):
        d = self.scene_dir(n)
        sh([sys.executable, os.path.join(HERE, "gen_scene.py"), "--n", str(n), "--ies", IES, "--out-dir", d])
        with open(os.path.join(d, f"office-{n}.oct"), "wb") as f:
            sh(["oconv", f"office-{n}.rad"], cwd=d, stdout=f)
        return d

    def scene_hash(self, n):
        d = self.scene_dir(n)
        h = hashlib.sha256()
        for name in (f"office-{n}.ron", f"office-{n}.rad", "lum.dat", "points.txt") + (("cie_overcast.cal",) if n == "daylit" else ()):
            with open(os.path.join(d, name), "rb") as f:
                h.update(f.read())
        with open(IES, "rb") as f:
            h.update(f.read())
        return h.hexdigest()[:16]

    # ---------- one run of each tool ----------
    def run_candela(self, n, samples, seed, tag):
        d = self.scene_dir(n)
        ron = os.path.join(d, f"{tag}.ron")
        with open(os.path.join(d, f"office-{n}.ron")) as f:
            text = f.read()
        assert "measure: (samples: 4096)" in text, "gen_scene.py's default measure.samples changed"
        text = text.replace("measure: (samples: 4096)", f"measure: (samples: {samples})")
        with open(ron, "w") as f:
            f.write(text)
        outdir = os.path.join(d, "out-" + tag)
        os.makedirs(outdir, exist_ok=True)
        cmd = [self.candela, "render", ron, "--threads", str(self.a.threads), "--seed", str(seed),
               "--out", outdir + "/", "--quiet", "--overwrite", "--checkpoint-interval", "0s"]
        c0, t0 = children_cpu(), time.perf_counter()
        sh(cmd, stdout=subprocess.DEVNULL)
        wall, cpu = time.perf_counter() - t0, children_cpu() - c0
        with open(os.path.join(outdir, f"{tag}.report.json")) as f:
            rep = json.load(f)
        g = rep["grids"][0]
        vals = [v for row in g["values"] for v in row]
        ses = [v for row in g["stderr"] for v in row]
        return {"wall_s": wall, "cpu_s": cpu, "measure_s": rep["timing"]["measure_seconds"], "values": vals, "stderr": ses,
                "samples": samples, "seed": seed}

    def load_radiance(self, directory):
        """A Radiance run made outside this script (--precomputed): out.txt = rtrace -I -h -ov
        over points.txt, time.txt = GNU time's '%e wall %U user %S sys ...', cmd.txt = the command."""
        with open(os.path.join(directory, "out.txt")) as f:
            rows = [line.split() for line in f.read().strip().splitlines()]
        with open(os.path.join(directory, "time.txt")) as f:
            t = f.read().split()
        with open(os.path.join(directory, "cmd.txt")) as f:
            cmd = f.read().strip()
        lux = [EFFICACY * sum(w * float(c) for w, c in zip(RGB_Y, r[:3])) for r in rows]
        return {"wall_s": float(t[0]), "cpu_s": float(t[2]) + float(t[4]), "values": lux, "args": cmd, "nproc": 1,
                "seed": 0, "precomputed": directory}

    def run_radiance(self, n, args, nproc, seed):
        """One rtrace -I process over the grid; rtrace has no seed option, so `seed` leading
        dummy points shift its random stream (their results are dropped)."""
        d = self.scene_dir(n)
        with open(os.path.join(d, "points.txt")) as f:
            pts = f.read()
        dummy = "4 3 1.5 0 0 1\n" * seed
        cmd = ["rtrace", "-h", "-I", "-ov", "-n", str(nproc)] + args.split() + [f"office-{n}.oct"]
        c0, t0 = children_cpu(), time.perf_counter()
        p = subprocess.run(cmd, cwd=d, input=dummy + pts, capture_output=True, text=True, check=True)
        wall, cpu = time.perf_counter() - t0, children_cpu() - c0
        rows = [line.split() for line in p.stdout.strip().splitlines()][seed:]
        lux = [EFFICACY * sum(w * float(c) for w, c in zip(RGB_Y, r[:3])) for r in rows]
        return {"wall_s": wall, "cpu_s": cpu, "values": lux, "args": args, "nproc": nproc, "seed": seed}

    # ---------- references ----------
    def references(self, n):
        """Both converged grids, each cached under a key of the scene files and its settings."""
        a = self.a
        h = self.scene_hash(n)
        return {
            "candela": self.cached(f"refs-candela-{n}-{h}-{a.ref_samples}", a.ref_seeds, lambda: self.ref_candela(n)),
            "radiance": self.cached(f"refs-radiance-{n}-{h}-{a.ref_ad}ab{a.ref_ab}", a.ref_runs,
                                    lambda: self.ref_radiance(n)),
        }

    def cached(self, name, runs, make):
        """A cached reference of these settings with at least `runs` runs (all of them used)."""
        path = os.path.join(self.out, f"{name}x{runs}.json")
        if not self.a.fresh_refs:
            for p in sorted(glob.glob(os.path.join(self.out, name + "x*.json"))):
                with open(p) as f:
                    got = json.load(f)
                if len(got) >= runs:
                    log(f"cached: {os.path.basename(p)}")
                    return got
        got = make()
        with open(path, "w") as f:
            json.dump(got, f)
        return got

    def ref_candela(self, n):
        a = self.a
        log(f"N={n}: candela reference, {a.ref_seeds} x {a.ref_samples} samples per point")
        return [self.run_candela(n, a.ref_samples, 1000 + k, f"ref-c{k}") for k in range(a.ref_seeds)]

    def ref_radiance(self, n):
        a = self.a
        log(f"N={n}: Radiance reference, {a.ref_runs} runs of {mc_args(a.ref_ad, a.ref_ab)}, 2 at a time")
        runs = []
        t0 = time.perf_counter()
        for k in range(0, a.ref_runs, 2):
            # Two single-process runs side by side, each with its own random stream.
            runs += self.parallel_radiance(n, mc_args(a.ref_ad, a.ref_ab), [s for s in (k, k + 1) if s < a.ref_runs])
            log(f"  {len(runs)}/{a.ref_runs} ({time.perf_counter() - t0:.0f} s)")
        return runs

    def parallel_radiance(self, n, args, seeds):
        import concurrent.futures as cf

        with cf.ThreadPoolExecutor(len(seeds)) as ex:
            return list(ex.map(lambda s: self.run_radiance(n, args, 1, 1 + 37 * s), seeds))


def mean_se(runs_values):
    """Per point: mean over runs and the standard error of that mean (spread of the runs)."""
    k = len(runs_values)
    m = [sum(col) / k for col in zip(*runs_values)]
    se = [math.sqrt(sum((x - mu) ** 2 for x in col) / (k - 1) / k) for col, mu in zip(zip(*runs_values), m)]
    return m, se


def combine_candela(cruns):
    """candela's runs merged by sample count (equal counts: plain mean); error from its reported
    standard errors, and, with 2+ seeds, from their spread too."""
    k = len(cruns)
    m = [sum(col) / k for col in zip(*(r["values"] for r in cruns))]
    se_rep = [math.sqrt(sum(s * s for s in col)) / k for col in zip(*(r["stderr"] for r in cruns))]
    se_spread = mean_se([r["values"] for r in cruns])[1] if k > 1 else None
    return m, se_rep, se_spread


def agreement(c, sc, r, sr):
    d = [(ci - ri) for ci, ri in zip(c, r)]
    s = [math.sqrt(a * a + b * b) for a, b in zip(sc, sr)]
    z = [di / si for di, si in zip(d, s)]
    rel = [di / ri for di, ri in zip(d, r)]
    npts = len(c)
    mean_rel = sum(rel) / npts
    # Error of the mean relative difference from the per-point errors (independent points).
    se_mean_rel = math.sqrt(sum((si / ri) ** 2 for si, ri in zip(s, r))) / npts
    return {
        "mean_rel_diff": mean_rel,
        "se_mean_rel_diff": se_mean_rel,
        "beyond_3sigma": sum(1 for x in z if abs(x) > 3),
        "beyond_2sigma": sum(1 for x in z if abs(x) > 2),
        "chi2_per_point": sum(x * x for x in z) / npts,
        "max_abs_z": max(abs(x) for x in z),
        "E_avg_candela": sum(c) / npts,
        "E_avg_radiance": sum(r) / npts,
        "points": npts,
    }


def rel_rms(values, ref, ref_se):
    """RMS relative error against the reference, its own noise subtracted:
    E[((x - ref)/ref)^2] = err_x^2 + (se_ref/ref)^2."""
    n = len(values)
    raw = sum(((x - r) / r) ** 2 for x, r in zip(values, ref)) / n
    noise = sum((s / r) ** 2 for s, r in zip(ref_se, ref)) / n
    return math.sqrt(max(raw - noise, 0.0)), math.sqrt(raw)


def bias(values, ref):
    return sum((x - r) / r for x, r in zip(values, ref)) / len(ref)


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--ns", default="6,48", help="luminaire counts (6, 48, 500) and/or daylit (the N = 6 office "
                    "lit by an overcast sky through a window instead)")
    ap.add_argument("--reps", type=int, default=3, help="timed runs of each configuration")
    ap.add_argument("--reps-high", type=int, default=3, help="timed runs of Radiance \"high\" (minutes each)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--candela", default=os.path.join(ROOT, "target", "release", "candela"), help="candela binary")
    ap.add_argument("--settings", default="mc,medium", help="Radiance settings to time: mc, medium, high")
    ap.add_argument("--precomputed", metavar="SETTING=DIR,...",
                    help="use the Radiance run in DIR (out.txt, time.txt, cmd.txt) for SETTING, e.g. one long "
                         "'high' run made beforehand; candela still runs --reps times")
    ap.add_argument("--mc-ad", type=int, default=256, help="-ad of the timed Monte Carlo mode")
    ap.add_argument("--ref-samples", type=int, default=16384, help="candela reference samples per point")
    ap.add_argument("--ref-seeds", type=int, default=2)
    ap.add_argument("--ref-ad", type=int, default=512, help="-ad of each Radiance reference run")
    ap.add_argument("--ref-runs", type=int, default=4, help="Radiance reference runs (averaged)")
    ap.add_argument("--ref-ab", type=int, default=16)
    ap.add_argument("--calib-samples", type=int, default=1024, help="candela run that sets its sample counts")
    ap.add_argument("--results", default="results.json", help="file name in target/bench/radiance/")
    ap.add_argument("--fresh-refs", action="store_true")
    ap.add_argument("--radiance-refs-only", action="store_true", help="only make (and cache) Radiance's references")
    ap.add_argument("--quick", action="store_true", help="smoke run: N=6, small references, 1 rep, medium+mc")
    ap.add_argument("--check", action="store_true", help="exit 1 when the references disagree")
    ap.add_argument("--table", metavar="JSON", help="only print the table of a results file")
    a = ap.parse_args()
    if a.table:
        with open(a.table) as f:
            print_table(json.load(f))
        return
    if a.quick:
        a.ns, a.reps, a.settings = "6", 1, "mc,medium"
        a.ref_samples, a.ref_seeds, a.ref_ad, a.ref_runs, a.mc_ad = 8192, 2, 128, 4, 64
    b = Bench(a)
    results = {"settings": vars(a), "presets": PRESETS, "machine": os.uname().nodename, "ns": {}}
    disagree = False
    for n in [x if x == "daylit" else int(x) for x in a.ns.split(",")]:
        b.generate(n)
        if a.radiance_refs_only:
            b.cached(f"refs-radiance-{n}-{b.scene_hash(n)}-{a.ref_ad}ab{a.ref_ab}", a.ref_runs, lambda: b.ref_radiance(n))
            continue
        ref = b.references(n)
        c, sc_rep, sc_spread = combine_candela(ref["candela"])
        r, sr = mean_se([x["values"] for x in ref["radiance"]])
        # candela's error: its reported standard error (what a user sees).
        agree = agreement(c, sc_rep, r, sr)
        if sc_spread:
            agree["candela_reported_over_spread_se"] = statistics.median(x / y for x, y in zip(sc_rep, sc_spread) if y > 0)
        log(f"N={n}: agreement {json.dumps(agree)}")
        if agree["beyond_3sigma"] > max(1, 0.01 * agree["points"]):
            disagree = True
        # The common reference: inverse-variance mean of the two converged grids.
        ref_v, ref_se = [], []
        for ci, si, ri, ti in zip(c, sc_rep, r, sr):
            wc, wr = 1 / si**2, 1 / ti**2
            ref_v.append((wc * ci + wr * ri) / (wc + wr))
            ref_se.append(math.sqrt(1 / (wc + wr)))
        entry = {"agreement": agree, "reference_E_avg": sum(ref_v) / len(ref_v), "timed": {}}
        results["ns"][str(n)] = entry
        # candela's calibration run: error at calib-samples, then RMS^2 ~ 1/samples.
        cal = b.run_candela(n, a.calib_samples, 7, "calib")
        cal_rms = rel_rms(cal["values"], ref_v, ref_se)[0]
        entry["candela_calibration"] = {"samples": a.calib_samples, "rel_rms": cal_rms, "wall_s": cal["wall_s"]}
        log(f"N={n}: candela {a.calib_samples} samples/point: rel. RMS {cal_rms:.4%} in {cal['wall_s']:.2f} s")
        pre = dict(x.split("=", 1) for x in a.precomputed.split(",")) if a.precomputed else {}
        for setting in a.settings.split(",") + [k for k in pre if k not in a.settings.split(",")]:
            args = mc_args(a.mc_ad, 12) if setting == "mc" else PRESETS.get(setting, "")
            log(f"N={n}: {setting}: {args}")
            rad_runs, can_runs = [], []
            samples = None
            for rep in range(a.reps_high if setting == "high" and setting not in pre else a.reps):
                # rtrace seeds its random numbers itself (repeated runs differ): no dummy points here.
                rr = b.load_radiance(pre[setting]) if setting in pre else b.run_radiance(n, args, a.threads, 0)
                rr["rel_rms"], rr["rel_rms_raw"] = rel_rms(rr["values"], ref_v, ref_se)
                rr["bias"] = bias(rr["values"], ref_v)
                del rr["values"]
                rad_runs.append(rr)
                if samples is None:
                    # Samples for candela's RMS to equal this setting's (from the first run).
                    samples = max(16, math.ceil(a.calib_samples * (cal_rms / max(rr["rel_rms"], 1e-6)) ** 2))
                cr = b.run_candela(n, samples, 100 + rep, f"timed-{setting}")
                cr["rel_rms"], cr["rel_rms_raw"] = rel_rms(cr["values"], ref_v, ref_se)
                cr["bias"] = bias(cr["values"], ref_v)
                del cr["values"], cr["stderr"]
                can_runs.append(cr)
                log(f"  rep {rep}: Radiance {rr['wall_s']:.2f} s rel. RMS {rr['rel_rms']:.3%} (bias {rr['bias']:+.3%}); "
                    f"candela {samples} samples {cr['wall_s']:.3f} s (CPU {cr['cpu_s']:.2f} s; Radiance CPU {rr['cpu_s']:.1f} s) rel. RMS {cr['rel_rms']:.3%}")
            tr = [x["wall_s"] for x in rad_runs]
            tc = [x["wall_s"] for x in can_runs]
            cr_ = [x["cpu_s"] for x in rad_runs]
            cc_ = [x["cpu_s"] for x in can_runs]
            entry["timed"][setting] = {
                "args": args,
                "radiance": rad_runs,
                "candela": can_runs,
                "candela_samples": samples,
                "radiance_time_median": statistics.median(tr), "radiance_time_min": min(tr), "radiance_time_max": max(tr),
                "radiance_rms_median": statistics.median(x["rel_rms"] for x in rad_runs),
                "radiance_bias_median": statistics.median(x["bias"] for x in rad_runs),
                "candela_time_median": statistics.median(tc), "candela_time_min": min(tc), "candela_time_max": max(tc),
                "candela_rms_median": statistics.median(x["rel_rms"] for x in can_runs),
                "radiance_cpu_median": statistics.median(cr_), "candela_cpu_median": statistics.median(cc_),
                "cpu_ratio_median": statistics.median(cr_) / statistics.median(cc_),
                "ratio_median": statistics.median(tr) / statistics.median(tc),
                "ratio_min": min(tr) / max(tc), "ratio_max": max(tr) / min(tc),
            }
            # Saved after every setting, so an interrupted run keeps what it measured.
            results["ns"][str(n)] = entry
            with open(os.path.join(b.out, a.results), "w") as f:
                json.dump(results, f, indent=1)
    if not a.radiance_refs_only:
        print_table(results)
    if a.check and disagree:
        sys.exit(1)


def equal_rms(t):
    """CPU-time ratio with candela's time scaled to exactly Radiance's RMS (time ~ 1/RMS^2)."""
    return t["cpu_ratio_median"] * (t["radiance_rms_median"] / t["candela_rms_median"]) ** 2


def ratio(x):
    return f"{x:.1f}" if x < 10 else f"{x:.0f}"


def print_table(results):
    print("| N | candela − Radiance, converged (points > 3σ) | Radiance setting | Radiance wall s | Radiance rel. RMS (bias) "
          "| candela samples/point | candela wall s | candela rel. RMS | wall-time ratio | CPU-time ratio | CPU-time ratio at equal RMS |")
    print("|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for n, e in results["ns"].items():
        ag = e["agreement"]
        first = True
        for setting, t in e["timed"].items():
            agree = (f"{ag['mean_rel_diff']:+.2%} ± {ag['se_mean_rel_diff']:.2%} ({ag['beyond_3sigma']}/{ag['points']})"
                     if first else "")
            reps = len(t["radiance"])
            print(f"| {n if first else ''} | {agree} | {setting} ({reps} run{'s' if reps > 1 else ''}) | "
                  f"{t['radiance_time_median']:.1f} ({t['radiance_time_min']:.1f}–{t['radiance_time_max']:.1f}); CPU {t['radiance_cpu_median']:.2f} | "
                  f"{t['radiance_rms_median']:.2%} ({t['radiance_bias_median']:+.2%}) | {t['candela_samples']} | "
                  f"{t['candela_time_median']:.2f} ({t['candela_time_min']:.2f}–{t['candela_time_max']:.2f}); CPU {t['candela_cpu_median']:.2f} | "
                  f"{t['candela_rms_median']:.2%} | {ratio(t['ratio_median'])}× ({ratio(t['ratio_min'])}–{ratio(t['ratio_max'])}) | "
                  f"{ratio(t['cpu_ratio_median'])}× | **{ratio(equal_rms(t))}×** |")
            first = False


if __name__ == "__main__":
    main()
