# Shared set-up for run.sh and test.sh (sourced, not run): installs what is
# missing from Debian when it can, then configures and builds with meson.
# Usage: setup_build BUILD_DIR [meson setup options...]

BVHLAB_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BVHLAB_DEBS="meson ninja-build gcc pkg-config libcjson-dev"

missing_debs() {
	local missing=""
	command -v meson >/dev/null 2>&1 || missing="$missing meson"
	command -v ninja >/dev/null 2>&1 || missing="$missing ninja-build"
	command -v cc >/dev/null 2>&1 || missing="$missing gcc"
	command -v pkg-config >/dev/null 2>&1 || missing="$missing pkg-config"
	if ! command -v pkg-config >/dev/null 2>&1 || ! pkg-config --exists libcjson; then
		missing="$missing libcjson-dev"
	fi
	echo "$missing"
}

install_deps() {
	local missing
	missing=$(missing_debs)
	[ -z "$missing" ] && return 0
	if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
		echo "setup: installing$missing" >&2
		export DEBIAN_FRONTEND=noninteractive
		apt-get update -qq >&2 || true
		# shellcheck disable=SC2086
		apt-get install -y -qq --no-install-recommends $missing >&2 || {
			echo "setup: apt-get could not install:$missing" >&2
			return 1
		}
	else
		echo "setup: missing Debian packages:$missing" >&2
		echo "setup: install them with: sudo apt-get install$missing" >&2
		return 1
	fi
}

# Configures (once) and builds one build directory.
setup_build() {
	local dir=$1
	shift
	install_deps || return 1
	if [ ! -f "$dir/build.ninja" ]; then
		meson setup "$dir" "$BVHLAB_ROOT" "$@" >&2 || return 1
	fi
	ninja -C "$dir" >&2 || return 1
}
