/*
 * PLY loader: the body, in ASCII or binary of either byte order.
 *
 * Uses the `vertex` element's x, y, z, the `face` element's vertex_indices
 * (or vertex_index) list, fan-triangulated, and the `tristrips` element's
 * vertex_indices list (-1 restarts a strip); everything else is skipped.
 * Errors read "PATH:LINE: message" in the header and in ASCII bodies,
 * "PATH: byte offset N: message" in binary bodies.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_ply.h"
#include "scene/scene_private.h"

enum role { ROLE_SKIP, ROLE_VERTEX, ROLE_FACE, ROLE_STRIPS };

struct ply_reader {
	const char *path;
	const unsigned char *data;
	size_t pos, size;
	enum ply_format format;
	bool swap;           /* binary byte order differs from the host's */
	size_t line;         /* ASCII: line of pos */
	size_t value_pos;    /* where the last value read starts */
	size_t value_line;
	const struct ply_element *element; /* being read, for messages */
	uint64_t item;
	long xyz[3];         /* positions of x, y, z among the vertex properties */
	long list;           /* position of the index list in the element being read */
	uint32_t vertex_count;
	struct scene_mesh mesh;
	uint32_t *poly;      /* one face's or strip's indices */
	size_t poly_cap;
	bvhlab_error *err;
};

/* "PATH:LINE: " or "PATH: byte offset N: " for the value read last. */
static int body_error(struct ply_reader *r, const char *fmt, ...) BVHLAB_PRINTF(2, 3);

static int body_error(struct ply_reader *r, const char *fmt, ...)
{
	char msg[400];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(msg, sizeof(msg), fmt, ap);
	va_end(ap);
	if (r->format == PLY_ASCII)
		scene_error(r->err, "%s:%zu: %s", r->path, r->value_line, msg);
	else
		scene_error(r->err, "%s: byte offset %zu: %s", r->path, r->value_pos, msg);
	return -EINVAL;
}

static int truncated(struct ply_reader *r)
{
	return body_error(r, "truncated file: it ends inside element '%s' (at index %llu, "
	                     "%llu declared)", r->element->name, (unsigned long long)r->item,
	                  (unsigned long long)r->element->count);
}

static double decode(const unsigned char *p, enum ply_type type, bool swap)
{
	unsigned char b[8];
	size_t n = ply_type_size(type);
	union {
		int8_t i8;
		uint8_t u8;
		int16_t i16;
		uint16_t u16;
		int32_t i32;
		uint32_t u32;
		float f;
		double d;
	} v;

	for (size_t i = 0; i < n; i++)
		b[i] = swap ? p[n - 1 - i] : p[i];
	memcpy(&v, b, n);
	switch (type) {
	case PLY_INT8: return v.i8;
	case PLY_UINT8: return v.u8;
	case PLY_INT16: return v.i16;
	case PLY_UINT16: return v.u16;
	case PLY_INT32: return v.i32;
	case PLY_UINT32: return v.u32;
	case PLY_FLOAT32: return v.f;
	default: return v.d;
	}
}

static bool in_range(double v, enum ply_type type)
{
	static const double lo[] = { 0, -128, 0, -32768, 0, -2147483648.0, 0 };
	static const double hi[] = { 0, 127, 255, 32767, 65535, 2147483647.0, 4294967295.0 };

	return v >= lo[type] && v <= hi[type];
}

static int read_ascii(struct ply_reader *r, enum ply_type type, double *out)
{
	const char *s = (const char *)r->data + r->pos, *end = (const char *)r->data + r->size;
	char *stop;

	for (; s < end && (*s == ' ' || *s == '\t' || *s == '\r' || *s == '\n'); s++)
		r->line += *s == '\n';
	r->value_pos = (size_t)(s - (const char *)r->data);
	r->value_line = r->line;
	if (s == end) {
		/* Name the last line that has text, not the empty one after it. */
		r->value_line -= r->line > 1 && s[-1] == '\n';
		return truncated(r);
	}
	if (ply_type_is_integer(type))
		*out = (double)strtoll(s, &stop, 10);
	else
		*out = strtod(s, &stop);
	if (stop == s || (stop < end && *stop != ' ' && *stop != '\t' && *stop != '\r' &&
	                  *stop != '\n'))
		return body_error(r, "malformed number in element '%s'", r->element->name);
	if (ply_type_is_integer(type) && !in_range(*out, type))
		return body_error(r, "value out of range of its type in element '%s'",
		                  r->element->name);
	r->pos = (size_t)(stop - (const char *)r->data);
	return 0;
}

