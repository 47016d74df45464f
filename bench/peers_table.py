#!/usr/bin/env python3
"""Tables of one run of bench/peers.json, for README and docs/benchmarks.md.

Usage: bench/peers_table.py RESULTS_DIR [--scene NAME | --summary]

RESULTS_DIR holds the run's results.json and the report.md that bvhlab
wrote beside it (--summary reads results.json alone). Prints Markdown:

  1. per scene, one row per builder: build ms (own_ms, as in 2), SAH cost and primary nodes
     per ray at 1 and 2 threads, and whether the run is on the Pareto front
     of time x SAH, as the report's "Pareto fronts" table says (the front
     is the report's own verdict, read from report.md, not recomputed);
  2. per scene and thread count, every peer run (plugins tinybvh, bvh2,
     embree) against the fastest bvhlab run whose SAH cost is no higher,
     every time the run's own_ms as the report's fronts take it (build_ms
     without the phases `input` and `convert`: making the library's input
     from bvhlab's scene, writing its tree in bvhlab's layout; what is left
     is the library's own build, the strictest reading): the ratio, and
     whether it is at most 0.9. A peer run that failed validation has
     nothing to beat and is listed with its reason.

With --summary, only one line per scene and thread count: how many valid
peer runs are dominated at <= 0.9x, and the highest ratio (the closest
call) with its peer and bvhlab builder.
"""
import argparse
import json
import os
import re
import sys

PEERS = ("tinybvh", "bvh2", "embree")


def load(path, summary):
    """results.json, and report.md beside it (not needed with --summary,
    which reads results.json alone)."""
    with open(os.path.join(path, "results.json")) as f:
        results = json.load(f)
    if summary:
        return results, ""
    with open(os.path.join(path, "report.md")) as f:
        report = f.read()
    return results, report


def report_fronts(report):
    """(scene, builder, threads) -> 'front' or the report's dominance text."""
    fronts = {}
    scene = None
    in_table = False
    for line in report.splitlines():
        m = re.match(r"^## (.+)$", line)
        if m:
            scene = m.group(1)
            in_table = False
            continue
        if line.startswith("### Pareto fronts"):
            in_table = True
            continue
        if line.startswith("### "):
            in_table = False
        if not in_table or not line.startswith("| ") or line.startswith("| builder"):
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        if len(cells) < 5 or not cells[1].split()[0].isdigit():
            continue
        fronts[(scene, cells[0], int(cells[1].split()[0]))] = cells[4]
    return fronts


def fmt_ms(ms):
    return f"{ms:.0f}" if ms >= 100 else f"{ms:.1f}"


def scene_table(runs, fronts, scene):
    rows = {}
    for r in runs:
        if r["scene"] == scene:
            rows.setdefault(r["builder"], {})[r["threads"]] = r
    out = [f"#### {scene}", "",
           "| builder | 1T ms | 1T SAH | 1T nodes/ray | 1T front | 2T ms | 2T SAH | 2T front |",
           "|---|---:|---:|---:|---|---:|---:|---|"]
    for builder, by in rows.items():
        cells = [builder]
        for t in (1, 2):
            r = by.get(t)
            if r is None:
                cells += ["", ""] + ([""] if t == 1 else []) + [""]
                continue
            if r["status"] != "ok":
                cells += [r["status"], "", ""] if t == 1 else [r["status"], ""]
                cells.append("")
                continue
            verdict = fronts.get((scene, builder, t), "")
            short = "**front**" if verdict == "front" else (
                "dominated by " + verdict.split("dominated by ")[1].split(" (")[0]
                if "dominated by" in verdict else verdict)
            cells += [fmt_ms(own_ms(r)), f"{r['tree']['sah_cost']:.3f}"]
            if t == 1:
                cells.append(f"{r['rays']['primary']['nodes_per_ray']:.1f}")
            cells.append(short)
        out.append("| " + " | ".join(cells) + " |")
    return out


def own_ms(run):
    """The build time the report's fronts and verdicts compare: results.json's
    own_ms (build_ms's median less the phases `input` and `convert`, the
    harness's translation to and from a library's formats; defined once, in
    core/output/results_stages.c)."""
    if "own_ms" not in run:
        sys.exit(f"peers_table: run {run.get('id')} has no own_ms: results.json is older "
                 "than it (rerun the sweep)")
    return run["own_ms"]


