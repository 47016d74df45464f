#!/usr/bin/env bash
# Makes a relocatable bundle of a built bvhlab: a folder to carry (tar, scp,
# rsync) to another x86-64 Linux with the same or a newer C library and
# nothing installed, e.g. a GPU cluster node, and run from there.
# Usage: scripts/bundle.sh DIR [BUILD_DIR]   (BUILD_DIR default: build)
#
# DIR is laid out as an install, so the bundled bvhlab finds its plugins
# from its own file, as an installed one does (README, "The bvhlab command"):
#   bin/bvhlab                       DT_RPATH $ORIGIN/../LIBDIR/bvhlab/lib
#   LIBDIR/bvhlab/plugins/*.so       every plugin built (kernels inside)
#   LIBDIR/bvhlab/lib/*.so.*         every library they need beyond the C
#                                    library, found by the dynamic loader
#                                    (ldd): cJSON, hwloc, the OpenCL ICD
#                                    loader, libstdc++, Embree, TBB, ...
#   configs/{default,gpu}.json, bench/gpu.json   their scene paths rewritten
#   scenes/                          the meshes those configs name
#   gpu-check.sh                     scripts/gpu-check.sh (docs/gpu.md)
# The images module (bvhlab-images.so, OpenImageIO's ~250 libraries) stays
# out: the bundle's runs say "images skipped" and go on. The OpenCL driver
# is the node's own (bvhlab finds it, registered or not: docs/gpu.md).
# Fails (exit 1) when DIR exists and is not empty, or when the bundle
# comes out over 64 MiB; prints the size.
set -euo pipefail
case "${1:-}" in
-h|--help|"") sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; [ -n "${1:-}" ]; exit ;;
esac
root=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "${2:-$root/build}" && pwd)
out=$1
max_bytes=$((64 * 1024 * 1024))

die() { echo "bundle: $*" >&2; exit 1; }

[ -x "$build/app/bvhlab" ] || die "$build/app/bvhlab is not built (ninja -C $build)"
if [ -e "$out" ] && [ -n "$(ls -A "$out")" ]; then
	die "$out exists and is not empty"
fi
libdir=$(python3 -c 'import json,sys
print(next(o["value"] for o in json.load(open(sys.argv[1])) if o["name"] == "libdir"))' \
	"$build/meson-info/intro-buildoptions.json")
case "$libdir" in /*) die "libdir '$libdir' is absolute: configure a relative one" ;; esac
plugins="$out/$libdir/bvhlab/plugins"
libs="$out/$libdir/bvhlab/lib"
mkdir -p "$out/bin" "$plugins" "$libs" "$out/configs" "$out/bench" "$out/scenes"

cp "$build/app/bvhlab" "$out/bin/"
# Every plugin the build made (build/plugins/NAME/NAME.so), flat as installed.
find "$build/plugins" -name '*.so' -not -path '*/common/*' -exec cp {} "$plugins/" \;
# Their symbol tables are not needed to run (130 KB of the 64 MiB).
strip --strip-unneeded "$out/bin/bvhlab" "$plugins"/*.so

# The C library's own parts are the node's; everything else travels.
glibc='^(linux-vdso|ld-linux-x86-64|libc|libm|libmvec|libpthread|libdl|librt|libresolv|libutil)\.so'
for elf in "$out/bin/bvhlab" "$plugins"/*.so; do
	env -u LD_LIBRARY_PATH ldd "$elf" | awk '$2 == "=>" && $3 ~ /^\// { print $1, $3 }'
done | sort -u | while read -r soname path; do
	[[ "$soname" =~ $glibc ]] && continue
	cp -L "$path" "$libs/$soname"
done
if env -u LD_LIBRARY_PATH ldd "$out/bin/bvhlab" "$plugins"/*.so | grep -q 'not found'; then
	die "a library the build needs is not found: ldd $build/app/bvhlab"
fi

# The configs, their scenes copied in and named relative to the copy.
python3 - "$root" "$out" configs/default.json configs/gpu.json bench/gpu.json <<'EOF'
import json, os, shutil, sys
root, out, names = sys.argv[1], sys.argv[2], sys.argv[3:]
for name in names:
    src = os.path.join(root, name)
    with open(src) as f:
        cfg = json.load(f)
    for scene in cfg.get("scenes", []):
        if "path" not in scene:
            continue
        mesh = os.path.normpath(os.path.join(os.path.dirname(src), scene["path"]))
        base = os.path.basename(mesh)
        dest = os.path.join(out, "scenes", base)
        if not os.path.exists(dest):
            shutil.copyfile(mesh, dest)
        stem = os.path.splitext(base)[0]
        for extra in os.listdir(os.path.dirname(mesh)):  # licence notes
            if extra.startswith(stem + ".") and extra.endswith(".txt"):
                shutil.copyfile(os.path.join(os.path.dirname(mesh), extra),
                                os.path.join(out, "scenes", extra))
        scene["path"] = "../scenes/" + base
    with open(os.path.join(out, name), "w") as f:
        json.dump(cfg, f, indent=2)
        f.write("\n")
EOF
cp "$root/scripts/gpu-check.sh" "$out/gpu-check.sh"

# The newest C library symbol version any of it asks for: the oldest glibc
# it runs on.
glibc_min=$(objdump -T "$out/bin/bvhlab" "$plugins"/*.so "$libs"/* 2>/dev/null |
	grep -o 'GLIBC_[0-9.]*' | sed 's/GLIBC_//' | sort -uV | tail -1)
bytes=$(du -sb "$out" | cut -f1)
echo "bundle: $out: $((bytes / 1024 / 1024)) MiB ($bytes bytes), $(ls "$plugins" | wc -l) plugins, $(ls "$libs" | wc -l) libraries, needs glibc >= ${glibc_min:-?}"
[ "$bytes" -le "$max_bytes" ] || die "$out is $bytes bytes, over 64 MiB"