/* Any property value, as a double (exact for every PLY integer type). */
static int read_value(struct ply_reader *r, enum ply_type type, double *out)
{
	size_t n = ply_type_size(type);

	if (r->format == PLY_ASCII)
		return read_ascii(r, type, out);
	r->value_pos = r->pos;
	if (r->size - r->pos < n)
		return truncated(r);
	*out = decode(r->data + r->pos, type, r->swap);
	r->pos += n;
	return 0;
}

static int read_list_length(struct ply_reader *r, const struct ply_property *prop, size_t *n)
{
	double v;
	int ret = read_value(r, prop->count_type, &v);

	if (ret)
		return ret;
	if (v < 0)
		return body_error(r, "negative list length in element '%s'", r->element->name);
	*n = (size_t)v;
	return 0;
}

static int skip_property(struct ply_reader *r, const struct ply_property *prop)
{
	size_t n = 1;
	double v;
	int ret = 0;

	if (prop->count_type != PLY_NONE)
		ret = read_list_length(r, prop, &n);
	if (!ret && r->format != PLY_ASCII) {
		if ((r->size - r->pos) / ply_type_size(prop->type) < n)
			return truncated(r);
		r->pos += n * ply_type_size(prop->type);
		return 0;
	}
	for (size_t i = 0; i < n && !ret; i++)
		ret = read_value(r, prop->type, &v);
	return ret;
}

static int read_vertex(struct ply_reader *r)
{
	const struct ply_element *e = r->element;
	float xyz[3] = { 0, 0, 0 };
	double v;
	int ret;

	for (size_t i = 0; i < e->prop_count; i++) {
		int k = 0;

		while (k < 3 && r->xyz[k] != (long)i)
			k++;
		if (k == 3) {
			ret = skip_property(r, &e->props[i]);
			if (ret)
				return ret;
			continue;
		}
		ret = read_value(r, e->props[i].type, &v);
		if (ret)
			return ret;
		xyz[k] = (float)v;
		if (!isfinite(xyz[k]))
			return body_error(r, "vertex %llu: coordinate %c is NaN or infinite",
			                  (unsigned long long)r->item, "xyz"[k]);
		if (fabsf(xyz[k]) > SCENE_MAX_COORD)
			return body_error(r, "vertex %llu: coordinate %c is %g, beyond +-1e18 (a box's "
			                  "squared extent would overflow float)",
			                  (unsigned long long)r->item, "xyz"[k], (double)xyz[k]);
	}
	scene_mesh_put_vertex(&r->mesh, xyz[0], xyz[1], xyz[2]);
	return 0;
}

/* Reads a list of vertex indices into r->poly; -1 passes when allowed. */
static int read_index_list(struct ply_reader *r, const struct ply_property *prop, size_t *count,
                           bool allow_restart)
{
	size_t n = 0;
	double v;
	int ret = read_list_length(r, prop, &n);

	if (ret)
		return ret;
	/* Each index takes at least one byte: a bigger list is a truncated file,
	 * not an allocation to attempt. */
	if (n > r->size - r->pos)
		return truncated(r);
	if (n > r->poly_cap) {
		uint32_t *p = realloc(r->poly, n * sizeof(uint32_t));
		if (!p)
			return body_error(r, "out of memory for a list of %zu indices", n);
		r->poly = p;
		r->poly_cap = n;
	}
	for (size_t i = 0; i < n; i++) {
		ret = read_value(r, prop->type, &v);
		if (ret)
			return ret;
		if (v < 0 && !(allow_restart && v == -1))
			return body_error(r, "negative vertex index %.0f", v);
		if (v >= r->vertex_count)
			return body_error(r, "vertex index %.0f out of range (%u vertices)", v,
			                  r->vertex_count);
		r->poly[i] = v < 0 ? UINT32_MAX : (uint32_t)v;
	}
	*count = n;
	return 0;
}

static int emit_face(struct ply_reader *r, size_t n)
{
	if (n < 3)
		return body_error(r, "face %llu has %zu vertices (needs at least 3)",
		                  (unsigned long long)r->item, n);
	if (scene_mesh_reserve(&r->mesh, 0, n - 2))
		return body_error(r, "out of memory");
	for (size_t i = 1; i + 1 < n; i++)
		scene_mesh_put_triangle(&r->mesh, r->poly[0], r->poly[i], r->poly[i + 1]);
	return 0;
}

