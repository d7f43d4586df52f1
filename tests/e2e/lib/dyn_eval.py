#!/usr/bin/env python3
"""An engine's reader of obscura's dynamic-object model (README, "Dynamic
"), written from the documentation alone: the region holding
the point (else the nearest, the point clamped into it), eq 4 there, the
SH for the normal.  Prints the blended AO; evaluate() for other scripts.

    dyn_eval.py MODEL.json X,Y,Z NX,NY,NZ linear|quadratic
"""
import json
import math
import sys


def sh9(x, y, z):
    return [0.28209479177387814, 0.4886025119029199 * y, 0.4886025119029199 * z,
            0.4886025119029199 * x, 1.0925484305920792 * x * y, 1.0925484305920792 * y * z,
            0.31539156525252005 * (3 * z * z - 1), 1.0925484305920792 * x * z,
            0.5462742152960396 * (x * x - y * y)]


def evaluate(d, p, n, order):
    """(short, long, blended) AO of model d at point p for the normal n,
    order "linear" or "quadratic"."""
    k = 4 if order == "linear" else 9
    regs = d["regions"]
    hit = next((r for r in regs if r["model"] >= 0 and
                all(r["min"][a] <= p[a] <= r["max"][a] for a in range(3))), None)
    if hit is None:
        def dist(r):
            return sum(max(r["min"][a] - p[a], 0, p[a] - r["max"][a]) ** 2 for a in range(3))
        hit = min((r for r in regs if r["model"] >= 0), key=dist)
        p = [min(max(p[a], hit["min"][a]), hit["max"][a]) for a in range(3)]
    m = d["models"][hit["model"]]
    q = [p[a] - m["center"][a] for a in range(3)]
    ch = []
    for c in m["coefficients"]:
        v = c[0]
        for i in range(3):
            v += q[i] * (c[1 + 2 * i] if q[i] >= 0 else c[2 + 2 * i])
        ch.append(v)
    ln = math.sqrt(sum(v * v for v in n))
    y = sh9(*[v / ln for v in n])
    ao = [min(max(sum(ch[9 * j + i] * y[i] for i in range(k)), 0.0), 1.0) for j in range(2)]
    b = d["blend"]
    return ao[0], ao[1], min(max(b * ao[0] + (1 - b) * ao[1], 0.0), 1.0)


def main():
    d = json.load(open(sys.argv[1]))
    p = [float(v) for v in sys.argv[2].split(",")]
    n = [float(v) for v in sys.argv[3].split(",")]
    print("%.6f" % evaluate(d, p, n, sys.argv[4])[2])


if __name__ == "__main__":
    main()
