/*
 * A run's report from its child, into the run's record (harness_report.h).
 */
#include "harness/harness_report.h"
#include "harness/harness_two_level.h"

/* A report from a child is checked before use: the child ran foreign code. */
void harness_report_to_run(struct series_report *rep, uint32_t repeat, uint32_t frames,
                           struct run_record *run)
{
	static const char *const names[] = {"ok", "invalid", "failed"};
	rep->error[sizeof(rep->error) - 1] = '\0';
	if (rep->status > SERIES_FAILED || rep->sample_count > repeat ||
	    rep->stage_count > HARNESS_MAX_STAGES || rep->phase_count > BVHLAB_MAX_PHASES ||
	    rep->frame_count > frames) {
		run->status = "crashed";
		run->error = "sent back a malformed report";
		return;
	}
	run->status = names[rep->status];
	run->error = rep->status != SERIES_OK ? rep->error : NULL;
	run->samples_ms = rep->samples;
	run->sample_count = rep->sample_count;
	run->cold_ms = rep->cold_ms;
	run->stats = rep->tree.has_stats ? &rep->tree.stats : NULL;
	run->width = rep->tree.width;
	run->epo = rep->tree.has_epo ? &rep->tree.epo : NULL;
	run->memory = rep->memory.measured ? &rep->memory : NULL;
	run->device = rep->has_device ? harness_memory_device_checked(&rep->device) : NULL;
	run->validated = rep->validated;
	run->valid = rep->tree.valid;
	run->rays_checked = rep->tree.rays_checked;
	run->mismatches = rep->tree.mismatches;
	rep->rays.error[sizeof(rep->rays.error) - 1] = '\0';
	rep->rays.device[sizeof(rep->rays.device) - 1] = '\0';
	run->rays = rep->rays.measured || rep->rays.error[0] ? &rep->rays : NULL;
	for (uint32_t k = 0; k < rep->stage_count; k++)
		rep->stages[k].plugin[sizeof(rep->stages[k].plugin) - 1] = '\0';
	run->stages = rep->stages;
	run->stage_count = rep->stage_count;
	for (uint32_t k = 0; k < rep->phase_count; k++)
		rep->phases[k].name[sizeof(rep->phases[k].name) - 1] = '\0';
	run->phases = rep->phases;
	run->phase_count = rep->phase_count;
	run->frames = (const struct frame_metrics *)(rep->samples + repeat);
	run->frame_count = rep->frame_count;
	run->two_level = rep->status == SERIES_OK ? harness_two_level_checked(&rep->two_level) : NULL;
}