/* Strips alternate winding; triangles with a repeated index only join
 * strips together and are dropped, the parity still advances. */
static int emit_strip(struct ply_reader *r, size_t n)
{
	size_t k = 0; /* position in the current strip */

	if (scene_mesh_reserve(&r->mesh, 0, n))
		return body_error(r, "out of memory");
	for (size_t i = 0; i < n; i++, k++) {
		uint32_t a, b, c = r->poly[i];

		if (c == UINT32_MAX) {
			k = (size_t)-1;
			continue;
		}
		if (k < 2)
			continue;
		a = r->poly[i - 2 + (k & 1)];
		b = r->poly[i - 1 - (k & 1)];
		if (a != b && b != c && a != c)
			scene_mesh_put_triangle(&r->mesh, a, b, c);
	}
	return 0;
}

/* One face or strip item: its index list and any other properties. */
static int read_polygon(struct ply_reader *r, enum role role)
{
	const struct ply_element *e = r->element;
	size_t n = 0;
	int ret;

	for (size_t i = 0; i < e->prop_count; i++) {
		if ((long)i == r->list)
			ret = read_index_list(r, &e->props[i], &n, role == ROLE_STRIPS);
		else
			ret = skip_property(r, &e->props[i]);
		if (ret)
			return ret;
	}
	return role == ROLE_STRIPS ? emit_strip(r, n) : emit_face(r, n);
}

static int read_item(struct ply_reader *r, enum role role)
{
	int ret = 0;

	switch (role) {
	case ROLE_VERTEX:
		return read_vertex(r);
	case ROLE_FACE:
	case ROLE_STRIPS:
		return read_polygon(r, role);
	default:
		for (size_t i = 0; i < r->element->prop_count && !ret; i++)
			ret = skip_property(r, &r->element->props[i]);
		return ret;
	}
}

/* Smallest possible size of one item: refuses absurd counts before any
 * allocation is sized by them. */
static size_t min_item_size(const struct ply_element *e, enum ply_format format)
{
	size_t size = 0;

	for (size_t i = 0; i < e->prop_count; i++) {
		const struct ply_property *p = &e->props[i];

		if (format == PLY_ASCII)
			size += 2; /* a digit and a separator */
		else
			size += ply_type_size(p->count_type ? p->count_type : p->type);
	}
	return size;
}

static int read_element(struct ply_reader *r, const struct ply_element *e, enum role role)
{
	size_t min = min_item_size(e, r->format);
	int ret;

	r->element = e;
	r->item = 0;
	r->value_pos = r->pos;
	r->value_line = r->line;
	if (e->prop_count == 0) /* nothing to read, however many items */
		return 0;
	if (e->count > (r->size - r->pos) / min + 1)
		return truncated(r);
	if (role == ROLE_VERTEX && scene_mesh_reserve(&r->mesh, e->count, 0))
		return body_error(r, "out of memory for %llu vertices",
		                  (unsigned long long)e->count);
	for (r->item = 0; r->item < e->count; r->item++) {
		ret = read_item(r, role);
		if (ret)
			return ret;
	}
	return 0;
}

static int header_error(struct ply_reader *r, size_t line, const char *fmt, ...)
	BVHLAB_PRINTF(3, 4);

static int header_error(struct ply_reader *r, size_t line, const char *fmt, ...)
{
	char msg[400];
	va_list ap;

	va_start(ap, fmt);
	vsnprintf(msg, sizeof(msg), fmt, ap);
	va_end(ap);
	scene_error(r->err, "%s:%zu: %s", r->path, line, msg);
	return -EINVAL;
}

static int find_xyz(struct ply_reader *r, const struct ply_element *e)
{
	for (int k = 0; k < 3; k++) {
		const char name[2] = { "xyz"[k], '\0' };

		r->xyz[k] = ply_find_property(e, name);
		if (r->xyz[k] < 0)
			return header_error(r, e->line, "element 'vertex' has no property '%s'",
			                    name);
		if (e->props[r->xyz[k]].count_type != PLY_NONE)
			return header_error(r, e->line, "vertex property '%s' is a list", name);
	}
	if (e->count > UINT32_MAX)
		return header_error(r, e->line, "%llu vertices, more than the %u a scene can hold",
		                    (unsigned long long)e->count, UINT32_MAX);
	r->vertex_count = (uint32_t)e->count;
	return 0;
}

