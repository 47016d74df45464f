# Shared set-up for run.sh and test.sh (sourced, not run): installs what is
# missing from Debian when it can, then configures and builds with meson.
# Usage: setup_build BUILD_DIR [meson setup options...]

BVHLAB_ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
BVHLAB_DEBS="meson ninja-build gcc g++ pkg-config libcjson-dev libhwloc-dev libopenimageio-dev"

missing_debs() {
	local missing=""
	command -v meson >/dev/null 2>&1 || missing="$missing meson"
	command -v ninja >/dev/null 2>&1 || missing="$missing ninja-build"
	command -v cc >/dev/null 2>&1 || missing="$missing gcc"
	command -v pkg-config >/dev/null 2>&1 || missing="$missing pkg-config"
	if ! command -v pkg-config >/dev/null 2>&1 || ! pkg-config --exists libcjson; then
		missing="$missing libcjson-dev"
	fi
	if ! command -v pkg-config >/dev/null 2>&1 || ! pkg-config --exists hwloc; then
		missing="$missing libhwloc-dev"
	fi
	# Images (core/output/images_oiio.cpp, the module bvhlab-images.so): OpenImageIO and a C++ compiler for that one file.
	command -v c++ >/dev/null 2>&1 || missing="$missing g++"
	if ! command -v pkg-config >/dev/null 2>&1 || ! pkg-config --exists OpenImageIO; then
		missing="$missing libopenimageio-dev"
	fi
	echo "$missing"
}

# Installs Debian packages when root with apt-get, after one `apt-get
# update` per shell; otherwise says what to install. 0, or 1 when nothing
# could be installed. Usage: apt_install WHO PACKAGE...
apt_install() {
	local who=$1
	shift
	if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
		echo "$who: missing Debian packages: $* (install them with: sudo apt-get install $*)" >&2
		return 1
	fi
	echo "$who: installing $*" >&2
	export DEBIAN_FRONTEND=noninteractive
	if [ -z "${BVHLAB_APT_UPDATED:-}" ]; then
		apt-get update -qq >&2 || true
		BVHLAB_APT_UPDATED=1
	fi
	apt-get install -y -qq --no-install-recommends "$@" >&2 || {
		echo "$who: apt-get could not install: $*" >&2
		return 1
	}
}

# Optional: Embree 3 for the embree peer plugin. Never fails the set-up.
install_optional() {
	[ -f /usr/include/embree3/rtcore.h ] && return 0
	apt_install "setup (optional: the embree plugin)" libembree-dev ||
		echo "setup: building without the embree plugin" >&2
	return 0
}

# Optional: OpenCL headers, ICD loader and PoCL (OpenCL on the CPU) for the
# device plugins (cl_*) and their tests. Never fails the set-up.
install_opencl() {
	local want=""
	[ -f /usr/include/CL/cl.h ] || want="$want opencl-c-headers"
	{ [ -f /usr/lib/x86_64-linux-gnu/libOpenCL.so ] || [ -f /usr/lib/libOpenCL.so ] ||
		{ command -v pkg-config >/dev/null 2>&1 && pkg-config --exists OpenCL; }; } ||
		want="$want ocl-icd-opencl-dev"
	ls /etc/OpenCL/vendors/*.icd >/dev/null 2>&1 || want="$want pocl-opencl-icd"
	[ -z "$want" ] && return 0
	# shellcheck disable=SC2086
	apt_install "setup (optional: OpenCL device plugins)" $want ||
		echo "setup: without$want the device plugins are not built or their tests skip" >&2
	return 0
}

# Optional: GNU parallel (the cli-plan-parallel test) and a single-node Slurm
# (scripts/slurm-smoke.sh). Their tests report themselves skipped without
# them, so this never fails the set-up.
install_sweep_tools() {
	local want=""
	command -v parallel >/dev/null 2>&1 || want="$want parallel"
	command -v slurmctld >/dev/null 2>&1 || want="$want slurm-wlm"
	command -v munged >/dev/null 2>&1 || want="$want munge"
	[ -z "$want" ] && return 0
	if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
		echo "setup: optional$want missing: their tests will be skipped" >&2
		return 0
	fi
	echo "setup: installing$want (optional: sweeps over GNU parallel and Slurm)" >&2
	export DEBIAN_FRONTEND=noninteractive
	local pkg
	for pkg in $want; do
		apt-get install -y -qq --no-install-recommends "$pkg" >&2 ||
			{ apt-get update -qq >&2 && apt-get install -y -qq --no-install-recommends "$pkg" >&2; } ||
			echo "setup: could not install $pkg: its test will be skipped" >&2
	done
	return 0
}

install_deps() {
	local missing
	missing=$(missing_debs)
	[ -z "$missing" ] && return 0
	# shellcheck disable=SC2086
	apt_install setup $missing
}

# Configures (once) and builds one build directory.
setup_build() {
	local dir=$1
	shift
	install_deps || return 1
	install_optional
	install_opencl
	install_sweep_tools
	if [ ! -f "$dir/build.ninja" ]; then
		meson setup "$dir" "$BVHLAB_ROOT" "$@" >&2 || return 1
	elif meson configure "$dir" 2>/dev/null | grep -qE '^ *pkgconfig\.relocatable +false'; then
		# A folder set up before meson.build asked for it: default_options
		# apply only at setup, and the sdk test needs a relocatable .pc.
		meson configure "$dir" -Dpkgconfig.relocatable=true >&2 || return 1
	fi
	ninja -C "$dir" >&2 || return 1
}
