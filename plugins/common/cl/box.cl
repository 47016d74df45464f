/*
 * A record's box between global memory and a private copy, for the device
 * builders whose records keep it as lo[3] and hi[3] (cl_lbvh's nodes,
 * cl_hploc's clusters). Volatile: other work-items write those records,
 * published by the atomics around the reads and writes, so no copy may be
 * kept in registers. Put before morton_sort.cl by the build (meson's
 * cl_sort_source), so every device builder's program has them.
 */
static inline void box_load(float *lo, float *hi, volatile __global const float *glo,
	volatile __global const float *ghi)
{
	for (int k = 0; k < 3; k++) {
		lo[k] = glo[k];
		hi[k] = ghi[k];
	}
}

static inline void box_store(volatile __global float *glo, volatile __global float *ghi,
	const float *lo, const float *hi)
{
	for (int k = 0; k < 3; k++) {
		glo[k] = lo[k];
		ghi[k] = hi[k];
	}
}
