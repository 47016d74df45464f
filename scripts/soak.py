#!/usr/bin/env python3
"""Soak test of `bvhlab run`: N random configs, each sweep killed at a
random moment and resumed (sometimes killed again while resuming), its
config often changed in between: a scene (generator parameters, seed,
subdivide, frames, or the bytes of its file), a builder (options,
animation) or the measurement (repeat, warmup, validate_rays, the rays'
size, diffuse and traversal, rays_per_frame).

Each config mixes generated scenes, adversarial scene files (empty, NaN,
garbage, all-degenerate triangles), real builders
and test plugins that crash, abort, hang, exit, leak memory, fail, return
broken trees or crash while loading. Kills come at random moments and, with
rename_fault.so, at chosen ones: the Nth write of results.json (the folder's
creation, a run, the interleaved ray rounds) and the Nth file --force moves
aside. Some resumes run as two concurrent writers. After every sweep:
  - results.json parses and holds each scene x builder x thread count once;
  - every run finished before the kill is still there, unchanged (but for
    provisional ray figures, which a resume measures again), when the config
    did not change;
  - every run's identity matches the config it was resumed under: its
    recorded config fragment is the scene, builder and measurement settings
    of that config, and runs of one scene, builder or measurement share one
    hash (no stale run is kept);
  - after a change, every run made before it that the change concerns is
    made again and every other one kept (the last lines count both, and
    that none was kept stale or made again needlessly);
  - --force's move keeps the old results.json whole, in place or as .1;
  - of two concurrent writers one is refused, naming the other;
  - no temporary folder, tree, heat or shade file is left behind;
  - the exit status matches the runs: 0 all ok, 1 otherwise.

Usage: soak.py N BUILD_DIR [SEED]   (scripts/soak.sh N wraps it)
$SOAK_LIMIT_S (default 300): seconds after which a sweep counts as hung.
"""
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile

FAKE_FAILS = ["segfault", "abort", "loop", "exit", "invalid", "error", "silent", "alloc"]
REAL = [("sah_seq", {"method": "sweep"}), ("sah_seq", {"method": "binned"}),
        ("sah_even", {}), ("sah_tasks", {}), ("lbvh", {})]
# A sweep that needs longer than this has hung; $SOAK_LIMIT_S for a
# machine so loaded that a sweep may take longer.
LIMIT_S = float(os.environ.get("SOAK_LIMIT_S", "300"))


def adversarial_file(rng, folder, k):
    """A scene path that must fail to load, whatever the loader. (A FIFO, a
    folder or a missing file are refused with the config, before any output:
    tests/cli's cases, not a sweep's.)"""
    kind = rng.choice(["empty", "nan", "degenerate", "garbage"])
    path = os.path.join(folder, f"adv{k}.obj")
    if kind == "empty":
        open(path, "w").close()
    elif kind == "nan":
        with open(path, "w") as f:
            f.write("v 0 0 0\nv nan 1 0\nv 0 0 1\nf 1 2 3\n")
    elif kind == "garbage":
        with open(path, "wb") as f:
            f.write(bytes(rng.randrange(256) for _ in range(rng.randrange(1, 400))))
    elif kind == "degenerate":
        # Loads: every triangle the same point; builders must still cope.
        with open(path, "w") as f:
            f.write("v 1 1 1\n" + "f 1 1 1\n" * rng.randrange(1, 200))
    return {"name": f"s{k}", "path": path}


def random_scene(rng, folder, k):
    if rng.random() < 0.3:
        return adversarial_file(rng, folder, k)
    gen = rng.choice(["soup", "icosphere", "stadium", "terrain"])
    scene = {"name": f"s{k}", "generator": gen}
    if gen in ("soup", "stadium"):
        scene["count"] = rng.randrange(1, 4000)
        scene["seed"] = rng.randrange(0, 1000)
    elif gen == "icosphere":
        scene["frequency"] = rng.randrange(1, 16)
    else:
        scene["size"] = rng.randrange(1, 24)
    if rng.random() < 0.2:
        scene["subdivide"] = 1
    if rng.random() < 0.25:
        scene["frames"] = rng.randrange(2, 4)
        scene["deform"] = "wave"
    return scene


