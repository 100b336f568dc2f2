#!/usr/bin/env python3
"""Public items of clearance_joint (see .ci/public-items), from a rustdoc JSON file.

Counts, under a module (default `rapier`, or `crate` for the whole library):
- definitions: modules, types, functions and methods, fields, variants, constants and trait items
  reachable from the public API, each once however many paths reach it;
- second paths: extra public paths to a definition (a `pub use` of an item that is also public where
  it is defined). A `pub use` that is the only path to an item defined in a private file module is
  that item's path, not a second one.
Also prints `listing`: every `pub use` counted as an item beside its target, the rule used before the
split into definitions and second paths.
"""
import collections, json, signal, sys

signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # `| head` closes the pipe early

d = json.load(open(sys.argv[1]))
which = sys.argv[2] if len(sys.argv) > 2 else "rapier"
idx = d["index"]
root = idx[str(d["root"])]


def inner(it):
    k = list(it["inner"].keys())[0]
    return k, it["inner"][k]


seen = set()
arrivals = collections.Counter()
kinds = collections.Counter()
per = collections.Counter()
uses = 0


def visit(i, path):
    global uses
    i = str(i)
    if i not in idx:
        return
    it = idx[i]
    if it.get("crate_id", 0) != 0:
        return
    k, v = inner(it)
    if k != "impl" and k != "use":
        arrivals[i] += 1
    if i in seen:
        return
    seen.add(i)
    name = it.get("name")
    p = path + [name] if name else path
    if k not in ("impl", "use"):
        kinds[k] += 1
        per["::".join(p[:4])] += 1
    if k == "module":
        for c in v["items"]:
            visit(c, p)
    elif k in ("struct", "union"):
        kind = v.get("kind", {})
        if isinstance(kind, dict) and "plain" in kind:
            for f in kind["plain"]["fields"]:
                visit(f, p)
        elif isinstance(kind, dict) and "tuple" in kind:
            for f in kind["tuple"]:
                if f is not None:
                    visit(f, p)
        for im in v["impls"]:
            visit(im, p)
    elif k == "enum":
        for x in v["variants"]:
            visit(x, p)
        for im in v["impls"]:
            visit(im, p)
    elif k == "impl":
        if v.get("trait") is None and not v.get("is_synthetic") and not v.get("blanket_impl"):
            for c in v["items"]:
                visit(c, path)
    elif k == "trait":
        for c in v["items"]:
            visit(c, p)
    elif k == "use":
        uses += 1
        tgt = v.get("id")
        if tgt is not None:
            visit(tgt, path)


if which == "crate":
    visit(d["root"], [])
else:
    for c in inner(root)[1]["items"]:
        if idx[str(c)]["name"] == which:
            visit(c, [which])
definitions = sum(kinds.values())
second = sum(max(0, n - 1) for n in arrivals.values())
print(f"{which}: {definitions + second} public items = {definitions} definitions + {second} second paths"
      f" (listing: {definitions + uses})")
print(" ", dict(kinds))
for k, v in sorted(per.items(), key=lambda x: -x[1])[:40]:
    print(v, k)
