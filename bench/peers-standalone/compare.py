#!/usr/bin/env python3
"""Each peer builder in the harness against its library alone (issue 43).

Usage (from the checkout): bench/peers-standalone/compare.py [--build DIR]
    [--scene PATH] [--subdivide K] [--threads 1,2] [--repeat N] [--warmup N]
    [--pairs N] [--only SUBSTRING[,...]] [--keep DIR]

For every peer builder (tinybvh quick, binned, avx, sweep; madmann91/bvh
low, medium, high, sweep, binned; Embree low, medium, high) and thread
count, in one window, a `bvhlab run` of that one builder and the library's
standalone program (build/bench/peers-standalone/) on the same scene, with
the same warm-up and repeats, interleaved: pair by pair, the order of the
two flipped every pair, so a drift of the machine's speed falls on both.
Builders single-threaded in their library (tinybvh quick, bvh2 sweep and
binned) run at 1 thread only, as bench/peers.json runs them. Embree runs
alone twice: with callbacks of its tutorial's kind, and with the plugin's
own (--callbacks plugin: high clips triangles exactly), so the callbacks'
share shows apart from the harness's.

The in-harness time is the library's: results.json's own_ms, the median
build_ms less the median `input` (the library's input made from
bvhlab's scene) and `convert` (its tree written in bvhlab's layout)
phases, as the report's fronts take it. The standalone
time is the median of the build call alone. With --pairs N every builder
runs N such pairs and its ratio is the median of the N pairs' ratios (their
range in a last column): on a VM whose runs of one program differ by 30 %,
one pair's ratio is one draw. A run whose tree is invalid
(tinybvh avx on igea subdivided once: the library's own boxes) keeps its
time, its ratio marked "(note)" and the reason printed under the table. Prints a Markdown table with
the CPU model, the ratio in-harness / standalone per builder.

Wall-clock figures: run it on a quiet machine. Default (igea subdivided
once, 1 and 2 threads, 5 repeats after 1 warm-up): about 5 minutes on the
2-core AMD EPYC by an estimate from the libraries' earlier quiet times
(not yet timed quiet); --repeat 3 when that is too long.
"""
import argparse
import datetime
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

# (plugin, variant, single-threaded in the library)
BUILDERS = [
    ("tinybvh", "quick", True), ("tinybvh", "binned", False), ("tinybvh", "avx", False),
    ("tinybvh", "sweep", False),
    ("bvh2", "low", False), ("bvh2", "medium", False), ("bvh2", "high", False),
    ("bvh2", "sweep", True), ("bvh2", "binned", True),
    ("embree", "low", False), ("embree", "medium", False), ("embree", "high", False),
]
OPTION = {"tinybvh": "builder", "bvh2": "builder", "embree": "quality"}


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--build", default=os.path.join(ROOT, "build"))
    p.add_argument("--scene", default=os.path.join(ROOT, "..", "shared", "scenes", "igea.ply"))
    p.add_argument("--subdivide", type=int, default=1)
    p.add_argument("--threads", default="1,2")
    p.add_argument("--repeat", type=int, default=5)
    p.add_argument("--warmup", type=int, default=1)
    p.add_argument("--pairs", type=int, default=1,
                   help="harness/standalone pairs per builder (the ratio is their median)")
    p.add_argument("--only", default="", help="run the builders whose name holds this (or one of these, comma-separated)")
    p.add_argument("--keep", help="folder for the harness's outputs (default: a temporary one)")
    return p.parse_args()


def program(args, plugin):
    return os.path.join(args.build, "bench", "peers-standalone", f"{plugin}-standalone")


def pairs(args):
    """(name, plugin, variant, threads, standalone extra args), in run order;
    a library whose program was not built (meson said why) is left out."""
    out = []
    for plugin in OPTION:
        if not os.access(program(args, plugin), os.X_OK):
            print(f"{plugin}: skipped, {program(args, plugin)} not built", file=sys.stderr)
    for t in [int(x) for x in args.threads.split(",")]:
        for plugin, variant, serial in BUILDERS:
            name = f"{plugin}_{variant}"
            if (serial and t > 1) or not any(o in name for o in args.only.split(",")):
                continue
            if not os.access(program(args, plugin), os.X_OK):
                continue
            out.append((name, plugin, variant, t, []))
            if plugin == "embree":
                out.append((name + " (plugin's callbacks)", plugin, variant, t,
                            ["--callbacks", "plugin"]))
    return out


def harness(args, plugin, variant, threads, folder):
    """The library's median ms in the harness, and the run's phases."""
    config = {
        "format_version": 1, "output": folder, "repeat": args.repeat, "warmup": args.warmup,
        "threads": [threads], "validate": False,
        "rays": {"width": 8, "height": 8, "diffuse": 0, "min_ms": 1, "rounds": 1},
        "scenes": [{"name": "scene", "path": os.path.abspath(args.scene),
                    "subdivide": args.subdivide}],
        "builders": [{"plugin": plugin, "name": f"{plugin}_{variant}",
                      "options": {OPTION[plugin]: variant}}]}
    path = folder + ".json"
    with open(path, "w") as f:
        json.dump(config, f)
    # Exit 1 is a run that did not end ok: its status goes into the table.
    rc = subprocess.run([os.path.join(args.build, "app", "bvhlab"), "run", path, "--quiet",
                         "--force"]).returncode
    if rc not in (0, 1):
        sys.exit(f"{plugin} {variant} at {threads} threads: bvhlab run exited {rc}")
    with open(os.path.join(folder, "results.json")) as f:
        results = json.load(f)
    run = results["runs"][0]
    note = "" if run["status"] == "ok" else f"{run['status']}: {run.get('error', '')}"
    if run.get("own_ms") is None:  # not built: the note says why
        return None, note, {}, results["machine"]["cpu"], note
    # An invalid tree was still built and timed: its time stands, marked.
    phases = run.get("build_phases", {})
    whole = run["build_ms"]["median"]
    own = run["own_ms"]  # less input and convert, as the report's fronts take it
    return own, whole, phases, results["machine"]["cpu"], note


