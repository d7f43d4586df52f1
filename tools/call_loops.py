#!/usr/bin/env python3
"""Finds source files that call each other in a loop.

Reads the symbol tables of the given object files with `nm`: file A uses
file B when A's object leaves undefined a symbol that B's object defines.
A loop is a strongly connected component of that graph with more than one
file (Tarjan's algorithm).  Prints each loop with the symbols that close it
and exits 1 when there is one; exits 0 and prints the file count when the
graph has none.

    tools/call_loops.py build/obj/core build/obj/daemon
"""
import os
import subprocess
import sys


def objects(paths):
    for p in paths:
        if os.path.isdir(p):
            for root, _, files in os.walk(p):
                for f in sorted(files):
                    if f.endswith(".o"):
                        yield os.path.join(root, f)
        else:
            yield p


def symbols(obj):
    out = subprocess.run(["nm", "-P", obj], check=True, capture_output=True, text=True).stdout
    defined, undefined = set(), set()
    for line in out.splitlines():
        parts = line.split()
        if len(parts) < 2:
            continue
        name, kind = parts[0], parts[1]
        if kind == "U":
            undefined.add(name)
        elif kind.isupper() or kind in ("u", "v", "w"):
            defined.add(name)
    return defined, undefined


def sccs(nodes, edges):
    index, low, on, stack, out = {}, {}, set(), [], []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def main(argv):
    if len(argv) < 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    objs = sorted(set(objects(argv[1:])))
    if not objs:
        print("call_loops: no object files under " + " ".join(argv[1:]), file=sys.stderr)
        return 2
    defs, undefs, owner = {}, {}, {}
    for o in objs:
        defs[o], undefs[o] = symbols(o)
        for s in defs[o]:
            owner.setdefault(s, o)
    edges = {o: set() for o in objs}
    why = {}
    for o in objs:
        for s in undefs[o]:
            d = owner.get(s)
            if d and d != o:
                edges[o].add(d)
                why.setdefault((o, d), []).append(s)
    loops = [c for c in sccs(objs, edges) if len(c) > 1]
    name = lambda o: os.path.relpath(o)
    for c in loops:
        print("call loop among %d files:" % len(c))
        for a in c:
            for b in c:
                if (a, b) in why:
                    syms = sorted(why[(a, b)])
                    more = " ..." if len(syms) > 4 else ""
                    print("  %s -> %s (%s%s)" % (name(a), name(b), ", ".join(syms[:4]), more))
    if loops:
        return 1
    print("call_loops: no loop among %d object files" % len(objs))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
