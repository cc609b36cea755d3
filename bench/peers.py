#!/usr/bin/python3
"""bench/peers.py — rayes against Blender's Cycles on cornell-teapots, at a
sweep of samples, each image against its renderer's own converged reference
and against the other's (issue 21, item 3; docs/performance.md, "Against
Cycles"). Run through bench/peers, which builds rayes first.

    bench/peers [--size 256] [--bounces 1] [--threads 2] [--data DIR]
                [--cycles 16,64,256,1024] [--cycles-ref 4096]
                [--preview 4,16,64,256] [--final 4,16] [--ref-spp 1024]
                [--one-ray 64,256]
                [--adaptive 0.1,0.05,0.02,0.01] [--adaptive-spp 16]
                [--adaptive-max 1024] [--grid 0.4,0.3,0.2,0.1] [--grid-rays 8,24,4]
                [--reuse 0|1] [--out bench-out/peers]

Cycles renders the scene of ../shared/data/cornell-teapots.md built by
bench/peers_cycles.py with matched light transport: the same diffuse
bounces, 4 glossy, caustics off, no clamping, no denoising, no adaptive
sampling, a one-pixel box filter. rayes renders the built-in
cornell-teapots in its preview and final presets, the preview with one
shadow and one diffuse ray a camera hit (--one-ray), and the preview with
adaptive pixel sampling (--adaptive-spp samples everywhere, up to
--adaptive-max, at each listed --adaptive-error: a pixel stops when its
standard error is the error asked times the lesser of its mean and the
frame's, its variance at least its 3 x 3 neighbourhood's first block's,
its positions one Owen-scrambled Sobol sequence; DESIGN.md "Adaptive pixel
sampling"), and the grid hider (REYES: every grid shaded once at its
vertices, with --grid-rays shadow and diffuse rays a vertex and diffuse
rays a deeper hit (the preview's 4); sharp mirrors
and highlights shaded per sample; DESIGN.md "The grid hider") with the
same adaptive sampling at each --grid error. Non-adaptive rows are
unchanged by that rule (the same bytes),
so --reuse 1 keeps them. rayes's reference is the
preview's uncached estimator at --ref-spp pixel samples (4 diffuse and 4
shadow rays a hit: 4 x ref-spp paths a pixel, nothing cached); Cycles's is
--cycles-ref samples. Errors are relative RMSE (RMSE over RGB and pixels,
over the reference's mean). CPU seconds are the renderer's process time
over its renders (Cycles: its render calls, every thread; rayes: the
process, preparing included). The CPU seconds to reach 5%, 2% and 1% are
interpolated on the log-log line between the sweep's points around the
crossing (extrapolated as err ~ cpu^-1/2 past the last, marked '~').
With --reuse 1, renders whose image and record are in --out already are
not made again (rayes's beside each image, Cycles's in cycles.json).
"""
import json
import math
import os
import resource
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def parse(argv):
    opt = {"size": "256", "bounces": "1", "threads": "2",
           "data": os.environ.get("RAYES_DATA", os.path.join(ROOT, "..", "shared", "data")),
           "cycles": "16,64,256,1024", "cycles-ref": "4096", "preview": "4,16,64,256",
           "final": "4,16", "ref-spp": "1024", "one-ray": "64,256", "adaptive": "0.1,0.05,0.02,0.01",
           "adaptive-spp": "16", "adaptive-max": "1024", "grid": "0.4,0.3,0.2,0.1",
           "grid-rays": "8,24,4", "reuse": "0",
           "out": os.path.join(ROOT, "bench-out", "peers")}
    for i in range(0, len(argv), 2):
        key = argv[i].lstrip("-")
        if key not in opt or i + 1 >= len(argv):
            sys.exit("peers: unknown option or missing value: %s (see bench/peers.py)" % argv[i])
        opt[key] = argv[i + 1]
    return opt


def counts(s):
    return [int(x) for x in s.split(",") if x]


def read(path):
    inp = oiio.ImageInput.open(path)
    if not inp:
        sys.exit("peers: cannot read %s: %s" % (path, oiio.geterror()))
    px = inp.read_image("float")
    inp.close()
    return np.asarray(px, dtype=np.float64)[:, :, :3]


