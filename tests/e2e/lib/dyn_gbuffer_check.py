#!/usr/bin/env python3
"""obscura gbuffer --dynamic against the model (tests/e2e/dynamic.sh):

    dyn_gbuffer_check.py STATIC.exr DYNAMIC.exr MODEL.json linear|quadratic

STATIC.exr is the level alone, DYNAMIC.exr the level with the dynamic
object, both through one camera.  The object's pixels are those whose depth
(Z) differs (elsewhere the same fragment wins, bit for bit); there _AO, _AO_SHORT and _AO_LONG must be the model
evaluated by the independent reader (dyn_eval.py) at the pixel's P and
N; everywhere else the channels must be STATIC's, bit for bit.  Prints
the counts and the worst differences; exits 1 when a check fails."""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import dyn_eval  # noqa: E402
import exr_read  # noqa: E402


def main():
    w, h, s = exr_read.read(sys.argv[1])
    w2, h2, d = exr_read.read(sys.argv[2])
    model = json.load(open(sys.argv[3]))
    order = sys.argv[4]
    assert (w, h) == (w2, h2), "sizes differ"
    names = ("_AO_SHORT", "_AO_LONG", "_AO")
    dyn = stat = 0
    worst_dyn = worst_stat = 0.0
    values = []
    for i in range(w * h):
        if d["Z"][i] != s["Z"][i]:  # another fragment won: the object's
            p = [d["P." + a][i] for a in "XYZ"]
            n = [d["N." + a][i] for a in "XYZ"]
            want = dyn_eval.evaluate(model, p, n, order)
            for k in range(3):
                worst_dyn = max(worst_dyn, abs(d[names[k]][i] - want[k]))
            values.append(want[2])
            dyn += 1
        else:
            for c in names:
                worst_stat = max(worst_stat, abs(d[c][i] - s[c][i]))
            stat += 1
    spread = max(values) - min(values) if values else 0.0
    print("dynamic pixels %d (AO %.4f .. %.4f), worst |gbuffer - model| %.2e; static pixels %d, "
          "worst |with - without the object| %.2e" %
          (dyn, min(values or [0]), max(values or [0]), worst_dyn, stat, worst_stat))
    ok = dyn > 200 and stat > 200 and worst_dyn < 2e-5 and worst_stat == 0.0 and spread > 0.01
    sys.exit(0 if ok else 1)


main()