def standalone(args, plugin, variant, threads, extra):
    cmd = [program(args, plugin), args.scene, "--subdivide", str(args.subdivide),
           "--threads", str(threads), "--repeat", str(args.repeat),
           "--warmup", str(args.warmup), "--variant", variant] + extra
    line = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    fields = dict(re.findall(r"(\w+)=([\d.]+)", line))
    return float(fields["wall_ms"]), float(fields["cpu_ms"])


def median(values):
    v = sorted(values)
    return (v[(len(v) - 1) // 2] + v[len(v) // 2]) / 2


def summarise(name, t, tries):
    """One row from a builder's pairs: medians of each column, and the ratio
    as the median of the pairs' own ratios (each pair ran in one stretch of
    the machine's speed), with their range when there were several."""
    alone = [a for _, (a, _) in tries]
    alone_cpu = median([c for _, (_, c) in tries])
    ok = [h for h, _ in tries if h[0] is not None]
    note = next((h[4] for h, _ in tries if h[4]), "")
    if len(ok) < len(tries):  # a harness run did not end ok: its note says why
        return (name, t, tries[0][0][1], 0.0, 0.0, None, median(alone), alone_cpu, note, None)
    ratios = [h[0] / a for h, (a, _) in tries]
    return (name, t, median([h[1] for h in ok]),
            median([h[2].get("input", 0.0) for h in ok]),
            median([h[2].get("convert", 0.0) for h in ok]), median([h[0] for h in ok]),
            median(alone), alone_cpu, note, (median(ratios), min(ratios), max(ratios)))


def cpu_model(from_results):
    """results.json's CPU name (/proc/cpuinfo's when no run was made),
    with lscpu's family: "AMD EPYC" alone does not say which."""
    name = from_results
    if name == "?" and os.path.exists("/proc/cpuinfo"):
        with open("/proc/cpuinfo") as f:
            m = re.search(r"model name\s*:\s*(.+)", f.read())
        name = m.group(1).strip() if m else name
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True).stdout
    except OSError:
        return name
    fam = re.search(r"CPU family:\s*(\S+)", out)
    return name + (f" (CPU family {fam.group(1)})" if fam else "")


def main():
    args = parse_args()
    keep = os.path.abspath(args.keep or tempfile.mkdtemp(prefix="peers-compare-"))
    os.makedirs(keep, exist_ok=True)
    rows, cpu, start = [], "?", datetime.datetime.now(datetime.timezone.utc)
    order = 0
    for name, plugin, variant, t, extra in pairs(args):
        folder = os.path.join(keep, f"{name.split(' ')[0]}-{t}t{'-cb' if extra else ''}")
        steps = [lambda: harness(args, plugin, variant, t, folder),
                 lambda: standalone(args, plugin, variant, t, extra)]
        tries = []
        for _ in range(args.pairs):
            got = [None, None]
            for i in ([0, 1] if order % 2 == 0 else [1, 0]):
                got[i] = steps[i]()
            order += 1
            tries.append(got)
            (own, whole, _, cpu, _), (alone, _) = got
            print(f"{name} {t}T: harness {own if own is None else round(own, 1)} ms "
                  f"({whole}), alone {alone:.1f} ms", file=sys.stderr)
        rows.append(summarise(name, t, tries))
    end = datetime.datetime.now(datetime.timezone.utc)
    print(f"{os.path.basename(args.scene)} subdivided {args.subdivide}x, "
          f"{args.repeat} repeats after {args.warmup} warm-up, {args.pairs} "
          f"pair{'s' if args.pairs > 1 else ''} per builder, {cpu_model(cpu)}, "
          f"{start:%Y-%m-%d %H:%M} to {end:%H:%M} UTC\n")
    spread = args.pairs > 1
    print("| builder | threads | harness build_ms | input | convert | harness, library "
          "| standalone | standalone CPU | ratio |" + (" pairs' ratios |" if spread else ""))
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|" + ("---:|" if spread else ""))
    for name, t, whole, inp, conv, own, alone, alone_cpu, note, ratio in rows:
        if own is None:  # the harness's run did not end ok: whole says why
            print(f"| {name} | {t} | {whole} | | | | {alone:.1f} | {alone_cpu:.1f} | - |"
                  + (" |" if spread else ""))
            continue
        print(f"| {name} | {t} | {whole:.1f} | {inp:.1f} | {conv:.1f} | {own:.1f} "
              f"| {alone:.1f} | {alone_cpu:.1f} | {ratio[0]:.2f}{' (note)' if note else ''} |"
              + (f" {ratio[1]:.2f}-{ratio[2]:.2f} |" if spread else ""))
    for name, t, *_, note, _ in rows:
        if note:
            print(f"\n{name} at {t} threads: {note}")


if __name__ == "__main__":
    main()