def comparisons(runs, scenes):
    """Per scene, thread count and peer run: the fastest bvhlab run with
    no higher SAH (None if there is none), the ratio of its time to the
    peer's without conversion; a failed peer run carries its reason."""
    for scene in scenes:
        for t in (1, 2):
            ours = [r for r in runs if r["scene"] == scene and r["threads"] == t and
                    r["plugin"] not in PEERS and r["status"] == "ok"]
            for p in runs:
                if p["scene"] != scene or p["threads"] != t or p["plugin"] not in PEERS:
                    continue
                c = {"scene": scene, "threads": t, "peer": p, "best": None, "ratio": None}
                if p["status"] == "ok":
                    sah = p["tree"]["sah_cost"]
                    c["best"] = min((r for r in ours if r["tree"]["sah_cost"] <= sah),
                                    key=own_ms, default=None)
                    if c["best"] is not None:
                        c["ratio"] = own_ms(c["best"]) / own_ms(p)
                yield c


def met(c):
    return c["ratio"] is not None and c["ratio"] <= 0.9


def verdicts(runs, scenes):
    out = ["| scene | threads | peer | peer ms (no input, convert) | peer SAH | fastest bvhlab builder with SAH <= | its ms | its SAH | ratio | <= 0.9 |",
           "|---|---:|---|---:|---:|---|---:|---:|---:|---|"]
    misses = 0
    for c in comparisons(runs, scenes):
        p, best, lead = c["peer"], c["best"], f"| {c['scene']} | {c['threads']} | {c['peer']['builder']} |"
        if p["status"] != "ok":
            out.append(f"{lead} {p['status']}: {p.get('error', p['status'])} | | | | | | nothing to beat |")
            continue
        misses += not met(c)
        head = f"{lead} {fmt_ms(own_ms(p))} | {p['tree']['sah_cost']:.3f} |"
        if best is None:
            out.append(f"{head} none | | | | **no** |")
            continue
        out.append(f"{head} {best['builder']} | {fmt_ms(own_ms(best))} | "
                   f"{best['tree']['sah_cost']:.3f} | {c['ratio']:.2f} | {'yes' if met(c) else '**no**'} |")
    out.append("")
    out.append(f"Peer runs not dominated at <= 0.9x: {misses}.")
    return out


def summary(runs, scenes):
    """One row per scene and thread count: valid peer runs, how many are
    dominated at <= 0.9x, and the closest call."""
    out = ["| scene | threads | valid peer runs | dominated at <= 0.9x | highest ratio: peer, bvhlab builder |",
           "|---|---:|---:|---:|---|"]
    for scene in scenes:
        valid = [c for c in comparisons(runs, [scene]) if c["peer"]["status"] == "ok"]
        for t in (1, 2):
            cs = [c for c in valid if c["threads"] == t]
            if not cs:
                continue
            worst = max(cs, key=lambda c: float("inf") if c["ratio"] is None else c["ratio"])
            close = (f"{worst['peer']['builder']}: none with SAH <=" if worst["best"] is None else
                     f"{worst['ratio']:.2f}: {worst['peer']['builder']} "
                     f"({fmt_ms(own_ms(worst['peer']))} ms, SAH {worst['peer']['tree']['sah_cost']:.3f}), "
                     f"{worst['best']['builder']} ({fmt_ms(own_ms(worst['best']))} ms, "
                     f"SAH {worst['best']['tree']['sah_cost']:.3f})")
            out.append(f"| {scene} | {t} | {len(cs)} | {sum(map(met, cs))} | {close} |")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("results_dir")
    ap.add_argument("--scene", help="only this scene's builder table")
    ap.add_argument("--summary", action="store_true",
                    help="only one line per scene and thread count: peers dominated, the closest call")
    args = ap.parse_args()
    try:
        results, report = load(args.results_dir, args.summary)
    except OSError as e:
        sys.exit(f"peers_table: {e}")
    runs = results["runs"]
    scenes = [s["name"] for s in results["scenes"]]
    fronts = report_fronts(report)
    m = results["machine"]
    print(f"Machine: {m.get('cpu', '?')}, {m.get('cores', '?')} cores; bvhlab {results.get('bvhlab_version', '?')}, {results.get('created', '?')}.")
    print()
    if args.summary:
        print("\n".join(summary(runs, scenes)))
        return
    for scene in ([args.scene] if args.scene else scenes):
        print("\n".join(scene_table(runs, fronts, scene)))
        print()
    if not args.scene:
        print("\n".join(verdicts(runs, scenes)))


if __name__ == "__main__":
    main()
