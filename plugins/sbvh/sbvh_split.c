/*
 * Choosing a split for the sbvh plugin: binned object splits over the
 * references' centroids, binned spatial splits over the node's box with
 * every reference clipped exactly into the bins it crosses, Stich's alpha
 * test for when spatial splits are worth trying, and reference
 * unsplitting when a cut reference is cheaper left whole on one side.
 *
 * Costs are SAH in units of the node's area with c_trav = c_isect = 1:
 * 1 + (A_L * N_L + A_R * N_R) / A, against N for a leaf.
 */
#include <math.h>
#include <string.h>

#include <bvhlab/aabb.h>

#include "sah_simd.h"
#include "sbvh.h"
#include "tri_clip.h"

void sbvh_bins_clear(sbvh_bins *b, uint32_t bins)
{
	for (int a = 0; a < 3; a++)
		for (uint32_t i = 0; i < bins; i++) {
			bvhlab_box_empty(b->lo[a][i], b->hi[a][i]);
			b->count[a][i] = b->exits[a][i] = 0;
		}
}

void sbvh_bins_merge(sbvh_bins *to, const sbvh_bins *from, uint32_t bins)
{
	for (int a = 0; a < 3; a++)
		for (uint32_t i = 0; i < bins; i++) {
			bvhlab_box_grow(to->lo[a][i], to->hi[a][i], from->lo[a][i], from->hi[a][i]);
			to->count[a][i] += from->count[a][i];
			to->exits[a][i] += from->exits[a][i];
		}
}

void sbvh_centroid_bounds(const sbvh_build *B, const sbvh_job *job, uint32_t begin,
                          uint32_t end, float clo[3], float chi[3])
{
	const sbvh_ref *refs = B->refs[job->buf];

	bvhlab_box_empty(clo, chi);
	for (uint32_t i = begin; i < end; i++)
		for (int k = 0; k < 3; k++) {
			float c = 0.5f * (refs[i].lo[k] + refs[i].hi[k]);
			clo[k] = bvhlab_minf(clo[k], c);
			chi[k] = bvhlab_maxf(chi[k], c);
		}
}

/* Centroid bin along axis k; the same function bins and places. */
static uint32_t object_bin(const sbvh_ref *r, int k, float clo, float scale, uint32_t bins)
{
	float c = 0.5f * (r->lo[k] + r->hi[k]);
	int64_t i = (int64_t)((c - clo) * scale);

	return i < 0 ? 0 : i >= (int64_t)bins ? bins - 1 : (uint32_t)i;
}

static float object_scale(const float clo[3], const float chi[3], int k, uint32_t bins)
{
	float ext = chi[k] - clo[k];

	return ext > 0.0f ? (float)bins * 0.99999f / ext : 0.0f;
}

/* Grows bin j of axis k by a reference's box, loaded as two vectors. */
static inline void bin_grow(sbvh_bins *b, int k, uint32_t j, v4 lo, v4 hi)
{
	v4_store(b->lo[k][j], v4_min(v4_load(b->lo[k][j]), lo));
	v4_store(b->hi[k][j], v4_max(v4_load(b->hi[k][j]), hi));
}

/* One pass for the three axes: a reference is read once, and its box
 * grows each axis's bin with one vector min and max (a reference's lo and
 * hi are each followed by a 32-bit field, so four floats are readable). */
void sbvh_bin_object(const sbvh_build *B, const sbvh_job *job, const float clo[3],
                     const float chi[3], uint32_t begin, uint32_t end, sbvh_bins *b)
{
	sbvh_bin_object_refs(B->refs[job->buf], B->opt.bins, clo, chi, begin, end, b);
}

void sbvh_bin_object_refs(const sbvh_ref *refs, uint32_t bins, const float clo[3],
                          const float chi[3], uint32_t begin, uint32_t end, sbvh_bins *b)
{
	float scale[3];

	sbvh_bins_clear(b, bins);
	for (int k = 0; k < 3; k++)
		scale[k] = object_scale(clo, chi, k, bins);
	for (uint32_t i = begin; i < end; i++) {
		const sbvh_ref *r = &refs[i];
		v4 lo = v4_load(r->lo), hi = v4_load(r->hi);

		for (int k = 0; k < 3; k++) {
			uint32_t j = object_bin(r, k, clo[k], scale[k], bins);

			bin_grow(b, k, j, lo, hi);
			b->count[k][j]++;
		}
	}
}

/* The plane between spatial bins j and j + 1 along axis k. */
static float plane(const sbvh_job *job, int k, uint32_t j, uint32_t bins)
{
	return job->lo[k] + (job->hi[k] - job->lo[k]) * ((float)(j + 1) / (float)bins);
}

