/*
 * Morton codes and their stable LSD radix sort on the device, shared by
 * cl_lbvh, cl_ploc and cl_hploc (concatenated before each plugin's own
 * kernels).
 *
 * The codes mirror plugins/common/morton exactly (the host passes the
 * quantiser's lo, scale and top, computed by the same C), and the sort
 * gives the CPU builders' (code, primitive) order: values start as the
 * primitive ids in order and every pass is stable.
 *
 * morton_spread21 comes from plugins/common/morton/morton_spread.h, which
 * the build puts before this file.
 *
 * A pass over one 8-bit digit: radix_hist counts each chunk's digits,
 * radix_scan turns the counts (digit-major: all chunks of digit 0 first)
 * into each chunk's first output position per digit, radix_scatter moves
 * each chunk's keys in order. A chunk is one work-item's contiguous run:
 * simple and stable, and on a CPU device (PoCL) streaming in cache.
 */
#pragma OPENCL FP_CONTRACT OFF

#define RADIX 256u

/* As morton_sort.c's axis(): clamped, NaN to cell 0, truncated. */
static ulong axis_cell(float c, float lo, float scale, float top)
{
	float x = (c - lo) * scale;
	x = x > 0 ? x : 0;
	x = x < top ? x : top;
	return morton_spread21((ulong)(uint)(int)x);
}

__kernel void morton_codes(__global const float *centroids, uint n, float lo0, float lo1,
	float lo2, float s0, float s1, float s2, float top, __global ulong *keys,
	__global uint *vals)
{
	uint i = get_global_id(0);
	if (i >= n)
		return;
	__global const float *c = centroids + 3 * (size_t)i;
	keys[i] = axis_cell(c[0], lo0, s0, top) << 2 | axis_cell(c[1], lo1, s1, top) << 1 |
	          axis_cell(c[2], lo2, s2, top);
	vals[i] = i;
}

/* Which key bits vary, per chunk: the OR of key ^ keys[0]. Digits that
 * vary nowhere need no pass. */
__kernel void morton_varying(__global const ulong *keys, uint n, uint chunk,
	__global ulong *part)
{
	uint c = get_global_id(0);
	size_t lo = (size_t)c * chunk, hi = min((size_t)n, lo + chunk);
	ulong k0 = keys[0], acc = 0;
	if (lo >= n)
		return;
	for (size_t i = lo; i < hi; i++)
		acc |= keys[i] ^ k0;
	part[c] = acc;
}

__kernel void radix_hist(__global const ulong *keys, uint n, uint chunk, uint chunks,
	uint shift, __global uint *hist)
{
	uint c = get_global_id(0), count[RADIX];
	size_t lo = (size_t)c * chunk, hi = min((size_t)n, lo + chunk);
	if (c >= chunks)
		return;
	for (uint d = 0; d < RADIX; d++)
		count[d] = 0;
	for (size_t i = lo; i < hi; i++)
		count[(uint)(keys[i] >> shift) & (RADIX - 1)]++;
	for (uint d = 0; d < RADIX; d++)
		hist[d * chunks + c] = count[d];
}

/* Exclusive prefix over RADIX * chunks counts, in place; one work-item
 * (a few hundred thousand adds at most). */
__kernel void radix_scan(__global uint *hist, uint total)
{
	uint sum = 0;
	if (get_global_id(0) != 0)
		return;
	for (uint k = 0; k < total; k++) {
		uint v = hist[k];
		hist[k] = sum;
		sum += v;
	}
}

__kernel void radix_scatter(__global const ulong *keys, __global const uint *vals,
	__global ulong *keys_out, __global uint *vals_out, uint n, uint chunk, uint chunks,
	uint shift, __global const uint *hist)
{
	uint c = get_global_id(0), at[RADIX];
	size_t lo = (size_t)c * chunk, hi = min((size_t)n, lo + chunk);
	if (c >= chunks)
		return;
	for (uint d = 0; d < RADIX; d++)
		at[d] = hist[d * chunks + c];
	for (size_t i = lo; i < hi; i++) {
		ulong k = keys[i];
		uint d = (uint)(k >> shift) & (RADIX - 1), to = at[d]++;
		keys_out[to] = k;
		vals_out[to] = vals[i];
	}
}

