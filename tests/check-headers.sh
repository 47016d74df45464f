#!/bin/sh
# Usage: check-headers.sh INCLUDE_DIR CC [CC ARGS...]
# Compiles each public header alone, in strict C11 with warnings as errors,
# so none of them depends on another being included first.
set -u
incdir=$1
shift
status=0
for h in "$incdir"/bvhlab/*.h; do
	name=$(basename "$h")
	if ! printf '#include <bvhlab/%s>\n#include <bvhlab/%s>\n' "$name" "$name" |
		"$@" -std=c11 -Wall -Wextra -Wpedantic -Werror -fsyntax-only -I "$incdir" -x c -; then
		echo "FAIL: bvhlab/$name does not compile on its own" >&2
		status=1
	else
		echo "ok: bvhlab/$name"
	fi
done
exit $status