/* A node's spatial planes and bin scale per axis, computed once per node
 * (binning asked plane() for them a few times per reference, each a
 * division): plane[k][j] is plane(job, k, j, bins), the same float. */
typedef struct spatial_grid {
	float plane[3][SBVH_MAX_BINS];
	float scale[3];
} spatial_grid;

static void grid_init(spatial_grid *g, const sbvh_job *job, uint32_t bins)
{
	for (int k = 0; k < 3; k++) {
		float ext = job->hi[k] - job->lo[k];
		g->scale[k] = ext > 0.0f ? (float)bins / ext : 0.0f;
		for (uint32_t j = 0; j < bins; j++)
			g->plane[k][j] = plane(job, k, j, bins);
	}
}

/* Spatial bin of coordinate x along k, made consistent with the planes. */
static uint32_t spatial_bin(const spatial_grid *g, const sbvh_job *job, int k, float x,
                            uint32_t bins)
{
	int64_t i = (int64_t)((x - job->lo[k]) * g->scale[k]);
	uint32_t j = i < 0 ? 0 : i >= (int64_t)bins ? bins - 1 : (uint32_t)i;

	while (j > 0 && x < g->plane[k][j - 1])
		j--;
	while (j + 1 < bins && x > g->plane[k][j])
		j++;
	return j;
}

static void load_triangle(const sbvh_build *B, uint32_t prim, float v[3][3])
{
	const uint32_t *tri = &B->in->indices[3 * (size_t)prim];

	for (int j = 0; j < 3; j++)
		memcpy(v[j], &B->in->vertices[3 * (size_t)tri[j]], sizeof(v[j]));
}

/* Adds the points where the triangle's edges cross x[k] = at. */
static void add_crossings(const float v[3][3], int k, float at, float lo[3], float hi[3])
{
	for (int e = 0; e < 3; e++) {
		const float *a = v[e], *b = v[e == 2 ? 0 : e + 1];
		if (!((a[k] < at && at < b[k]) || (b[k] < at && at < a[k])))
			continue;
		float t = (at - a[k]) / (b[k] - a[k]), p[3];
		for (int m = 0; m < 3; m++)
			p[m] = a[m] + t * (b[m] - a[m]);
		p[k] = at;
		bvhlab_box_grow(lo, hi, p, p);
	}
}

/*
 * A reference crossing bins b0 < b1 along k: the box of its triangle's
 * part in each bin's slab, cut down to the reference's box. Binning only
 * estimates a split's cost, so this is Embree's cheap bound (the slab
 * piece of the whole triangle, O(1) per plane from the edges' crossings)
 * instead of clipping the reference's polygon; the references a split
 * actually cuts are clipped exactly (sbvh_place). Float rounding here
 * only moves an estimate.
 */
static void clip_into_bins(const spatial_grid *g, const float v[3][3], const sbvh_ref *r,
                           int k, uint32_t b0, uint32_t b1, sbvh_bins *b)
{
	float below = -INFINITY, clo[3], chi[3]; /* crossings of `below` */

	bvhlab_box_empty(clo, chi);
	for (uint32_t j = b0; j <= b1; j++) {
		float above = j < b1 ? g->plane[k][j] : INFINITY, lo[3], hi[3];
		bvhlab_box_empty(lo, hi);
		for (int m = 0; m < 3; m++)
			if (below <= v[m][k] && v[m][k] <= above)
				bvhlab_box_grow(lo, hi, v[m], v[m]);
		/* A plane's crossings bound both bins beside it: found once. */
		bvhlab_box_grow(lo, hi, clo, chi);
		bvhlab_box_empty(clo, chi);
		if (j < b1)
			add_crossings(v, k, above, clo, chi);
		bvhlab_box_grow(lo, hi, clo, chi);
		for (int m = 0; m < 3; m++) {
			lo[m] = bvhlab_maxf(lo[m], r->lo[m]);
			hi[m] = bvhlab_minf(hi[m], r->hi[m]);
		}
		if (lo[0] <= hi[0] && lo[1] <= hi[1] && lo[2] <= hi[2])
			bvhlab_box_grow(b->lo[k][j], b->hi[k][j], lo, hi);
		below = above;
	}
	b->count[k][b0]++;
	b->exits[k][b1]++;
}

