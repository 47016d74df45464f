#!/usr/bin/env python3
"""bench/peers_table.py --summary from a results.json alone, every time its
own_ms (build_ms less the phases input and convert, as the report's fronts
take it): a peer whose library took 2.0 of its 3.0 ms against cl_lbvh's
1.5 of 3.0 (its convert, 1.5, is translation too) is dominated at 0.75x;
on the whole call both took 3.0 and it would not be. A results.json
without own_ms is refused by name. Usage: peers_table_test.py SCRIPT"""
import json
import os
import subprocess
import sys
import tempfile


def run(ms, sah, plugin, name, phases=None, own=True):
    r = {"id": 0, "scene": "s", "builder": name, "plugin": plugin, "threads": 1,
         "status": "ok", "build_ms": {"median": ms}, "tree": {"sah_cost": sah}}
    if phases:
        r["build_phases"] = phases
    if own:
        r["own_ms"] = ms - sum(v for k, v in (phases or {}).items() if k in ("input", "convert"))
    return r


def summary(script, runs):
    with tempfile.TemporaryDirectory(prefix="peers-table-") as d:
        with open(os.path.join(d, "results.json"), "w") as f:
            json.dump({"machine": {"cpu": "test", "cores": 2}, "scenes": [{"name": "s"}],
                       "runs": runs}, f)
        return subprocess.run([sys.executable, script, d, "--summary"], capture_output=True,
                              text=True)


def main():
    script, failures = sys.argv[1], 0
    peer = run(3.0, 45, "tinybvh", "tinybvh_avx", {"input": 0.4, "convert": 0.6})
    ours = run(3.0, 44, "cl_lbvh", "cl_lbvh", {"upload": 0.5, "convert": 1.5})
    out = summary(script, [ours, peer])
    want = ("| s | 1 | 1 | 1 | 0.75: tinybvh_avx (2.0 ms, SAH 45.000), "
            "cl_lbvh (1.5 ms, SAH 44.000) |")
    if out.returncode != 0 or want not in out.stdout:
        print(f"want {want!r} in:\n{out.stdout}{out.stderr}", file=sys.stderr)
        failures += 1
    del ours["own_ms"]
    out = summary(script, [ours, peer])
    if out.returncode == 0 or "has no own_ms" not in out.stderr:
        print(f"a results.json without own_ms was not refused:\n{out.stdout}{out.stderr}",
              file=sys.stderr)
        failures += 1
    print("ok" if failures == 0 else f"{failures} check(s) failed")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