def random_builder(rng, k, loadcrash, memory_limits):
    name = f"b{k}"
    roll = rng.random()
    if roll < 0.1:
        return {"plugin": "lbvh", "name": name,
                "animation": {"update": "refit", "allow_static": True}}
    if roll < 0.45:
        plugin, options = rng.choice(REAL)
        return {"plugin": plugin, "name": name, "options": dict(options)}
    if roll < 0.55:
        which = rng.choice(["crash_ctor", "crash_entry", "hang_entry"])
        return {"plugin": os.path.join(loadcrash, which + ".so"), "name": name,
                "timeout_s": 1}
    fails = FAKE_FAILS if memory_limits else [f for f in FAKE_FAILS if f != "alloc"]
    fail = rng.choice(fails + ["no", "no"])
    b = {"plugin": "fake_good", "name": name, "options": {"fail": fail}}
    if fail == "loop":
        b["timeout_s"] = 0.5
    if fail == "alloc":
        b["memory_limit_mb"] = 512  # never without a limit: it eats 4 GB
    return b


def random_config(rng, folder, out, loadcrash, memory_limits):
    threads = sorted(rng.sample([1, 2, 3], rng.randrange(1, 4)))
    cfg = {"output": out, "repeat": rng.randrange(1, 3), "warmup": rng.randrange(0, 2),
           "threads": threads, "validate_rays": 64,
           "rays": {"width": 16, "height": 12, "diffuse": rng.randrange(0, 2),
                    "rounds": rng.choice([1, 2, 4])},
           "images": rng.random() < 0.5,
           "scenes": [random_scene(rng, folder, k) for k in range(rng.randrange(1, 4))],
           "builders": [random_builder(rng, k, loadcrash, memory_limits)
                        for k in range(rng.randrange(1, 5))]}
    if rng.random() < 0.3:
        cfg["builders"][0]["threads"] = [1]
    return cfg


# Plugins without the PARALLEL flag: one run per scene, at the first of
# their thread counts that is 1, else at their first (README, threads).
SERIAL = {"sah_seq", "fake_good"}


def mutate_scene(rng, cfg):
    """One scene's description or file changed: its generator's parameter,
    seed, subdivide, frames, or (an adversarial file) the file's bytes at
    the same path. The scene's name."""
    s = rng.choice(cfg["scenes"])
    if "path" in s:
        with open(s["path"], "ab") as f:
            f.write(b"\n# changed\n")
        return s["name"]
    what = rng.choice(["size", "seed", "subdivide", "frames"])
    if what == "seed" and "seed" in s:
        s["seed"] += 1
    elif what == "subdivide":
        s["subdivide"] = 1 - s.get("subdivide", 0)
    elif what == "frames" and "frames" in s:
        s["frames"] = 5 - s["frames"]  # 2 <-> 3
    else:
        key = {"icosphere": "frequency", "terrain": "size"}.get(s["generator"], "count")
        s[key] = s.get(key, 4) + rng.randrange(1, 4)
    return s["name"]


def mutate_builder(rng, cfg):
    """One builder's options or animation changed. Its name, or None when
    this builder has neither to change."""
    b = rng.choice(cfg["builders"])
    if "animation" in b:
        a = b["animation"]
        if "rebuild_every" in a:
            del a["rebuild_every"]
        else:
            a["rebuild_every"] = 2
    elif b["plugin"] == "sah_seq":
        b["options"]["method"] = "binned" if b["options"].get("method") != "binned" else "sweep"
    elif b["plugin"] in ("lbvh", "sah_even", "sah_tasks"):
        b["options"]["max_leaf"] = 4 if b["options"].get("max_leaf") != 4 else 2
    elif b["plugin"] == "fake_good" and b["options"]["fail"] in ("no", "invalid", "error"):
        b["options"]["fail"] = rng.choice([f for f in ("no", "invalid", "error")
                                           if f != b["options"]["fail"]])
    else:
        return None
    return b["name"]


def mutate_measure(rng, cfg):
    """A measurement setting changed. Whether it concerns only animated
    scenes' runs (rays_per_frame), else every run."""
    what = rng.choice(["repeat", "warmup", "validate_rays", "width", "height", "diffuse",
                       "traversal", "rays_per_frame"])
    rays = cfg["rays"]
    if what == "repeat":
        cfg["repeat"] = 3 - cfg["repeat"]
    elif what == "warmup":
        cfg["warmup"] = 1 - cfg["warmup"]
    elif what == "validate_rays":
        cfg["validate_rays"] = 96 - cfg["validate_rays"]  # 64 <-> 32
    elif what == "rays_per_frame":
        cfg["rays_per_frame"] = cfg.get("rays_per_frame", 0) + rng.randrange(1, 1000)
        return True
    elif what == "traversal":
        rays["traversal"] = "stack" if rays.get("traversal") != "stack" else "stackless"
    elif what == "diffuse":
        rays["diffuse"] = 1 - rays["diffuse"]
    else:
        rays[what] = 24 - rays[what] if what == "width" else 20 - rays[what]  # 16<->8, 12<->8
    return False


