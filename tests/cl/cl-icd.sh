#!/bin/sh
# Usage: cl-icd.sh BVHLAB
# OpenCL where the driver is not registered (core/machine/machine_icd.c),
# with PoCL: a vendors folder with no .icd file (BVHLAB_CL_VENDORS_DIR) and
# the usual driver folders replaced by an empty one (BVHLAB_CL_DRIVER_DIRS).
# With a link to libpocl.so.2 in a folder on LD_LIBRARY_PATH, `bvhlab info
# --machine` says it found it there and lists PoCL's device through the
# loader's OCL_ICD_VENDORS, and the private vendors folder is gone after;
# without the link, it says none was found and lists no platform; a
# caller's OCL_ICD_VENDORS is left alone. Skips (77) without PoCL.
set -u
bvhlab=$1
pocl=$(ldconfig -p 2>/dev/null | awk '$1 == "libpocl.so.2" { print $NF; exit }')
[ -n "$pocl" ] || { echo "skip: no libpocl.so.2 (Debian pocl-opencl-icd)"; exit 77; }
dir=$(mktemp -d /tmp/bvhlab-cl-icd-XXXXXX) || exit 1
trap 'rm -rf "$dir"' EXIT
mkdir "$dir/vendors" "$dir/none" "$dir/drv" "$dir/tmp"
ln -s "$pocl" "$dir/drv/libpocl.so.2"
fail() { echo "FAIL: $*"; cat "$dir/out"; exit 1; }
info() { # info LD_LIBRARY_PATH: bvhlab info --machine into $dir/out
	env -u OCL_ICD_VENDORS BVHLAB_CL_VENDORS_DIR="$dir/vendors" \
		BVHLAB_CL_DRIVER_DIRS="$dir/none" TMPDIR="$dir/tmp" LD_LIBRARY_PATH="$1" \
		"$bvhlab" info --machine >"$dir/out" 2>&1 || fail "info --machine failed"
}
info "$dir/drv"
grep -q "^OpenCL ICD: none registered in $dir/vendors; found $dir/drv/libpocl.so.2 (LD_LIBRARY_PATH), used through OCL_ICD_VENDORS=$dir/tmp/bvhlab-icd-" "$dir/out" ||
	fail "the ICD line does not name the library found"
grep -q '^OpenCL: .* 0:0 .*(Portable Computing Language)' "$dir/out" ||
	fail "no PoCL device through the found ICD"
[ -z "$(ls -A "$dir/tmp")" ] || fail "the private vendors folder is left: $(ls "$dir/tmp")"
echo "found on LD_LIBRARY_PATH: $(grep '^OpenCL' "$dir/out" | head -2)"
info ""
grep -q "^OpenCL ICD: none registered in $dir/vendors and no driver (libnvidia-opencl.so.1, libamdocl64.so, libigdrcl.so, libpocl.so.2) on LD_LIBRARY_PATH or in $dir/none" "$dir/out" ||
	fail "the ICD line does not say none was found"
grep -q '^OpenCL: .*no OpenCL platform found' "$dir/out" || fail "a platform without a driver"
OCL_ICD_VENDORS="$dir/vendors" "$bvhlab" info --machine >"$dir/out" 2>&1
grep -q "^OpenCL ICD: OCL_ICD_VENDORS=$dir/vendors, from the environment" "$dir/out" ||
	fail "the caller's OCL_ICD_VENDORS not reported"
echo "none found, and the caller's OCL_ICD_VENDORS: as said"
