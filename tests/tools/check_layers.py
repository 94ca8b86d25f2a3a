#!/usr/bin/env python3
"""Checks that host/, capture/ and bench/ include only their own layer and the layers below
it, as docs/design.md's layer table says (read from it: one source), and that no include
cycle exists. Exit 1 names each breach."""
import os
import re
import sys

DESIGN = "docs/design.md"


def read_layers(root):
    """docs/design.md's layer table: each layer and the layers it may include (besides its
    own), the table's "uses" column closed over the layers below."""
    uses, order = {}, []
    with open(os.path.join(root, DESIGN), encoding="utf-8") as f:
        text = f.read()
    table = text[text.index("| layer | folder |"):].split("\n\n")[0]
    for row in table.splitlines()[2:]:
        cells = [c.strip() for c in row.strip("|").split("|")]
        layer, used = cells[0], cells[-1]
        order.append(layer)
        uses[layer] = set(order[:-1]) if used == "all" else {u.strip() for u in used.split(",") if u.strip()}
    below = {}
    for layer in order:  # each row may use only rows above it, so one pass closes the sets
        below[layer] = set(uses[layer])
        for u in uses[layer]:
            if u not in below:
                raise SystemExit(f"{DESIGN}: layer {layer} uses {u}, which is not a row above it")
            below[layer] |= below[u]
        if layer != "common":
            below[layer].add("common")
    return below


MAX_CPP_PER_FOLDER = 10


def layer_of(path):
    parts = path.split("/")
    return parts[1] if parts[0] == "host" else parts[0]


def report_cycles(name, graph):
    """Prints each cycle a depth-first search over `graph` meets; True when there is one."""
    state, found = {}, False

    def visit(node, stack):
        nonlocal found
        state[node] = 1
        stack.append(node)
        for nxt in graph.get(node, ()):
            if state.get(nxt) == 1:
                print(f"{name} cycle: " + " -> ".join(stack[stack.index(nxt):] + [nxt]))
                found = True
            elif state.get(nxt) is None:
                visit(nxt, stack)
        stack.pop()
        state[node] = 2

    for node in list(graph):
        if state.get(node) is None:
            visit(node, [])
    return found


def main(root):
    below = read_layers(root)
    files = {}
    for top in ("host", "capture", "bench"):
        for folder, _, names in os.walk(os.path.join(root, top)):
            rel_folder = os.path.relpath(folder, root)
            cpps = [n for n in names if n.endswith(".cpp")]
            if len(cpps) > MAX_CPP_PER_FOLDER:
                print(f"{rel_folder}: {len(cpps)} .cpp files, more than {MAX_CPP_PER_FOLDER}")
                files["__too_many__"] = []
            for n in names:
                if n.endswith((".cpp", ".hpp")):
                    rel = os.path.join(rel_folder, n)
                    text = open(os.path.join(root, rel), encoding="utf-8").read()
                    files[rel] = re.findall(r'^#include "([^"]+)"', text, re.M)
    problems = "__too_many__" in files
    files.pop("__too_many__", None)
    # An include names its layer: "sim/params.hpp" is host/sim/params.hpp, "capture/png.hpp" capture/png.hpp.
    def resolve(inc):
        for candidate in (os.path.join("host", inc), inc):
            if candidate in files:
                return candidate
        return None

    graph = {}
    for f, incs in files.items():
        graph[f] = []
        for inc in incs:
            target = resolve(inc)
            if target is None:
                # shaders/contract.h: what C++ and GLSL share, below every layer.
                if not inc.endswith(".inc") and not (inc.startswith("shaders/") and os.path.exists(os.path.join(root, inc))):
                    print(f"{f}: includes \"{inc}\", which is not a layer-prefixed project header")
                    problems = True
                continue
            graph[f].append(target)
            a, b = layer_of(f), layer_of(target)
            if a != b and b not in below.get(a, ()):
                print(f"{f}: layer {a} includes {target} from layer {b}, which is not below it")
                problems = True
    # Module cycles: a .cpp and its header count as one node (params.cpp -> scene.hpp -> params.hpp).
    modules = {}
    for f, targets in graph.items():
        m = os.path.splitext(f)[0]
        modules.setdefault(m, set()).update(os.path.splitext(t)[0] for t in targets if os.path.splitext(t)[0] != m)
    for name, g in (("include", graph), ("module", modules)):
        if report_cycles(name, g):
            problems = True
    print(f"{len(files)} files checked" + (": breaches above" if problems else ": layers hold, no cycle"))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "..")))
