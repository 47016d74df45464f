/* The machine the results record: CPU model, core count and topology. */
#include <stdio.h>
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
