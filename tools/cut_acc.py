#!/usr/bin/env python3
"""Cuts a small AC3D fixture out of a TORCS track: every poly OBJECT with
a vertex in a box of the x-z plane, written as the kids of one
world object (TORCS' .acc files have no loc/rot, so positions are world
positions).  Used to make tests/data/levels/aalborg_cut.acc:

    tools/cut_acc.py ../shared/data/levels/torcs/aalborg/aalborg.acc \
        X0 Z0 X1 Z1 > tests/data/levels/aalborg_cut.acc
"""
import sys


def objects(lines):
    """(start, end) line ranges of every OBJECT poly, in file order."""
    starts = [i for i, l in enumerate(lines) if l.startswith("OBJECT")]
    starts.append(len(lines))
    for a, b in zip(starts, starts[1:]):
        if lines[a].split()[1] == "poly":
            yield a, b


def main():
    path, x0, z0, x1, z1 = sys.argv[1], *map(float, sys.argv[2:6])
    lines = open(path, encoding="latin-1").read().splitlines()
    header = [l for l in lines[:lines.index(next(l for l in lines if l.startswith("OBJECT")))]]
    kept = []
    for a, b in objects(lines):
        body = lines[a:b]
        nv = next(i for i, l in enumerate(body) if l.startswith("numvert"))
        n = int(body[nv].split()[1])
        pts = [list(map(float, l.split()[:3])) for l in body[nv + 1:nv + 1 + n]]
        if pts and any(x0 <= p[0] <= x1 and z0 <= p[2] <= z1 for p in pts):
            # kids 0 ends a poly object; drop its texture layers but the base
            kept.append([l for l in body if not (l.startswith("texture") and not l.endswith("base"))])
    out = header + ["OBJECT world", "kids %d" % len(kept)]
    for body in kept:
        out += body
    sys.stdout.write("\n".join(out) + "\n")
    sys.stderr.write("%d objects kept\n" % len(kept))


main()