def rel_rmse(img, ref):
    return float(np.sqrt(np.mean((img - ref) ** 2)) / np.mean(ref))


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def rayes(opt, tag, spp, extra, name=None):
    """Renders with rayes; returns (image path, CPU seconds of the process)."""
    path = os.path.join(opt["out"], "rayes-%s-%s.exr" % (tag, name or spp))
    record = path + ".json"
    if opt["reuse"] == "1" and os.path.exists(path) and os.path.exists(record):
        with open(record) as f:
            return path, json.load(f)["cpu_s"]
    cmd = [os.path.join(ROOT, "build", "rayes"), "render", "cornell-teapots", "--data", opt["data"],
           "--res", opt["size"], "--spp", str(spp), "--bounces", opt["bounces"],
           "--threads", opt["threads"], "--quiet", "-o", path] + extra
    c0 = child_cpu()
    subprocess.run(cmd, check=True)
    cpu = child_cpu() - c0
    with open(record, "w") as f:
        json.dump({"cmd": cmd[1:], "cpu_s": cpu}, f)
    print("peers: rayes %s %s, %.2f s cpu" % (tag, name or "%d spp" % spp, cpu), flush=True)
    return path, cpu


def time_to(points, target):
    """CPU seconds at which err falls to target along (cpu, err) points."""
    pts = sorted(points)
    for (c0, e0), (c1, e1) in zip(pts, pts[1:]):
        if e0 > target >= e1 and e0 > 0 and e1 > 0:
            f = math.log(e0 / target) / math.log(e0 / e1)
            return math.exp(math.log(c0) + f * math.log(c1 / c0)), ""
    if pts and pts[0][1] <= target:
        return pts[0][0], "<"
    if pts:
        c, e = pts[-1]
        return c * (e / target) ** 2, "~"
    return float("nan"), "?"


