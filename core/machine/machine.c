/* The machine the results record: CPU model, core count and topology. */
#include <stdio.h>
#include <sys/resource.h>
#include <time.h>
#include <string.h>
#include <unistd.h>

#include "machine/machine.h"

static void read_cpu_name(char *out, size_t size)
{
	snprintf(out, size, "unknown");
	FILE *f = fopen("/proc/cpuinfo", "r");
	if (!f)
		return;
	char line[512];
	while (fgets(line, sizeof(line), f)) {
		if (strncmp(line, "model name", 10) != 0)
			continue;
		const char *colon = strchr(line, ':');
		if (!colon)
			break;
		colon++;
		while (*colon == ' ' || *colon == '\t')
			colon++;
		snprintf(out, size, "%.*s", (int)strcspn(colon, "\n"), colon);
		break;
	}
	fclose(f);
}

void machine_info_read(struct machine_info *info)
{
	read_cpu_name(info->cpu, sizeof(info->cpu));
	long n = sysconf(_SC_NPROCESSORS_ONLN);
	info->cores = n > 0 ? (uint32_t)n : 1;
	machine_topology_read(&info->topo);
	info->threads_available = info->topo.physical_cores;
}

double machine_load_average(void)
{
	double load = -1;
	FILE *f = fopen("/proc/loadavg", "r");
	if (!f)
		return -1;
	if (fscanf(f, "%lf", &load) != 1)
		load = -1;
	fclose(f);
	return load;
}

static double tv_s(struct timeval t)
{
	return (double)t.tv_sec + (double)t.tv_usec * 1e-6;
}

/* Busy seconds of all CPUs from /proc/stat's first line, or -1. */
static double machine_busy_s(void)
{
	unsigned long long v[8] = {0};
	FILE *f = fopen("/proc/stat", "r");
	if (!f)
		return -1;
	int n = fscanf(f, "cpu %llu %llu %llu %llu %llu %llu %llu %llu", &v[0], &v[1], &v[2],
	               &v[3], &v[4], &v[5], &v[6], &v[7]);
	fclose(f);
	long hz = sysconf(_SC_CLK_TCK);
	if (n < 8 || hz <= 0)
		return -1;
	/* user nice system idle iowait irq softirq steal: all but idle, iowait */
	return (double)(v[0] + v[1] + v[2] + v[5] + v[6] + v[7]) / (double)hz;
}

void machine_cpu_mark(struct machine_cpu_mark *m)
{
	struct rusage self, children;
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	m->wall_s = (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
	m->machine_s = machine_busy_s();
	getrusage(RUSAGE_SELF, &self);
	getrusage(RUSAGE_CHILDREN, &children);
	m->own_s = tv_s(self.ru_utime) + tv_s(self.ru_stime) + tv_s(children.ru_utime) +
	           tv_s(children.ru_stime);
	m->ok = m->machine_s >= 0;
}

double machine_other_load(const struct machine_cpu_mark *before,
                          const struct machine_cpu_mark *after)
{
	double wall = after->wall_s - before->wall_s;
	if (!before->ok || !after->ok || wall < 0.05)
		return -1;
	double other = (after->machine_s - before->machine_s) - (after->own_s - before->own_s);
	return other > 0 ? other / wall : 0;
}

uint64_t machine_memory_available(void)
{
	FILE *f = fopen("/proc/meminfo", "r");
	char line[256];
	unsigned long long kb = 0;
	if (!f)
		return 0;
	while (fgets(line, sizeof(line), f))
		if (sscanf(line, "MemAvailable: %llu kB", &kb) == 1)
			break;
	fclose(f);
	return (uint64_t)kb * 1024;
}
