"""bench/hair.py — rayes's physicalhair against Cycles's Principled Hair.

Each case is a ball of cubic strands around a grey sphere (strand i's
root, direction and droop from a fixed seed, radius 0.004 at the root to
0.002 at the tip), lit by a sun (irradiance 3 from (3, 4, 2)) and a grey
sky (0.3 0.3 0.35). The same strands are written as a pbrt-v4 file for
rayes (`curve` shapes, cubic Bezier) and handed to Blender, which builds
them as hair curves (each Bezier sampled at 17 points, bench/hair_cycles.py)
under a Principled Hair BSDF with the same absorption, roughness, index
and tilt. pbrt is left-handed: Cycles's image is mirrored to match.

Cases (--cases, comma separated): sparse (300 strands, sigma_a of
eumelanin 0.3), sparse0 (the same, direct light only), dense (4,000
strands, eumelanin 0.3), dark (eumelanin 1.3, pbrt's default), light
(reflectance .85 .6 .35). Options: --size 256, --spp 64 (rayes),
--cycles-spp 512, --bounces 8, --quality preview, --threads 2,
--out bench-out/hair. Prints per case the means over the ball (a disc of
0.4 of the image about its centre) and their ratio, CPU seconds of each,
and the worst of 4 x 4 regions.
"""
import json
import math
import os
import random
import resource
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EU = (0.419, 0.697, 1.37)  # pbrt's eumelanin sigma_a per unit concentration


def melanin(c):
    return [c * x for x in EU]


def from_reflectance(c, bn=0.3):
    d = 5.969 - 0.215 * bn + 2.532 * bn ** 2 - 10.73 * bn ** 3 + 5.574 * bn ** 4 + 0.245 * bn ** 5
    return [(math.log(x) / d) ** 2 for x in c]


CASES = {
    "sparse": (300, melanin(0.3), None),
    "sparse0": (300, melanin(0.3), 0),
    "dense": (4000, melanin(0.3), None),
    "dark": (4000, melanin(1.3), None),
    "light": (4000, from_reflectance((0.85, 0.6, 0.35)), None),
}


def parse(argv):
    opt = {"size": "256", "spp": "64", "cycles-spp": "512", "bounces": "8", "quality": "preview",
           "threads": "2", "cases": "sparse0,sparse,dense,dark,light",
           "out": os.path.join(ROOT, "bench-out", "hair")}
    for i in range(0, len(argv), 2):
        key = argv[i].lstrip("-")
        if key not in opt or i + 1 >= len(argv):
            sys.exit("hair: unknown option or missing value: %s (see bench/hair.py)" % argv[i])
        opt[key] = argv[i + 1]
    return opt


def strands(n):
    """Control points of n cubic Bezier strands (pbrt's coordinates)."""
    rnd = random.Random(7)
    out = []
    for _ in range(n):
        z = rnd.uniform(-1, 1)
        phi = rnd.uniform(0, 2 * math.pi)
        r = math.sqrt(1 - z * z)
        d = (r * math.cos(phi), r * math.sin(phi), z)
        cps = []
        for k in range(4):
            t = k / 3.0
            p = [0.5 * d[j] + 0.45 * t * d[j] for j in range(3)]
            p[1] -= 0.25 * t * t
            cps.append(p)
        out.append(cps)
    return out


def write_pbrt(path, n, sigma, size, bounces):
    lines = ['LookAt 0 0.3 4  0 0 0  0 1 0', 'Camera "perspective" "float fov" 30',
             'Film "rgb" "integer xresolution" %s "integer yresolution" %s' % (size, size),
             'Integrator "volpath" "integer maxdepth" %d' % max(bounces, 1), 'WorldBegin',
             'LightSource "infinite" "rgb L" [0.3 0.3 0.35]',
             'LightSource "distant" "point3 from" [3 4 2] "point3 to" [0 0 0] "rgb L" [3 3 3]',
             'AttributeBegin', 'Material "diffuse" "rgb reflectance" [0.4 0.4 0.4]',
             'Shape "sphere" "float radius" 0.5', 'AttributeEnd', 'AttributeBegin',
             'Material "hair" "rgb sigma_a" [%g %g %g]' % tuple(sigma)]
    for cps in strands(n):
        pts = " ".join("%.6f" % c for p in cps for c in p)
        lines.append('Shape "curve" "string type" "cylinder" "point3 P" [%s] '
                     '"float width0" 0.008 "float width1" 0.004' % pts)
    lines.append('AttributeEnd')
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def read(path):
    inp = oiio.ImageInput.open(path)
    if not inp:
        sys.exit("hair: cannot read %s: %s" % (path, oiio.geterror()))
    px = inp.read_image("float")
    inp.close()
    return np.asarray(px, dtype=np.float64)[:, :, :3]


def child_cpu():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def run(cmd, quiet=True):
    c0 = child_cpu()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL if quiet else None)
    return child_cpu() - c0


def main():
    opt = parse(sys.argv[1:])
    os.makedirs(opt["out"], exist_ok=True)
    size = int(opt["size"])
    print("| case | bounces | rayes mean (R G B) | Cycles mean | ratio | worst region | rayes CPU | Cycles CPU |")
    print("|---|---|---|---|---|---|---|---|")
    for name in [c for c in opt["cases"].split(",") if c]:
        if name not in CASES:
            sys.exit("hair: unknown case %s (%s)" % (name, ", ".join(CASES)))
        n, sigma, bounces = CASES[name]
        b = int(opt["bounces"]) if bounces is None else bounces
        scene = os.path.join(opt["out"], name + ".pbrt")
        write_pbrt(scene, n, sigma, size, b)
        mine = os.path.join(opt["out"], name + "-rayes.exr")
        cpu_r = run([os.path.join(ROOT, "build", "rayes"), "render", scene, "--res", opt["size"],
                     "--spp", opt["spp"], "--bounces", str(b), "--quality", opt["quality"],
                     "--threads", opt["threads"], "--quiet", "-o", mine])
        theirs = os.path.join(opt["out"], name + "-cycles.exr")
        cfg = os.path.join(opt["out"], name + "-cycles.json")
        with open(cfg, "w") as f:
            json.dump({"strands": strands(n), "sigma_a": sigma, "size": size, "bounces": b,
                       "samples": int(opt["cycles-spp"]), "threads": int(opt["threads"]),
                       "out": theirs}, f)
        cpu_c = run(["blender", "-b", "--factory-startup", "--python",
                     os.path.join(ROOT, "bench", "hair_cycles.py"), "--", cfg])
        a, c = read(mine), read(theirs)[:, ::-1]  # Cycles's image mirrored: pbrt is left-handed
        yy, xx = np.mgrid[0:size, 0:size]
        disc = (xx - size / 2) ** 2 + (yy - size / 2) ** 2 < (0.4 * size) ** 2
        ma, mc = a[disc].mean(0), c[disc].mean(0)
        q = size // 4
        worst = max((abs(a[y:y + q, x:x + q].mean() / c[y:y + q, x:x + q].mean() - 1), y // q, x // q)
                    for y in range(0, size, q) for x in range(0, size, q))
        print("| %s | %d | %.4f %.4f %.4f | %.4f %.4f %.4f | %.3f %.3f %.3f | %.1f%% (row %d, col %d) "
              "| %.1f s | %.1f s |" % ((name, b) + tuple(ma) + tuple(mc) + tuple(ma / mc) +
                                       (100 * worst[0], worst[1], worst[2], cpu_r, cpu_c)), flush=True)


if __name__ == "__main__":
    main()
