#!/usr/bin/env python3
"""Held-out views: the Blender scenes seen from cameras and at AO distances
that no figure of bench/QUALITY.md was measured on, with obscura's own
Embree reference as the truth.

    bench/heldout.py [--obscura build/obscura] [--out out/heldout] [--spp 512]
                     [--methods default,gtao,hemisphere,default@deep,gtao@deep]

For each scene of ../shared/data/blender (room, yard and validation/: the
.obj, its SCENE.json), four views, fixed here before any was measured and
never changed by a result:

  A: the scene's camera turned 25 degrees about the vertical axis through
     its target (counter-clockwise seen from above), at the scene's own AO
     distance D;
  B: turned 25 degrees the other way and 25 % nearer the target, at D;
  A2, B2: the same cameras at D2 = 2 m where D <= 0.5 m, else 0.5 m (the
     distances of the validation scenes run from 0.25 to 2 m).

The walls of the Blender rooms stand at x = -3.05 and y = 3.05 (the
scene script, shared/tools/blender_scene.py), so every camera stays in the
open quadrant they face. Each view: `obscura gbuffer SCENE.obj` (flat
G-buffer, the view's camera), `obscura reference SCENE.obj` (Embree, --spp
rays a pixel, seed 0) and `obscura ao` of every method at the view's
distance (`--radius`, nothing else), scored by `obscura compare` (MSE and
SSIM on the pixels with geometry). A method written M@deep runs on
`obscura gbuffer --deep` of the same view (every fragment, with facing
flags) at the deep chain's defaults, scored on the same pixels (the
truth's). Prints one Markdown table a view and
the means; EEVEE has no render of these views, so the ratios are between
obscura's methods.
"""
import argparse
import json
import math
import os
import subprocess
import sys