/*
 * The sort's other shape, for a CPU device: passes over all keys on the
 * two highest varying digits only (radix_hist, radix_scan, radix_scatter),
 * then a work-item per bucket of those 16 bits sorts it on the lower
 * varying digits (`digits`: bit k for the digit at 8k): a bucket is some
 * tens of keys to some thousands on a million, so its passes stream in the
 * core's cache, where radix_scatter's passes over the whole array write to
 * 256 places at once across it. 16 bits, not 8, because a scene's
 * primitives can crowd into a few cells of the top digit (the conference
 * room subdivided once: 62 % in one). Still stable from the primitives'
 * order, so the same (code, primitive) order.
 */
#define BUCKETS 65536u
/* Buckets this small are insertion sorted, straight into the buffer where
 * the passes of the others end. */
#define SMALL_BUCKET 32

static uint bucket_of(ulong k, uint s1, uint s2)
{
	return (uint)(k >> s1 & 0xff) << 8 | (uint)(k >> s2 & 0xff);
}

/* Bucket b is [range[2b], range[2b + 1]) of the keys sorted on its two
 * digits (at s1 and s2); range[] zeroed first, so an empty one is [0, 0). */
__kernel void radix_ranges(__global const ulong *keys, uint n, uint s1, uint s2,
	__global uint *range)
{
	uint i = get_global_id(0);
	if (i >= n)
		return;
	uint b = bucket_of(keys[i], s1, s2);
	if (i == 0 || bucket_of(keys[i - 1], s1, s2) != b)
		range[2 * b] = i;
	if (i == n - 1 || bucket_of(keys[i + 1], s1, s2) != b)
		range[2 * b + 1] = i + 1;
}

/* Stable insertion sort of [lo, hi) from (kin, vin) into (kout, vout). */
static void insertion(__global const ulong *kin, __global const uint *vin,
	__global ulong *kout, __global uint *vout, size_t lo, size_t hi)
{
	for (size_t i = lo; i < hi; i++) {
		ulong k = kin[i];
		uint v = vin[i];
		size_t j = i;
		for (; j > lo && kout[j - 1] > k; j--) {
			kout[j] = kout[j - 1];
			vout[j] = vout[j - 1];
		}
		kout[j] = k;
		vout[j] = v;
	}
}

__kernel void radix_buckets(__global ulong *keys, __global uint *vals,
	__global ulong *keys_tmp, __global uint *vals_tmp, __global const uint *range,
	uint digits)
{
	uint b = get_global_id(0), count[RADIX];
	if (b >= BUCKETS)
		return;
	size_t lo = range[2 * b], hi = range[2 * b + 1];
	bool odd = popcount(digits) & 1;
	if (hi - lo <= SMALL_BUCKET) {
		insertion(keys, vals, odd ? keys_tmp : keys, odd ? vals_tmp : vals, lo, hi);
		return;
	}
	__global ulong *kin = keys, *kout = keys_tmp, *kt;
	__global uint *vin = vals, *vout = vals_tmp, *vt;
	for (uint shift = 0; shift < 64; shift += 8) {
		if (!((digits >> (shift / 8)) & 1))
			continue;
		for (uint d = 0; d < RADIX; d++)
			count[d] = 0;
		for (size_t i = lo; i < hi; i++)
			count[(uint)(kin[i] >> shift) & (RADIX - 1)]++;
		uint at = (uint)lo;
		for (uint d = 0; d < RADIX; d++) {
			uint c = count[d];
			count[d] = at;
			at += c;
		}
		for (size_t i = lo; i < hi; i++) {
			ulong k = kin[i];
			uint to = count[(uint)(k >> shift) & (RADIX - 1)]++;
			kout[to] = k;
			vout[to] = vin[i];
		}
		kt = kin, kin = kout, kout = kt;
		vt = vin, vin = vout, vout = vt;
	}
}
