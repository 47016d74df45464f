#!/usr/bin/env python3
"""Compares two results.json of the same config: old binary against new.

Usage: bench/compare_results.py OLD/results.json NEW/results.json

Pairs the runs by scene, builder and thread count, and prints for each: both
median build times, their ratio new/old, and whether the trees are the same
(node count, and SAH cost to 1e-12 relative: a parallel builder's node order
varies from build to build, and the SAH sum with it in its last digits).
Ends with the median and the geometric mean of the
ratios and the count of differing trees. Both folders should come from one
session on one machine, run alternately, so the ratio measures the binaries
and not the machine. Exit status 1 when a tree differs or a run is missing.
"""
import json
import math
import statistics
import sys


def runs(path):
    with open(path) as f:
        doc = json.load(f)
    out = {}
    for r in doc.get("runs", []):
        key = (r.get("scene"), r.get("builder"), r.get("threads"))
        out[key] = r
    return doc, out


def median_ms(run):
    b = run.get("build_ms") or {}
    return b.get("median")


def tree_of(run):
    t = run.get("tree") or {}
    return t.get("nodes"), t.get("sah_cost")


def same_tree(a, b):
    (na, sa), (nb, sb) = tree_of(a), tree_of(b)
    if na != nb or (sa is None) != (sb is None):
        return False
    return sa is None or abs(sa - sb) <= 1e-12 * max(abs(sa), abs(sb))


def main(argv):
    if len(argv) != 3 or argv[1] in ("-h", "--help"):
        print(__doc__.strip(), file=sys.stderr)
        return 2
    old_doc, old = runs(argv[1])
    new_doc, new = runs(argv[2])
    print(f"old: {old_doc.get('bvhlab_version')}  new: {new_doc.get('bvhlab_version')}")
    cpu = (new_doc.get("machine") or {}).get("cpu_model") or (new_doc.get("machine") or {}).get("cpu")
    if cpu:
        print(f"cpu: {cpu}")
    print("| scene | builder | threads | old ms | new ms | new/old | tree |")
    print("|---|---|---|---:|---:|---:|---|")
    ratios, differ, missing = [], 0, 0
    for key in sorted(old, key=str):
        if key not in new:
            missing += 1
            print(f"| {key[0]} | {key[1]} | {key[2]} | missing in new |||")
            continue
        a, b = old[key], new[key]
        ma, mb = median_ms(a), median_ms(b)
        same = same_tree(a, b)
        differ += not same
        ratio = mb / ma if ma and mb else None
        if ratio:
            ratios.append(ratio)
        rs = f"{ratio:.3f}" if ratio else "-"
        ts = "same" if same else f"DIFFERS {tree_of(a)} vs {tree_of(b)}"
        print(f"| {key[0]} | {key[1]} | {key[2]} | {ma or 0:.2f} | {mb or 0:.2f} | {rs} | {ts} |")
    missing += sum(1 for k in new if k not in old)
    if ratios:
        gm = math.exp(sum(math.log(r) for r in ratios) / len(ratios))
        print(f"\n{len(ratios)} runs: median ratio {statistics.median(ratios):.3f}, "
              f"geometric mean {gm:.3f}, min {min(ratios):.3f}, max {max(ratios):.3f}; "
              f"{differ} trees differ, {missing} runs missing")
    return 1 if differ or missing else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