void sbvh_bin_spatial(const sbvh_build *B, const sbvh_job *job, uint32_t begin,
                      uint32_t end, sbvh_bins *b)
{
	const sbvh_ref *refs = B->refs[job->buf];
	uint32_t bins = B->opt.bins;
	spatial_grid g;

	sbvh_bins_clear(b, bins);
	grid_init(&g, job, bins);
	/* One pass: a reference, and its triangle if an axis clips it, are
	 * read once for the three axes. */
	for (uint32_t i = begin; i < end; i++) {
		const sbvh_ref *r = &refs[i];
		float v[3][3];
		bool have_v = false;

		for (int k = 0; k < 3; k++) {
			if (!(g.scale[k] > 0.0f))
				continue;
			uint32_t b0 = spatial_bin(&g, job, k, r->lo[k], bins);
			uint32_t b1 = spatial_bin(&g, job, k, r->hi[k], bins);

			if (b0 == b1) {
				bin_grow(b, k, b0, v4_load(r->lo), v4_load(r->hi));
				b->count[k][b0]++;
				b->exits[k][b0]++;
			} else {
				if (!have_v)
					load_triangle(B, r->prim, v);
				have_v = true;
				clip_into_bins(&g, (const float(*)[3])v, r, k, b0, b1, b);
			}
		}
	}
}

/* Bins of axis k that hold anything: a box, an entry or an exit. */
static uint32_t used_bins(const sbvh_bins *b, int k, uint32_t bins, const uint32_t *enter,
                          const uint32_t *leave, uint32_t *used)
{
	uint32_t m = 0;

	for (uint32_t j = 0; j < bins; j++)
		if (b->lo[k][j][0] <= b->hi[k][j][0] || enter[j] || leave[j])
			used[m++] = j;
	return m;
}

/*
 * Sweeps one axis's bins: the best boundary by SAH. enter/leave: counts of
 * the left side (bins <= j) and right side (bins > j). Only bins that hold
 * something are visited: past an unused bin both sides and the cost are
 * those of the boundary before it, which the strict < already prefers, so
 * the split is the same as over every bin, and small nodes (a few used
 * bins of 32) sweep a few bins, not all.
 */
static void sweep(const sbvh_bins *b, int k, uint32_t bins, const uint32_t *enter,
                  const uint32_t *leave, double inv_area, sbvh_split *best, int kind)
{
	float rlo[SBVH_MAX_BINS][4], rhi[SBVH_MAX_BINS][4], llo[4], lhi[4];
	uint32_t rn[SBVH_MAX_BINS], used[SBVH_MAX_BINS], n = 0;
	uint32_t m = used_bins(b, k, bins, enter, leave, used);
	v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY);

	/* rlo[u], rhi[u], rn[u]: the right side of the boundary before used[u]. */
	for (uint32_t u = m; u-- > 1;) {
		lo = v4_min(lo, v4_load(b->lo[k][used[u]]));
		hi = v4_max(hi, v4_load(b->hi[k][used[u]]));
		n += leave[used[u]];
		v4_store(rlo[u], lo);
		v4_store(rhi[u], hi);
		rn[u] = n;
	}
	lo = v4_set1(INFINITY);
	hi = v4_set1(-INFINITY);
	n = 0;
	for (uint32_t u = 0; u + 1 < m; u++) {
		uint32_t j = used[u];
		lo = v4_min(lo, v4_load(b->lo[k][j]));
		hi = v4_max(hi, v4_load(b->hi[k][j]));
		n += enter[j];
		if (n == 0 || rn[u + 1] == 0)
			continue;
		v4_store(llo, lo);
		v4_store(lhi, hi);
		double cost = 1.0 + (bvhlab_box_area(llo, lhi) * n +
		                     bvhlab_box_area(rlo[u + 1], rhi[u + 1]) * rn[u + 1]) * inv_area;
		if (cost < best->cost) {
			best->cost = cost;
			best->kind = kind;
			best->axis = k;
			best->bin = j;
			best->nl = n;
			best->nr = rn[u + 1];
			memcpy(best->llo, llo, sizeof(best->llo));
			memcpy(best->lhi, lhi, sizeof(best->lhi));
			memcpy(best->rlo, rlo[u + 1], sizeof(best->rlo));
			memcpy(best->rhi, rhi[u + 1], sizeof(best->rhi));
		}
	}
}

void sbvh_best_object(const sbvh_build *B, const sbvh_job *job, const sbvh_bins *b,
                      const float clo[3], const float chi[3], sbvh_split *s)
{
	double a = bvhlab_box_area(job->lo, job->hi), inv = a > 0.0 ? 1.0 / a : 0.0;

	for (int k = 0; k < 3; k++)
		if (chi[k] > clo[k])
			sweep(b, k, B->opt.bins, b->count[k], b->count[k], inv, s, SPLIT_OBJECT);
	memcpy(s->clo, clo, sizeof(s->clo));
	memcpy(s->chi, chi, sizeof(s->chi));
}