static int find_index_list(struct ply_reader *r, const struct ply_element *e, long *list)
{
	*list = ply_find_property(e, "vertex_indices");
	if (*list < 0)
		*list = ply_find_property(e, "vertex_index");
	if (*list < 0)
		return header_error(r, e->line, "element '%s' has no vertex_indices list", e->name);
	if (e->props[*list].count_type == PLY_NONE || !ply_type_is_integer(e->props[*list].type))
		return header_error(r, e->line, "'%s' of element '%s' must be a list of integers",
		                    e->props[*list].name, e->name);
	return 0;
}

/* Decides what each element is read for; only the first of each kind counts. */
static int assign_roles(struct ply_reader *r, const struct ply_header *h, enum role *roles,
                        long *lists)
{
	bool vertex = false, faces = false;
	int ret = 0;

	for (size_t i = 0; i < h->element_count && !ret; i++) {
		const struct ply_element *e = &h->elements[i];

		roles[i] = ROLE_SKIP;
		if (!vertex && strcmp(e->name, "vertex") == 0) {
			roles[i] = ROLE_VERTEX;
			vertex = true;
			ret = find_xyz(r, e);
		} else if (strcmp(e->name, "face") == 0 || strcmp(e->name, "tristrips") == 0) {
			roles[i] = e->name[0] == 'f' ? ROLE_FACE : ROLE_STRIPS;
			faces = true;
			ret = find_index_list(r, e, &lists[i]);
		}
	}
	if (!ret && !vertex)
		ret = header_error(r, h->end_line, "no 'vertex' element");
	if (!ret && !faces)
		ret = header_error(r, h->end_line, "no faces: neither a 'face' nor a 'tristrips' "
		                                   "element");
	return ret;
}

static bool host_little_endian(void)
{
	const uint16_t one = 1;
	unsigned char first;

	memcpy(&first, &one, 1);
	return first == 1;
}

/* Data past the last element means the header's counts are wrong: say so
 * rather than build a scene from part of the file. Trailing blanks are fine. */
static int check_end(struct ply_reader *r, const struct ply_header *h)
{
	size_t pos = r->pos;

	while (pos < r->size && strchr(" \t\r\n", r->data[pos]) && r->data[pos])
		r->line += r->data[pos++] == '\n';
	if (pos == r->size)
		return 0;
	r->element = &h->elements[h->element_count - 1];
	r->value_pos = pos;
	r->value_line = r->line;
	return body_error(r, "%zu bytes of data after the last element '%s' (wrong element "
	                     "counts in the header?)", r->size - pos, r->element->name);
}

static int read_body(struct ply_reader *r, const struct ply_header *h)
{
	enum role *roles = calloc(h->element_count + 1, sizeof(*roles));
	long *lists = calloc(h->element_count + 1, sizeof(*lists));
	int ret = -ENOMEM;

	if (!roles || !lists) {
		scene_error(r->err, "%s: out of memory", r->path);
		goto out;
	}
	ret = assign_roles(r, h, roles, lists);
	r->format = h->format;
	r->swap = h->format != PLY_ASCII && (h->format == PLY_BINARY_LE) != host_little_endian();
	r->pos = h->body_offset;
	r->line = h->body_line;
	for (size_t i = 0; i < h->element_count && !ret; i++) {
		r->list = lists[i];
		ret = read_element(r, &h->elements[i], roles[i]);
	}
	if (!ret)
		ret = check_end(r, h);
	if (!ret && r->mesh.triangle_count == 0)
		ret = header_error(r, h->end_line, "no faces: the file has no triangles");
out:
	free(roles);
	free(lists);
	return ret;
}

int bvhlab_scene_load_ply(const char *path, bvhlab_scene **out, bvhlab_error *err)
{
	struct ply_reader r = { .path = path, .err = err };
	struct ply_header header = { 0 };
	char *data = NULL;
	int ret;

	ret = scene_read_file(path, &data, &r.size, err);
	if (ret)
		return ret;
	r.data = (const unsigned char *)data;
	ret = ply_header_parse(path, data, r.size, &header, err);
	if (!ret)
		ret = read_body(&r, &header);
	if (!ret)
		ret = scene_mesh_finish(&r.mesh, path, out, err);
	scene_mesh_free(&r.mesh);
	ply_header_free(&header);
	free(r.poly);
	free(data);
	return ret;
}
