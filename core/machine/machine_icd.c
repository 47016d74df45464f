/*
 * An OpenCL driver that is installed but not registered: GPU cluster nodes
 * and containers often have the vendor's library (NVIDIA's container
 * runtime mounts libnvidia-opencl.so.1 under /usr/local/nvidia/lib64) and
 * no file in /etc/OpenCL/vendors, so the ICD loader finds no platform.
 * Before the loader first runs, bvhlab looks for the usual vendor libraries
 * on the library path and in the usual driver folders, writes an .icd file
 * for each one found into a private folder and points OCL_ICD_VENDORS at
 * it (ocl-icd and Khronos's loader both read it). A caller's own
 * OCL_ICD_VENDORS, or any registered driver, is left alone.
 */
#include <dirent.h>
#include <limits.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "machine/machine.h"

/* What each vendor's OpenCL driver is called (NVIDIA, AMD ROCm, Intel's
 * compute runtime, PoCL). */
static const char *const drivers[] = {"libnvidia-opencl.so.1", "libamdocl64.so",
                                      "libigdrcl.so", "libpocl.so.2"};
#define DRIVERS (sizeof(drivers) / sizeof(drivers[0]))

/* Where they are installed when not on the library path; replaced by
 * $BVHLAB_CL_DRIVER_DIRS (colon-separated) where that is set. */
static const char default_dirs[] = "/usr/local/nvidia/lib64:/usr/lib/x86_64-linux-gnu:"
                                   "/usr/lib64:/usr/lib:/opt/rocm/lib:/opt/rocm/opencl/lib:"
                                   "/usr/lib/x86_64-linux-gnu/intel-opencl";

static struct {
	char how[2048];
	char dir[256]; /* the private vendors folder, removed at exit */
	pid_t owner;
} icd;

static bool registered(const char *vendors, char *names, size_t size)
{
	DIR *d = opendir(vendors);
	struct dirent *e;
	size_t len = 0;
	names[0] = '\0';
	while (d && (e = readdir(d))) {
		size_t n = strlen(e->d_name);
		if (n > 4 && !strcmp(e->d_name + n - 4, ".icd") && len + n + 2 < size)
			len += (size_t)snprintf(names + len, size - len, "%s%s", len ? " " : "",
			                        e->d_name);
	}
	if (d)
		closedir(d);
	return len > 0;
}

/* The first folder of the colon-separated list `dirs` holding `file`. */
static bool find_in(const char *dirs, const char *file, char *path, size_t size)
{
	while (dirs && *dirs) {
		size_t n = strcspn(dirs, ":");
		struct stat st;
		if (n && (size_t)snprintf(path, size, "%.*s/%s", (int)n, dirs, file) < size &&
		    stat(path, &st) == 0 && S_ISREG(st.st_mode))
			return true;
		dirs += n + (dirs[n] == ':');
	}
	return false;
}

static void remove_private(void)
{
	char path[512];
	if (getpid() != icd.owner) /* a forked child's exit leaves it to the parent */
		return;
	for (size_t k = 0; k < DRIVERS; k++) {
		snprintf(path, sizeof(path), "%s/%s.icd", icd.dir, drivers[k]);
		unlink(path);
	}
	rmdir(icd.dir);
}

/* Writes DIR/DRIVER.icd naming `lib`'s own file, links resolved: PoCL finds
 * its device modules beside its real file. */
static bool write_icd(const char *driver, const char *lib)
{
	char path[512], real[PATH_MAX];
	snprintf(path, sizeof(path), "%s/%s.icd", icd.dir, driver);
	FILE *f = fopen(path, "w");
	bool ok = f && fprintf(f, "%s\n", realpath(lib, real) ? real : lib) > 0;
	return f && !fclose(f) && ok;
}

/* The drivers found, each with where from; false when none. */
static bool find_drivers(char (*found)[1024], char *list, size_t size)
{
	const char *ld = getenv("LD_LIBRARY_PATH");
	const char *dirs = getenv("BVHLAB_CL_DRIVER_DIRS");
	size_t len = 0;
	list[0] = '\0';
	for (size_t k = 0; k < DRIVERS; k++) {
		found[k][0] = '\0';
		bool on_path = find_in(ld, drivers[k], found[k], sizeof(found[k]));
		if (!on_path && !find_in(dirs ? dirs : default_dirs, drivers[k], found[k],
		                         sizeof(found[k])))
			found[k][0] = '\0';
		else if (len < size)
			len += (size_t)snprintf(list + len, size - len, "%s%s (%s)", len ? ", " : "",
			                        found[k], on_path ? "LD_LIBRARY_PATH" : "driver folder");
	}
	return len > 0;
}

/* The registry folder: /etc/OpenCL/vendors, or $BVHLAB_CL_VENDORS_DIR (for
 * tests), which the loader is then pointed at too, so that it sees what
 * bvhlab saw. */
static const char *vendors_dir(void)
{
	const char *dir = getenv("BVHLAB_CL_VENDORS_DIR");
	if (!dir)
		return "/etc/OpenCL/vendors";
	setenv("OCL_ICD_VENDORS", dir, 1);
	return dir;
}

void machine_icd_setup(void)
{
	const char *set = getenv("OCL_ICD_VENDORS");
	char names[512], list[1024], found[DRIVERS][1024];
	if (set) {
		snprintf(icd.how, sizeof(icd.how), "OCL_ICD_VENDORS=%s, from the environment", set);
		return;
	}
	const char *vendors = vendors_dir();
	if (registered(vendors, names, sizeof(names))) {
		snprintf(icd.how, sizeof(icd.how), "registered in %s: %s", vendors, names);
		return;
	}
	if (!find_drivers(found, list, sizeof(list))) {
		snprintf(icd.how, sizeof(icd.how), "none registered in %s and no driver (%s, %s, %s, "
		         "%s) on LD_LIBRARY_PATH or in %s", vendors, drivers[0], drivers[1],
		         drivers[2], drivers[3], getenv("BVHLAB_CL_DRIVER_DIRS") ?
		         getenv("BVHLAB_CL_DRIVER_DIRS") : default_dirs);
		return;
	}
	const char *tmp = getenv("TMPDIR");
	snprintf(icd.dir, sizeof(icd.dir), "%s/bvhlab-icd-XXXXXX", tmp && *tmp ? tmp : "/tmp");
	bool ok = mkdtemp(icd.dir) != NULL;
	icd.owner = getpid();
	if (ok)
		atexit(remove_private);
	for (size_t k = 0; ok && k < DRIVERS; k++)
		ok = !found[k][0] || write_icd(drivers[k], found[k]);
	if (ok)
		ok = setenv("OCL_ICD_VENDORS", icd.dir, 1) == 0;
	snprintf(icd.how, sizeof(icd.how), "none registered in %s; found %s%s%s", vendors, list,
	         ok ? ", used through OCL_ICD_VENDORS=" : ", but could not write ",
	         ok ? icd.dir : "a vendors folder in TMPDIR");
}

const char *machine_icd_how(void)
{
	return icd.how[0] ? icd.how : "not looked for";
}
