#!/usr/bin/env python3
"""The include rules of ARCHITECTURE.md, checked on the #include lines.

Every C, C++ and header file of a room is read for its `#include "..."`
lines (system headers, <...>, are not the rooms' business). A header names
its room by where it lives: `<room>/...` for a room's own headers, and for
an installed header `tcb/<name>.h` the room that implements it (OWNER
below; a new installed header must be placed there, or this check fails).
Then:

  1. a room includes only its own headers and those of the rooms it may
     import (IMPORTS below: the layering, lower rooms first; it must stay
     acyclic, which this script checks too);
  2. a room's private headers (`*_internal.h`, and those PRIVATE lists)
     are included only inside that room — and by tests/ and fuzz/, which
     test the room's insides;
  3. library files (every room but cli/) do not include the umbrella
     tcb/tcb.h: each names the headers it uses;
  4. every quoted include resolves to a file of the tree.

Exit 0 when every rule holds, else 1 with one line per violation:
"FILE:LINE: includes HEADER: <rule>". Usage:

    scripts/check_includes.py [ROOT]      (default: the repository)
    scripts/check_includes.py --graph     the room graph as it is
"""
import os
import re
import sys

# Lower rooms first. A room may include the headers of the rooms listed for
# it, and its own. `interface` is include/tcb/method.h and registry.h: the
# plug-in contract (SQLite's sqlite3_module), which takes a method a
# sequence (datasets) and which every room above may name. `predictions`
# is include/tcb/predictions.h, scoring/'s one installed face, split off so
# that a method may read prediction files without importing scoring.
IMPORTS = {
    "interface": ["core", "datasets"],
    "core":      [],
    "metrics":   ["core"],
    "neural":    ["core", "interface"],
    "meshing":   ["core", "metrics"],
    "datasets":  ["core", "metrics"],
    "methods":   ["core", "interface", "metrics", "neural", "meshing", "datasets", "predictions"],
    "store":     ["core", "interface", "metrics", "datasets"],
    "predictions": ["core"],
    "scoring":   ["core", "interface", "metrics", "datasets", "store", "predictions"],
    "config":    ["core", "interface", "metrics", "datasets"],
    "costs":     ["core", "interface", "metrics", "datasets", "scoring", "config", "methods"],
    "harness":   ["core", "interface", "metrics", "datasets", "methods", "store", "scoring",
                  "predictions", "config", "costs"],
    "views":     ["core", "interface", "metrics", "datasets", "store", "scoring", "config", "harness"],
    "reports":   ["core", "interface", "metrics", "datasets", "store", "config"],
    "cli":       ["core", "interface", "metrics", "datasets", "methods", "store", "scoring",
                  "predictions", "config", "costs", "harness", "views", "reports"],
}
# Rooms whose code may include any room's face (they drive or measure it),
# and, for tests/ and fuzz/, its private headers too.
CONSUMERS = {"tests": True, "fuzz": True, "bench": False, "examples": False}

# include/tcb/<name>.h: the room that implements it.
OWNER = {
    "error": "core", "fsutil": "core", "hash": "core", "json": "core", "lap": "core", "nn": "core",
    "npy": "core", "npz": "core", "progress": "core", "rng": "core", "geometry": "core",
    "mesh": "core", "sysinfo": "core", "version": "core",
    "metrics": "metrics", "geodesic": "metrics", "bootstrap": "metrics", "wilcoxon": "metrics",
    "locate": "meshing", "meshing": "meshing", "cholesky": "meshing", "large_steps": "meshing",
    "tetmesh": "meshing",
    "sequence": "datasets", "split": "datasets", "synth": "datasets", "align": "datasets",
    "block": "datasets", "dfaust": "datasets", "distortion": "datasets", "mesh_io": "datasets",
    "method": "interface", "registry": "interface",
    "results": "store",
    "predictions": "predictions",
    "config": "config",
    "runner": "harness", "score": "harness", "binding": "harness",
    "inspect": "views", "frames": "views",
    "report": "reports", "compare": "reports",
    "tcb": "umbrella",
}
# Private headers not named *_internal.h: the pieces of views/ that only
# its own files (and the tests) use.
PRIVATE = {"views/render.h", "views/colormap.h", "views/checker.h", "views/frames_style.h",
           "core/npy_header.h"}