def mutate(rng, cfg):
    """Changes the config the way a user between two attempts might: a
    scene (its description or its file), a builder (options, animation) or
    the measurement (repeat, warmup, validation, rays, rays_per_frame).
    (kind, the test a run's key passes when the change concerns it)."""
    kind = rng.choice(["scene", "builder", "measure"])
    if kind == "builder":
        name = mutate_builder(rng, cfg)
        if name is not None:
            return kind, lambda key: key[1] == name
        kind = "scene"
    if kind == "scene":
        name = mutate_scene(rng, cfg)
        return kind, lambda key: key[0] == name
    animated = {s["name"] for s in cfg["scenes"] if "frames" in s}
    if mutate_measure(rng, cfg):
        return "rays_per_frame", lambda key: key[0] in animated
    return kind, lambda key: True


def check_identity(cfg, runs, where):
    """Every run was made under cfg: its fragment is cfg's, and one scene,
    builder or measurement has one hash over all runs."""
    scenes = {s["name"]: s for s in cfg["scenes"]}
    builders = {b["name"]: b for b in cfg["builders"]}
    hashes = {}
    for key, r in runs.items():
        c, ident = r.get("config", {}), r.get("identity")
        if ident is None:
            raise AssertionError(f"{where}: run {key} has no identity")
        scene, b = scenes[key[0]], builders[key[1]]
        m = c.get("measure", {})
        rays = m.get("rays", {})
        want = (cfg["repeat"], cfg["warmup"], cfg["validate_rays"],
                {k: v for k, v in cfg["rays"].items()},
                cfg.get("rays_per_frame", 1000000) if "frames" in scene else None)
        got = (m.get("repeat"), m.get("warmup"), m.get("validate_rays"),
               {k: rays.get(k) for k in cfg["rays"]}, m.get("rays_per_frame"))
        if c.get("scene") != scene or got != want:
            raise AssertionError(f"{where}: run {key} kept from another config: "
                                 f"{c.get('scene')} {got}, config now {scene} {want}")
        opts = c.get("builder", {}).get("options", {})
        if any(opts.get(k) != v for k, v in b.get("options", {}).items()):
            raise AssertionError(f"{where}: run {key} kept from other options: {opts}")
        anim = c.get("builder", {}).get("animation")
        if anim and anim.get("rebuild_every") != b["animation"].get("rebuild_every", 0):
            raise AssertionError(f"{where}: run {key} kept from another animation: {anim}")
        for part, name in (("scene", key[0]), ("builder", key[1]),
                           ("measure", "frames" in scene)):
            if hashes.setdefault((part, name), ident[part]) != ident[part]:
                raise AssertionError(f"{where}: runs of {part} {name} with two hashes")


def count_after_change(before, after, concerned, where, cfg):
    """A resume after a change: every run made before that the change
    concerns must be made again (kept, it is stale), every other one kept
    (provisional ray figures apart, which a resume measures again)."""
    for key, run in before.items():
        kept = same_run(after.get(key), run)
        if not kept and gone(key, cfg, after):
            continue
        if concerned(key):
            COUNTS["stale kept" if kept else "rerun"] += 1
            if kept:
                raise AssertionError(f"{where}: run {key} kept though the change concerns it")
        elif kept:
            COUNTS["kept"] += 1
        elif not provisional(run):
            COUNTS["rerun needlessly"] += 1
            raise AssertionError(f"{where}: run {key} made again though the change does "
                                 "not concern it")


def unprobed(name, runs):
    """Whether the sweep could not open builder `name`'s plugin (its probe
    timed out: a loaded machine): its runs have no builder fragment and its
    flags were unknown, so every thread count was listed."""
    return any(k[1] == name and not r.get("config", {}).get("builder") for k, r in runs.items())


def expected_runs(cfg, runs=None):
    """The runs of cfg; of `runs` (results.json's) where a plugin could not
    be opened."""
    runs = runs or {}
    want = set()
    for s in cfg["scenes"]:
        for b in cfg["builders"]:
            threads = b.get("threads", cfg["threads"])
            if b["plugin"] in SERIAL and not unprobed(b["name"], runs):
                threads = [1] if 1 in threads else threads[:1]
            for t in threads:
                want.add((s["name"], b["name"], t))
    return want


def load_runs(out):
    """{identity: run} of results.json; None when there is none yet."""
    path = os.path.join(out, "results.json")
    if not os.path.exists(path):
        return None
    with open(path) as f:
        doc = json.load(f)  # must always parse: raises otherwise
    runs = {}
    for r in doc["runs"]:
        key = (r["scene"], r["builder"], r["threads"])
        if key in runs:
            raise AssertionError(f"run {key} twice in {path}")
        runs[key] = r
    return runs


