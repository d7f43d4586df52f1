#!/usr/bin/env python3
"""Finds source files that depend on each other in a loop.

A file depends on another in three ways, and all three are edges here:

  calls     A's object leaves undefined a symbol that B's object defines
            (the symbol tables, read with `nm`);
  includes  A's source includes B's header (B.h beside B.c; a header with
            no .c of its own is a node by itself, and its own includes are
            its edges), the project's public headers (include/) aside;
  inline    A's source calls a `static inline` function that B's header
            defines (no symbol is left for nm to see).

A loop is a strongly connected component of that graph with more than one
node (Tarjan's algorithm).  Prints each loop with the edges that close it
and exits 1 when there is one; exits 0 and prints the counts when there is
none.

With --internal, the objects given are outside core/ (daemon, protocol,
clients): a call of core's internal `obs__` names, or an include of a
header under core/, is reported as a breach of the internal-name rule and
exits 1.

    tools/call_loops.py build/obj/core
    tools/call_loops.py --internal build/obj/daemon
"""
import os
import re
import subprocess
import sys

INCLUDE_RE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)
INLINE_RE = re.compile(r'static\s+inline\s+[\w\s\*]*?\b(\w+)\s*\(', re.M)
COMMENT_RE = re.compile(r'/\*.*?\*/|//[^\n]*', re.S)
STRING_RE = re.compile(r'"(?:\\.|[^"\\\n])*"')
# Where #include "x" is looked up, after the including file's own folder:
# the build's -I folders (Makefile, protocol.mk, daemon.mk, clients.mk).
SEARCH = ["include", "core", "protocol", "clients", "daemon"]


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


def source_of(obj):
    """build/obj/core/chain/frame.o -> core/chain/frame.c (or .cpp)."""
    rel = obj.split("/obj/", 1)[-1][:-2]
    for ext in (".c", ".cpp"):
        if os.path.exists(rel + ext):
            return rel + ext
    return None


def code_of(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        text = f.read()
    return text, STRING_RE.sub('""', COMMENT_RE.sub(" ", text))


def resolve(name, here):
    for d in [os.path.dirname(here)] + SEARCH:
        p = os.path.normpath(os.path.join(d, name))
        if os.path.exists(p):
            return p
    return None  # generated (build/gen) or a system header


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


class Graph:
    """Nodes are sources (a .c with the header of its own name) and the
    headers that have no .c; edges carry the reasons that made them."""

    def __init__(self, sources):
        self.sources = set(sources)
        self.edges, self.why, self.nodes = {}, {}, set()
        self.inline_owner = {}
        self.seen = set()

    def node(self, path):
        stem, ext = os.path.splitext(path)
        if ext == ".h":
            for e in (".c", ".cpp"):
                if stem + e in self.sources:
                    path = stem + e
                    break
        self.nodes.add(path)
        self.edges.setdefault(path, set())
        return path

    def add(self, a, b, reason):
        a, b = self.node(a), self.node(b)
        if a != b:
            self.edges[a].add(b)
            self.why.setdefault((a, b), set()).add(reason)

    def scan(self, path):
        """Include and inline edges of one file, and of the headers it names."""
        if path in self.seen:
            return
        self.seen.add(path)
        self.node(path)
        text, code = code_of(path)
        for inc in INCLUDE_RE.findall(text):
            h = resolve(inc, path)
            if not h or h.startswith("include" + os.sep):
                continue
            self.add(path, h, "includes " + inc)
            self.scan(h)
        if path.endswith(".h"):
            for fn in INLINE_RE.findall(code):
                self.inline_owner.setdefault(fn, path)

    def inline_calls(self):
        if not self.inline_owner:
            return
        call = re.compile(r'\b(' + "|".join(map(re.escape, self.inline_owner)) + r')\s*\(')
        for path in sorted(self.seen):
            _, code = code_of(path)
            for fn in set(call.findall(code)):
                h = self.inline_owner[fn]
                if self.node(h) != self.node(path):
                    self.add(path, h, "inline " + fn)


def internal_breaches(objs):
    bad = []
    for o in objs:
        _, undef = symbols(o)
        calls = sorted(s for s in undef if s.startswith("obs__"))
        src = source_of(o)
        incs = []
        if src:
            text, _ = code_of(src)
            for inc in INCLUDE_RE.findall(text):
                h = resolve(inc, src)
                if h and h.startswith("core" + os.sep):
                    incs.append(inc)
        if calls or incs:
            bad.append((src or o, calls, incs))
    return bad


def main(argv):
    internal = "--internal" in argv
    args = [a for a in argv[1:] if a != "--internal"]
    if not args:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    objs = sorted(set(objects(args)))
    if not objs:
        print("call_loops: no object files under " + " ".join(args), file=sys.stderr)
        return 2
    if internal:
        bad = internal_breaches(objs)
        for src, calls, incs in bad:
            what = []
            if calls:
                what.append("calls " + ", ".join(calls[:4]) + (" ..." if len(calls) > 4 else ""))
            if incs:
                what.append("includes " + ", ".join(incs))
            print("call_loops: %s uses core's internals: %s" % (src, "; ".join(what)))
        if bad:
            return 1
        print("call_loops: %d object files use only the public headers and names" % len(objs))
        return 0

    src = {o: source_of(o) or o for o in objs}
    g = Graph([s for s in src.values() if not s.endswith(".o")])
    defs, undefs, owner = {}, {}, {}
    for o in objs:
        defs[o], undefs[o] = symbols(o)
        for s in defs[o]:
            owner.setdefault(s, o)
    for o in objs:
        g.node(src[o])
        for s in undefs[o]:
            d = owner.get(s)
            if d and d != o:
                g.add(src[o], src[d], "calls " + s)
        if not src[o].endswith(".o"):
            g.scan(src[o])
    g.inline_calls()
    loops = [c for c in sccs(g.nodes, g.edges) if len(c) > 1]
    for c in loops:
        print("loop among %d files:" % len(c))
        for a in c:
            for b in c:
                if (a, b) in g.why:
                    rs = sorted(g.why[(a, b)])
                    more = " ..." if len(rs) > 3 else ""
                    print("  %s -> %s (%s%s)" % (a, b, ", ".join(rs[:3]), more))
    if loops:
        return 1
    n_edges = sum(len(e) for e in g.edges.values())
    print("call_loops: no loop among %d files (%d dependencies: calls, internal includes, "
          "inline calls)" % (len(g.nodes), n_edges))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