SOURCES = (".c", ".h", ".cpp")
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def room_of_header(h):
    """(room, is_private) of a quoted include path, or (None, False)."""
    if h.startswith("tcb/"):
        return OWNER.get(h[4:-2]), False
    top = h.split("/")[0]
    private = h.endswith("_internal.h") or h in PRIVATE
    if top in IMPORTS:
        return top, private
    return None, private


def files(root):
    for top in sorted(set(IMPORTS) | set(CONSUMERS)):
        base = os.path.join(root, top)
        for d, _, names in os.walk(base):
            for n in sorted(names):
                if n.endswith(SOURCES):
                    yield top, os.path.relpath(os.path.join(d, n), root)
    inc = os.path.join(root, "include", "tcb")
    for n in sorted(os.listdir(inc)):
        if n.endswith(".h"):
            yield OWNER.get(n[:-2], "unplaced"), os.path.join("include", "tcb", n)


def resolves(root, path, h):
    here = os.path.join(root, os.path.dirname(path), h)
    return any(os.path.isfile(p) for p in (here, os.path.join(root, h), os.path.join(root, "include", h),
                                           os.path.join(root, "tests", "support", h),
                                           os.path.join(root, "bench", h)))


def acyclic():
    state = {}

    def visit(r, trail):
        if state.get(r) == 1:
            return trail[trail.index(r):] + [r]
        if state.get(r) == 2:
            return None
        state[r] = 1
        for d in IMPORTS[r]:
            cyc = visit(d, trail + [r])
            if cyc:
                return cyc
        state[r] = 2
        return None

    for r in IMPORTS:
        cyc = visit(r, [])
        if cyc:
            return cyc
    return None


def check(root):
    problems, graph = [], {}
    for room, path in files(root):
        if room == "umbrella":
            continue                        # tcb/tcb.h includes every installed header
        if room == "unplaced":
            problems.append(f"{path}:1: installed header of no room: add it to OWNER in {sys.argv[0]}")
            continue
        with open(os.path.join(root, path), encoding="utf-8", errors="replace") as f:
            lines = f.readlines()
        for no, line in enumerate(lines, 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            h = m.group(1)
            where = f"{path}:{no}: includes {h}"
            if not resolves(root, path, h):
                problems.append(f"{where}: no such header")
                continue
            target, private = room_of_header(h)
            if target is None:
                continue                    # a consumer's own helper (tests/support, bench/)
            if target == "umbrella":
                if room in IMPORTS and room != "cli":
                    problems.append(f"{where}: library code names the headers it uses, not the umbrella")
                continue
            graph.setdefault(room, set()).add(target)
            if room in CONSUMERS:
                if private and not CONSUMERS[room]:
                    problems.append(f"{where}: private to {target}/ (only its room and the tests include it)")
                continue
            if target == room:
                continue
            if private:
                problems.append(f"{where}: private to {target}/")
            elif target not in IMPORTS[room]:
                problems.append(f"{where}: {room}/ may not import {target}/ (ARCHITECTURE.md, the code map)")
    return problems, graph


def main():
    args = [a for a in sys.argv[1:] if a != "--graph"]
    root = args[0] if args else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    cyc = acyclic()
    if cyc:
        print("the room imports form a cycle: " + " -> ".join(cyc))
        return 1
    problems, graph = check(root)
    if "--graph" in sys.argv:
        for r in sorted(graph):
            print(f"{r:10} -> {' '.join(sorted(graph[r] - {r}))}")
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} include rule violation(s); the rules: ARCHITECTURE.md, \"Include rules\"")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