def launch(bvhlab, config, resume, extra=(), env=None):
    args = [bvhlab, "run", "--quiet", config] + (["--resume"] if resume else []) + list(extra)
    return subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=env)


def shim_env(shim, nth, to):
    """Kills bvhlab just before its nth rename (or link) onto a name ending in `to`."""
    env = dict(os.environ, LD_PRELOAD=shim, BVHLAB_FAULT_RENAME=str(nth), BVHLAB_FAULT_TO=to)
    env["ASAN_OPTIONS"] = env.get("ASAN_OPTIONS", "") + ":verify_asan_link_order=0"
    return env


def killed_sweep(rng, bvhlab, config, out, resume, shim):
    """Starts a sweep, kills it at a random moment or at its Nth write of
    results.json (creating the folder, a run, the rounds); the runs it left."""
    env = shim_env(shim, rng.randrange(1, 9), "/results.json") if rng.random() < 0.6 else None
    p = launch(bvhlab, config, resume, env=env)
    try:
        p.wait(timeout=rng.uniform(0.0, 2.0) if env is None else LIMIT_S)
    except subprocess.TimeoutExpired:
        p.send_signal(signal.SIGKILL)
        p.wait()
    p.stderr.close()
    return load_runs(out) or {}


def killed_force(rng, bvhlab, config, out, before, shim):
    """--force killed while it moves the old files aside: the old results.json
    stays whole, in place or as results.json.1. The runs left to resume."""
    old = os.path.join(out, "results.json")
    text = open(old).read() if os.path.exists(old) else None
    p = launch(bvhlab, config, False, ["--force"], shim_env(shim, 1, rng.choice(
        ["/results.csv.1", "/report.md.1", "/report.html.1", "/images.1", "/results.json.1"])))
    p.communicate(timeout=LIMIT_S)
    moved = os.path.join(out, "results.json.1")
    if text is not None and os.path.exists(moved):
        if open(moved).read() != text:
            raise AssertionError("--force killed: results.json.1 is not the old results.json")
        return {}
    if text is not None and open(old).read() != text:
        raise AssertionError("--force killed: results.json changed before it was moved")
    for name in os.listdir(out) if os.path.isdir(out) else []:
        if name.endswith(".2"):
            raise AssertionError(f"--force killed: a second generation {name}")
    return before


def concurrent_resume(bvhlab, config, where):
    """Two writers at once: each ends normally or is refused naming the other."""
    ps = [launch(bvhlab, config, True) for _ in range(2)]
    codes = []
    for p in ps:
        try:
            _, err = p.communicate(timeout=LIMIT_S)
        except subprocess.TimeoutExpired:
            p.kill()
            raise AssertionError(f"{where}: concurrent sweep still running after {LIMIT_S} s")
        refused = p.returncode == 2 and b"in use by another bvhlab (pid" in err
        if p.returncode not in (0, 1) and not refused:
            raise AssertionError(f"{where}: concurrent writer exit {p.returncode}\n{err.decode()}")
        codes.append(p.returncode)
    return codes


def same_run(a, b):
    """Equal but for heat_image, which a resumed sweep may add to a kept run
    whose heat map the killed attempt had left unconverted."""
    strip = lambda r: {k: v for k, v in r.items() if k != "heat_image"}
    return a is not None and b is not None and strip(a) == strip(b)


def provisional(run):
    return bool(run.get("rays", {}).get("provisional"))


def gone(key, cfg, after):
    """A run of a slot the config no longer has: a plugin that could not be
    probed in time under load was listed at every thread count, and --resume
    drops those runs once it is known to be serial. Counted, never a loss."""
    if key in expected_runs(cfg, after):
        return False
    COUNTS["dropped"] += 1
    return True


def check_kept(before, after, where, cfg):
    for key, run in before.items():
        if (not provisional(run) and not same_run(after.get(key), run) and
                not gone(key, cfg, after)):
            raise AssertionError(f"{where}: finished run {key} lost or changed")


def check_no_leftovers(work, out, where):
    for name in os.listdir(work):
        if name.startswith(".bvhlab-new-"):
            raise AssertionError(f"{where}: temporary folder {name} left behind")
    for name in os.listdir(out):
        if name.startswith((".tree-", ".heat-", ".shade-")):
            raise AssertionError(f"{where}: {name} left behind")