def normalize(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def camera_json(pos, target, fov_y, width, height, near=0.05, far=100.0):
    """A camera in the Blender scenes' convention (SCENE.camera.json): world
    Z up, the camera looking down -Z with +Y up, column-vector matrices."""
    f = normalize([t - p for t, p in zip(target, pos)])
    r = normalize(cross(f, [0.0, 0.0, 1.0]))
    u = cross(r, f)
    rows = [r, u, [-x for x in f]]
    w2c = [row + [-sum(a * b for a, b in zip(row, pos))] for row in rows] + [[0.0, 0.0, 0.0, 1.0]]
    t = 1.0 / math.tan(math.radians(fov_y) / 2.0)
    proj = [[t * height / width, 0, 0, 0], [0, t, 0, 0],
            [0, 0, -(far + near) / (far - near), -2 * far * near / (far - near)], [0, 0, -1, 0]]
    return {"width": width, "height": height, "fov_y_deg": fov_y, "near": near, "far": far,
            "world_to_camera": w2c, "projection": proj,
            "convention": "matrices are column-vector (p_cam = M * p_world), rows listed top to "
                          "bottom; camera looks down -Z, +Y up"}


def views(spec):
    cam = spec["camera"]
    pos, target = cam["pos"], cam["target"]
    dx, dy = pos[0] - target[0], pos[1] - target[1]
    rad, az = math.hypot(dx, dy), math.atan2(dy, dx)
    d = spec["ao_distance"]
    d2 = 2.0 if d <= 0.5 else 0.5
    out = []
    for name, turn, scale in (("A", 25.0, 1.0), ("B", -25.0, 0.75)):
        a = az + math.radians(turn)
        p = [target[0] + scale * rad * math.cos(a), target[1] + scale * rad * math.sin(a),
             target[2] + scale * (pos[2] - target[2])]
        out.append((name, p, d))
        out.append((name + "2", p, d2))
    return out


def run(cmd):
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        sys.exit("heldout: failed (%d): %s\n%s" % (r.returncode, " ".join(cmd), r.stderr[-2000:]))
    return r.stdout


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--obscura", default="build/obscura")
    ap.add_argument("--out", default="out/heldout")
    ap.add_argument("--spp", type=int, default=512)
    ap.add_argument("--methods", default="default,gtao,hemisphere,default@deep,gtao@deep")
    ap.add_argument("--shared", default=os.environ.get("OBSCURA_SHARED_DATA", "../shared/data"))
    a = ap.parse_args()
    base = os.path.join(a.shared, "blender")
    if not os.path.isdir(base):
        print("heldout: %s not found: the Blender scenes are not here, nothing measured" % base)
        return 0
    scenes = [os.path.join(base, s) for s in ("room", "yard")]
    vdir = os.path.join(base, "validation")
    scenes += sorted(os.path.join(vdir, f[:-5]) for f in os.listdir(vdir)
                     if f.endswith(".json") and not f.endswith(".camera.json"))
    methods = a.methods.split(",")
    os.makedirs(a.out, exist_ok=True)
    rows, sums = [], {m: [] for m in methods}
    for s in scenes:
        name = os.path.basename(s)
        spec = json.load(open(s + ".json"))
        width, height = spec["res"]
        for vname, pos, dist in views(spec):
            tag = os.path.join(a.out, "%s.%s" % (name, vname))
            with open(tag + ".camera.json", "w") as fh:
                json.dump(camera_json(pos, spec["camera"]["target"], spec["camera"]["fov_y"],
                                      width, height), fh, indent=1)
            cam = ["--camera", tag + ".camera.json"]
            if not os.path.exists(tag + ".gbuffer.exr"):
                run([a.obscura, "gbuffer", s + ".obj", "-o", tag + ".gbuffer.exr", "-q"] + cam)
            if any(m.endswith("@deep") for m in methods) and not os.path.exists(tag + ".deep.exr"):
                run([a.obscura, "gbuffer", s + ".obj", "--deep", "-o", tag + ".deep.exr", "-q"] + cam)
            ref = "%s.ref%g.exr" % (tag, dist)
            if not os.path.exists(ref):
                run([a.obscura, "reference", s + ".obj", "-o", ref, "--distance", str(dist),
                     "--spp", str(a.spp), "--seed", "0", "-q"] + cam)
            row = [name, vname, "%g m" % dist]
            for m in methods:
                meth, _, layers = m.partition("@")
                o = "%s.%s%g.exr" % (tag, m.replace("@", "-"), dist)
                extra = [] if meth == "default" else ["--method", meth]
                src = tag + (".deep.exr" if layers == "deep" else ".gbuffer.exr")
                # a deep EXR carries its camera in its header (gbuffer --deep writes it)
                run([a.obscura, "ao", src, "--radius", str(dist), "--float", "-q", "-o", o]
                    + ([] if layers == "deep" else cam) + extra)
                c = json.loads(run([a.obscura, "compare", ref, o, "--json"]))
                sums[m].append(c["mse"])
                row.append("%.5f / %.4f" % (c["mse"], c["ssim"]))
            rows.append(row)
            print(" | ".join(row), file=sys.stderr)
    print("| scene | view | AO distance | " + " | ".join("%s MSE / SSIM" % m for m in methods) + " |")
    print("|---|---|---|" + "---|" * len(methods))
    for r in rows:
        print("| " + " | ".join(r) + " |")
    n = len(rows)
    means = {m: sum(v) / n for m, v in sums.items()}
    print("\nmean MSE over %d views: " % n
          + ", ".join("%s %.5f" % (m, means[m]) for m in methods))
    if "default" in means:
        print("ratio to default: " + ", ".join("%s %.3f" % (m, means[m] / means["default"])
                                               for m in methods))
    for m in methods:
        flat = m.partition("@")[0]
        if m.endswith("@deep") and flat in sums:
            worse = sum(1 for d, f in zip(sums[m], sums[flat]) if d > f)
            print("%s: %.3f x %s's mean MSE, worse than it on %d of %d views"
                  % (m, means[m] / means[flat], flat, worse, n))
    for m in methods:
        for sub in ("own distance", "other distance"):
            pick = [v for r, v in zip(rows, sums[m]) if (r[1].endswith("2")) == (sub == "other distance")]
            print("%s, %s: mean %.5f over %d views" % (m, sub, sum(pick) / len(pick), len(pick)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