void sbvh_best_spatial(const sbvh_build *B, const sbvh_job *job, const sbvh_bins *b,
                       sbvh_split *s)
{
	double a = bvhlab_box_area(job->lo, job->hi), inv = a > 0.0 ? 1.0 / a : 0.0;
	int kind = s->kind;

	for (int k = 0; k < 3; k++)
		if (job->hi[k] > job->lo[k])
			sweep(b, k, B->opt.bins, b->count[k], b->exits[k], inv, s, SPLIT_SPATIAL);
	if (s->kind == SPLIT_SPATIAL && kind != SPLIT_SPATIAL)
		s->pos = plane(job, s->axis, s->bin, B->opt.bins);
}

/*
 * Stich's alpha against the root's area, and (as Embree's builder does) a
 * share of the node's own area: deep down, where nodes are small, an
 * overlap above alpha of the root can still be a sliver of the node, and
 * spatial binning there costs far more than the rare split it finds
 * (courtyard, without this test: 38 % of a 1-thread build in spatial
 * binning; with it, 620 against 804 ms at 2 threads, SAH 17.8503 against
 * 17.8481).
 */
bool sbvh_try_spatial(const sbvh_build *B, const sbvh_job *job, const sbvh_split *s)
{
	float lo[3], hi[3];
	double overlap;

	if (s->kind != SPLIT_OBJECT)
		return true; /* no object split at all: maybe a spatial one */
	for (int k = 0; k < 3; k++) {
		lo[k] = bvhlab_maxf(s->llo[k], s->rlo[k]);
		hi[k] = bvhlab_minf(s->lhi[k], s->rhi[k]);
		if (!(hi[k] >= lo[k]))
			return false;
	}
	overlap = bvhlab_box_area(lo, hi);
	return overlap > B->opt.alpha * B->root_area &&
	       overlap >= B->opt.overlap * bvhlab_box_area(job->lo, job->hi);
}

/* Stich's reference unsplitting: 1 (all left), 2 (all right) or 3 (cut). */
static unsigned unsplit(const sbvh_split *s, const sbvh_ref *r)
{
	float lo[3], hi[3];
	double al = bvhlab_box_area(s->llo, s->lhi), ar = bvhlab_box_area(s->rlo, s->rhi);
	double cut = al * s->nl + ar * s->nr, to_left, to_right;

	memcpy(lo, s->llo, sizeof(lo));
	memcpy(hi, s->lhi, sizeof(hi));
	bvhlab_box_grow(lo, hi, r->lo, r->hi);
	to_left = bvhlab_box_area(lo, hi) * s->nl + ar * (s->nr - 1);
	memcpy(lo, s->rlo, sizeof(lo));
	memcpy(hi, s->rhi, sizeof(hi));
	bvhlab_box_grow(lo, hi, r->lo, r->hi);
	to_right = al * (s->nl - 1) + bvhlab_box_area(lo, hi) * s->nr;
	if (to_left < cut && to_left <= to_right)
		return 1;
	return to_right < cut ? 2 : 3;
}

static void set_box(sbvh_ref *to, const sbvh_ref *from, const bvhlab_aabb *box)
{
	*to = *from;
	memcpy(to->lo, box->lo, sizeof(to->lo));
	memcpy(to->hi, box->hi, sizeof(to->hi));
}

unsigned sbvh_place(const sbvh_build *B, const sbvh_split *s, const sbvh_ref *ref,
                    sbvh_ref *l, sbvh_ref *r)
{
	int k = s->axis;
	unsigned side;

	if (s->kind == SPLIT_OBJECT) {
		float scale = object_scale(s->clo, s->chi, k, B->opt.bins);
		side = object_bin(ref, k, s->clo[k], scale, B->opt.bins) <= s->bin ? 1 : 2;
	} else {
		side = ref->hi[k] <= s->pos ? 1 : ref->lo[k] >= s->pos ? 2 : unsplit(s, ref);
	}
	if (side != 3) {
		*(side == 1 ? l : r) = *ref;
		return side;
	}
	const bvhlab_aabb box = { { ref->lo[0], ref->lo[1], ref->lo[2] },
		                  { ref->hi[0], ref->hi[1], ref->hi[2] } };
	bvhlab_aabb lb, rb;
	tri_clip_split(B->in->vertices, &B->in->indices[3 * (size_t)ref->prim], &box, k, s->pos,
	               &lb, &rb);
	bool has_l = lb.lo[0] <= lb.hi[0], has_r = rb.lo[0] <= rb.hi[0];
	if (has_l)
		set_box(l, ref, &lb);
	if (has_r)
		set_box(r, ref, &rb);
	if (!has_l && !has_r)
		*l = *ref; /* rounding lost the triangle: keep the reference whole */
	/* Rounding can leave a reference straddling the plane with nothing of
	 * its triangle on one side: it goes to the other side only. */
	return has_l && has_r ? 3 : has_r ? 2 : 1;
}