def one_config(rng, i, bvhlab, folder, loadcrash, memory_limits):
    work = os.path.join(folder, f"c{i}")
    os.mkdir(work)
    out = os.path.join(work, "out")
    cfg = random_config(rng, work, out, loadcrash, memory_limits)
    config = os.path.join(work, "config.json")
    with open(config, "w") as f:
        json.dump(cfg, f, indent=1)
    shim = os.path.join(os.path.dirname(loadcrash), "shim", "rename_fault.so")
    before = killed_sweep(rng, bvhlab, config, out, False, shim)
    if rng.random() < 0.4:
        again = killed_sweep(rng, bvhlab, config, out, True, shim)
        check_kept(before, again, f"config {i} (second kill)", cfg)
        before = again
    if rng.random() < 0.2 and os.path.exists(os.path.join(out, "results.json")):
        before = killed_force(rng, bvhlab, config, out, before, shim)
    changed = None
    if rng.random() < 0.5:
        changed, concerned = mutate(rng, cfg)
        with open(config, "w") as f:
            json.dump(cfg, f, indent=1)
    if rng.random() < 0.2:
        concurrent_resume(bvhlab, config, f"config {i}")
    p = launch(bvhlab, config, True)
    try:
        _, err = p.communicate(timeout=LIMIT_S)
    except subprocess.TimeoutExpired:
        p.kill()
        raise AssertionError(f"config {i}: resumed sweep still running after {LIMIT_S} s")
    after = load_runs(out) or {}
    if changed is None:
        check_kept(before, after, f"config {i}", cfg)
        COUNTS["kept"] += sum(1 for k in before if k in after)
    else:
        MUTATED[changed] = MUTATED.get(changed, 0) + 1
        count_after_change(before, after, concerned, f"config {i}", cfg)
    check_identity(cfg, after, f"config {i}")
    want = expected_runs(cfg, after)
    if set(after) != want:
        raise AssertionError(f"config {i}: runs {sorted(set(after) ^ want)} missing or extra")
    check_no_leftovers(work, out, f"config {i}")
    all_ok = all(r["status"] == "ok" for r in after.values())
    if p.returncode != (0 if all_ok else 1):
        raise AssertionError(f"config {i}: exit status {p.returncode} but "
                             f"{'all' if all_ok else 'not all'} runs ok\n{err.decode()}")
    shutil.rmtree(work)


MUTATED = {}  # kind of change: configs resumed after it
# Runs made before a resume: kept, made again after a change that concerns
# them, kept though it does (must stay 0), made again though it does not.
COUNTS = {"kept": 0, "rerun": 0, "stale kept": 0, "rerun needlessly": 0, "dropped": 0}


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    n, build = int(sys.argv[1]), os.path.abspath(sys.argv[2])
    seed = int(sys.argv[3]) if len(sys.argv) > 3 else random.randrange(1 << 30)
    rng = random.Random(seed)
    bvhlab = os.path.join(build, "app", "bvhlab")
    loadcrash = os.path.join(build, "tests", "fake", "loadcrash")
    os.environ["BVHLAB_PLUGIN_PATH"] = os.path.join(build, "tests", "fake")
    # Crashes are the point here: no sanitizer report in place of the signal.
    asan = os.environ.get("ASAN_OPTIONS", "")
    os.environ["ASAN_OPTIONS"] = (asan + ":" if asan else "") + \
        "handle_segv=0:handle_abort=0:detect_leaks=0:allocator_may_return_null=1"
    memory_limits = os.environ.get("SOAK_NO_MEMORY_LIMITS") != "1"
    folder = tempfile.mkdtemp(prefix="bvhlab-soak-")
    print(f"soak: {n} configs, seed {seed}, in {folder}", flush=True)
    for i in range(n):
        try:
            one_config(rng, i, bvhlab, folder, loadcrash, memory_limits)
        except (AssertionError, ValueError, KeyError) as e:
            print(f"soak: FAILED at config {i} (seed {seed}): {e}; files kept in {folder}")
            sys.exit(1)
        # Every config: a soak stopped early still says how far it got.
        print(f"soak: {i + 1}/{n} configs ok; runs made before a resume: "
              + ", ".join(f"{v} {k}" for k, v in COUNTS.items()), flush=True)
    print(f"soak: configs changed before resuming: {MUTATED or 'none'}")
    print(f"soak: runs made before a resume: {COUNTS['kept']} kept, {COUNTS['rerun']} made "
          f"again after a change that concerns them, {COUNTS['stale kept']} stale kept, "
          f"{COUNTS['rerun needlessly']} made again needlessly, {COUNTS['dropped']} dropped "
          "(a slot no longer listed); none lost or duplicated")
    shutil.rmtree(folder)


if __name__ == "__main__":
    main()