def main():
    opt = parse(sys.argv[1:])
    os.makedirs(opt["out"], exist_ok=True)
    cyc = counts(opt["cycles"]) + [int(opt["cycles-ref"])]
    done = {}
    if opt["reuse"] == "1" and os.path.exists(os.path.join(opt["out"], "cycles.json")):
        with open(os.path.join(opt["out"], "cycles.json")) as f:
            done = {r["spp"]: r for r in json.load(f) if os.path.exists(r["image"])}
    missing = [c for c in cyc if c not in done]
    if missing:
        subprocess.run(["blender", "-b", "--factory-startup", "--python",
                    os.path.join(ROOT, "bench", "peers_cycles.py"), "--", "--data", opt["data"],
                    "--size", opt["size"], "--bounces", opt["bounces"], "--threads",
                    opt["threads"], "--out", opt["out"], "--samples",
                    ",".join(str(c) for c in missing)], check=True, stdout=subprocess.DEVNULL)
        with open(os.path.join(opt["out"], "cycles.json")) as f:
            done.update({r["spp"]: r for r in json.load(f)})
        with open(os.path.join(opt["out"], "cycles.json"), "w") as f:
            json.dump(list(done.values()), f, indent=1)
    cycles = done
    ref_cycles = read(cycles[int(opt["cycles-ref"])]["image"])
    rows = []
    for spp in counts(opt["cycles"]):
        rows.append(("cycles", spp, cycles[spp]["cpu_s"], read(cycles[spp]["image"])))
    ref_path, ref_cpu = rayes(opt, "reference", int(opt["ref-spp"]),
                              ["--quality", "preview", "--cache", "off"])
    ref_rayes = read(ref_path)
    for tag, preset in (("preview", "preview"), ("final", "final")):
        for spp in counts(opt[tag]):
            path, cpu = rayes(opt, tag, spp, ["--quality", preset])
            rows.append((tag, spp, cpu, read(path)))
    for spp in counts(opt["one-ray"]):
        path, cpu = rayes(opt, "one-ray", spp, ["--quality", "preview", "--shadow-rays", "1",
                                                "--diffuse-rays", "1"])
        rows.append(("one-ray", spp, cpu, read(path)))
    for e in [float(x) for x in opt["adaptive"].split(",") if x]:
        path, cpu = rayes(opt, "adaptive", int(opt["adaptive-spp"]),
                          ["--quality", "preview", "--max-spp", opt["adaptive-max"],
                           "--adaptive-error", "%g" % e], name="e%g" % e)
        rows.append(("adaptive", "e%g" % e, cpu, read(path)))
    shadow, diffuse, deep = counts(opt["grid-rays"])
    for e in [float(x) for x in opt["grid"].split(",") if x]:
        path, cpu = rayes(opt, "grid", int(opt["adaptive-spp"]),
                          ["--quality", "preview", "--hider", "grid", "--shadow-rays", str(shadow),
                           "--diffuse-rays", str(diffuse), "--diffuse-rays-deep", str(deep),
                           "--max-spp", opt["adaptive-max"],
                           "--adaptive-error", "%g" % e], name="s%dd%de%g" % (shadow, diffuse, e))
        rows.append(("grid", "e%g" % e, cpu, read(path)))

    print()
    print("cornell-teapots %sx%s, %s diffuse bounce(s), %s threads; relative RMSE against each "
          "renderer's own reference and against the other's" % (opt["size"], opt["size"],
                                                                 opt["bounces"], opt["threads"]))
    print("%-8s %6s %9s | %9s %9s" % ("mode", "spp/err", "cpu s", "own ref", "other ref"))
    record = {"size": int(opt["size"]), "bounces": int(opt["bounces"]),
              "threads": int(opt["threads"]), "rows": [], "time_to": {}}
    for tag, spp, cpu, img in rows:
        own, other = (ref_cycles, ref_rayes) if tag == "cycles" else (ref_rayes, ref_cycles)
        e_own, e_other = rel_rmse(img, own), rel_rmse(img, other)
        print("%-8s %6s %9.2f | %8.2f%% %8.2f%%" % (tag, spp, cpu, 100 * e_own, 100 * e_other))
        record["rows"].append({"mode": tag, "spp": spp, "cpu_s": cpu, "rmse_own": e_own,
                               "rmse_other": e_other})
    m_c, m_r = float(np.mean(ref_cycles)), float(np.mean(ref_rayes))
    between = rel_rmse(ref_rayes, ref_cycles)
    print("references: Cycles %s samples %.1f s cpu, rayes %s spp uncached %.1f s cpu; means "
          "%.5f and %.5f (rayes/Cycles %.4f), relative RMSE between them %.2f%%"
          % (opt["cycles-ref"], cycles[int(opt["cycles-ref"])]["cpu_s"], opt["ref-spp"], ref_cpu,
             m_c, m_r, m_r / m_c, 100 * between))
    record["references"] = {"cycles_mean": m_c, "rayes_mean": m_r, "rmse_between": between,
                            "cycles_cpu_s": cycles[int(opt["cycles-ref"])]["cpu_s"],
                            "rayes_cpu_s": ref_cpu}
    print()
    print("CPU seconds to reach a relative RMSE (own reference; '~' extrapolated, '<' at the "
          "first point already)")
    print("%-8s %10s %10s %10s" % ("mode", "5%", "2%", "1%"))
    for tag in ("cycles", "preview", "final", "one-ray", "adaptive", "grid"):
        pts = [(r["cpu_s"], r["rmse_own"]) for r in record["rows"] if r["mode"] == tag]
        cells, rec = [], {}
        for target in (0.05, 0.02, 0.01):
            t, mark = time_to(pts, target)
            cells.append("%s%.1f" % (mark, t))
            rec["%g" % target] = {"cpu_s": t, "mark": mark}
        record["time_to"][tag] = rec
        print("%-8s %10s %10s %10s" % (tag, *cells))
    for target in ("0.05", "0.02", "0.01"):
        best = min(record["time_to"][t][target]["cpu_s"]
                   for t in ("preview", "final", "one-ray", "adaptive", "grid"))
        ratio = record["time_to"]["cycles"][target]["cpu_s"] / best
        print("at %s%%: Cycles / rayes's better preset = %.2f" % (float(target) * 100, ratio))
        record["time_to"]["ratio_" + target] = ratio
    with open(os.path.join(opt["out"], "peers.json"), "w") as f:
        json.dump(record, f, indent=1)
    print("wrote %s" % os.path.join(opt["out"], "peers.json"))


if __name__ == "__main__":
    main()
