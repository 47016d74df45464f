#!/usr/bin/env python3
"""Compares the ray throughput of two bvhlab results.json files run by run.

Usage: scripts/compare-rays.py A/results.json B/results.json
                               [--kind primary|diffuse|both] [--limit 1.10] [--all]

Runs are matched by scene, builder and thread count. For each pair the
ratio is the larger Mrays/s over the smaller (1.00: the same); the worst
pairs are listed, then the worst ratio. "tree differs" marks a pair whose
rays did not visit the same number of nodes: the builder gave a different
tree the second time (a parallel build's order can vary), so a difference
in speed there is not only the measurement's.

Exit status: 0 when the worst ratio is within --limit (default 1.10, the
10 % of issue 17), 1 when not, 2 on bad input.
"""
import argparse
import json
import sys


def load(path):
    try:
        with open(path, encoding="utf-8") as f:
            doc = json.load(f)
    except (OSError, ValueError) as e:
        sys.exit(f"compare-rays: {path}: {e}")
    runs = {}
    for run in doc.get("runs", []):
        if run.get("status") != "ok" or "rays" not in run:
            continue
        runs[(run["scene"], run["builder"], run["threads"])] = run
    return runs


def pairs(a, b, kinds):
    """(key, kind, mrays a, mrays b, same tree) for every run in both."""
    for key in sorted(a.keys() & b.keys()):
        for kind in kinds:
            ra, rb = a[key]["rays"].get(kind), b[key]["rays"].get(kind)
            if not ra or not rb or not ra.get("mrays_per_s") or not rb.get("mrays_per_s"):
                continue
            same = ra.get("nodes_per_ray") == rb.get("nodes_per_ray")
            yield key, kind, ra["mrays_per_s"], rb["mrays_per_s"], same


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--kind", choices=["primary", "diffuse", "both"], default="primary")
    ap.add_argument("--limit", type=float, default=1.10)
    ap.add_argument("--all", action="store_true", help="list every pair, not the worst 10")
    args = ap.parse_args()
    kinds = ["primary", "diffuse"] if args.kind == "both" else [args.kind]
    a, b = load(args.a), load(args.b)
    rows = [(max(x, y) / min(x, y), key, kind, x, y, same)
            for key, kind, x, y, same in pairs(a, b, kinds)]
    if not rows:
        sys.exit("compare-rays: no runs with rays in both files")
    rows.sort(key=lambda r: r[0], reverse=True)
    for ratio, (scene, builder, threads), kind, x, y, same in rows[: None if args.all else 10]:
        note = "" if same else "  (tree differs)"
        print(f"{ratio:6.3f}  {scene:<12} {builder:<16} {threads:>2}t {kind:<8}"
              f" {x:8.3f} {y:8.3f} Mrays/s{note}")
    worst = rows[0]
    unmatched = len(a.keys() ^ b.keys())
    print(f"worst ratio {worst[0]:.3f} over {len(rows)} pairs"
          f" ({worst[1][0]}, {worst[1][1]}, {worst[1][2]} threads, {worst[2]})"
          + (f"; {unmatched} runs in only one file" if unmatched else ""))
    return 0 if worst[0] <= args.limit else 1


if __name__ == "__main__":
    sys.exit(main())
