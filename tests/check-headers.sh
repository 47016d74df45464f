#!/bin/sh
# Usage: check-headers.sh INCLUDE_DIR c|c++ COMPILER [ARGS...]
# Compiles each public header alone (twice, so include guards are needed),
# in strict C11 or C++17 with warnings as errors, so none depends on another
# being included first and C++ code can include every one (test-cxx-api
# checks that the functions link from C++, i.e. are extern "C").
# BVHLAB_HEADERS_SKIP: space-separated header names not to check (opencl.h
# when the build has no OpenCL headers).
set -u
incdir=$1
lang=$2
shift 2
case $lang in
c) std=-std=c11 ;;
c++) std=-std=c++17 ;;
*) echo "check-headers.sh: language must be c or c++, not '$lang'" >&2; exit 2 ;;
esac
status=0
headers="$incdir"/bvhlab/*.h
[ "$lang" = c++ ] && headers="$headers $incdir/bvhlab/*.hpp" # C++-only helpers
for h in $headers; do
	name=$(basename "$h")
	case " ${BVHLAB_HEADERS_SKIP:-} " in
	*" $name "*) echo "skip: bvhlab/$name (built without its dependency)"; continue ;;
	esac
	src=$(printf '#include <bvhlab/%s>\n#include <bvhlab/%s>\n' "$name" "$name")
	if ! printf '%s\n' "$src" |
		"$@" $std -Wall -Wextra -Wpedantic -Werror -fsyntax-only -I "$incdir" -x "$lang" -; then
		echo "FAIL: bvhlab/$name does not compile on its own as $lang" >&2
		status=1
	else
		echo "ok: bvhlab/$name ($lang)"
	fi
done
exit $status
