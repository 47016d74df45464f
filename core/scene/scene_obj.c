/*
 * Wavefront OBJ loader: positions and faces only.
 *
 * The whole file is read into memory and parsed in place, line by line;
 * this is several times faster than stdio scanning on meshes of 100K+
 * triangles. Errors read "PATH:LINE: message".
 */
#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_private.h"

struct obj_parser {
	const char *path;
	size_t line;            /* 1-based number of the current line */
	struct scene_mesh mesh;
	uint32_t *face;         /* vertex indices of the polygon being read */
	size_t face_cap;
	/* Positive indices may point forward (to later `v` lines), so they are
	 * checked once all vertices are known; remember the worst one. */
	uint64_t max_index;
	size_t max_index_line;
	struct scene_load_stats stats;
	bvhlab_error *err;
};

static bool is_space(char c)
{
	return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

static const char *skip_space(const char *s, const char *end)
{
	while (s < end && is_space(*s))
		s++;
	return s;
}

/* End of the token at s: the next blank or the end of the line. */
static const char *token_end(const char *s, const char *end)
{
	while (s < end && !is_space(*s))
		s++;
	return s;
}

static bool token_is(const char *s, const char *e, const char *word)
{
	size_t n = strlen(word);

	return (size_t)(e - s) == n && memcmp(s, word, n) == 0;
}

static int parse_error(struct obj_parser *p, const char *what, const char *s, const char *end)
{
	const char *e = token_end(s, end);
	int n = (int)(e - s > 40 ? 40 : e - s);

	scene_error(p->err, "%s:%zu: %s '%.*s'", p->path, p->line, what, n, s);
	return -EINVAL;
}

/* One coordinate; strtof would skip a newline, so a blank was skipped
 * before and the token must not be empty. */
static int parse_coord(struct obj_parser *p, const char **s, const char *end, float *out)
{
	const char *start = skip_space(*s, end);
	char *stop;

	if (start >= end || *start == '#') {
		scene_error(p->err, "%s:%zu: vertex needs 3 coordinates", p->path, p->line);
		return -EINVAL;
	}
	*out = strtof(start, &stop);
	if (stop == start || (stop < end && !is_space(*stop) && *stop != '#'))
		return parse_error(p, "malformed number", start, end);
	if (!isfinite(*out))
		return parse_error(p, "coordinate is NaN or infinite:", start, end);
	if (fabsf(*out) > SCENE_MAX_COORD)
		return parse_error(p, "coordinate beyond +-1e18 (a box's squared extent would "
		                   "overflow float):", start, end);
	*s = stop;
	return 0;
}

static int parse_vertex(struct obj_parser *p, const char *s, const char *end)
{
	float xyz[3];
	int ret;

	for (int k = 0; k < 3; k++) {
		ret = parse_coord(p, &s, end, &xyz[k]);
		if (ret)
			return ret;
	}
	/* A `w` or vertex colours may follow; they do not matter here. */
	if (p->mesh.vertex_count == p->mesh.vertex_cap && scene_mesh_reserve(&p->mesh, 1, 0)) {
		scene_error(p->err, "%s:%zu: out of memory", p->path, p->line);
		return -ENOMEM;
	}
	scene_mesh_put_vertex(&p->mesh, xyz[0], xyz[1], xyz[2]);
	return 0;
}

/* An optionally signed integer; false when there are no digits. Values are
 * clamped far beyond any valid index, so overflow cannot wrap around. */
static bool parse_int(const char **s, const char *end, int64_t *out)
{
	const char *q = *s;
	bool neg = q < end && *q == '-';
	int64_t v = 0;

	if (q < end && (*q == '-' || *q == '+'))
		q++;
	if (q >= end || *q < '0' || *q > '9')
		return false;
	for (; q < end && *q >= '0' && *q <= '9'; q++)
		v = v > (INT64_C(1) << 40) ? v : v * 10 + (*q - '0');
	*out = neg ? -v : v;
	*s = q;
	return true;
}

/* "v", "v/vt", "v//vn" or "v/vt/vn"; only v is kept. */
static bool parse_corner(const char **s, const char *end, int64_t *v)
{
	const char *q = *s;
	int64_t unused;

	if (!parse_int(&q, end, v))
		return false;
	if (q < end && *q == '/') {
		q++;
		if (q < end && *q != '/')
			if (!parse_int(&q, end, &unused))
				return false;
		if (q < end && *q == '/') {
			q++;
			if (!parse_int(&q, end, &unused))
				return false;
		}
	}
	if (q < end && !is_space(*q) && *q != '#')
		return false;
	*s = q;
	return true;
}

/* Turns a 1-based or negative (relative) OBJ index into a 0-based one. */
static int resolve_index(struct obj_parser *p, int64_t v, const char *tok, const char *end,
                         uint32_t *out)
{
	int64_t count = (int64_t)p->mesh.vertex_count;

	if (v == 0)
		return parse_error(p, "vertex index 0 is invalid (OBJ counts from 1):", tok, end);
	if (v < 0 && count + v < 0)
		return parse_error(p, "vertex index out of range:", tok, end);
	if (v > UINT32_MAX)
		return parse_error(p, "vertex index out of range:", tok, end);
	*out = (uint32_t)(v < 0 ? count + v : v - 1);
	if (v > 0 && (uint64_t)v > p->max_index) {
		p->max_index = (uint64_t)v;
		p->max_index_line = p->line;
	}
	return 0;
}

static int add_corner(struct obj_parser *p, size_t n, uint32_t index)
{
	if (n == p->face_cap) {
		size_t cap = p->face_cap ? 2 * p->face_cap : 16;
		uint32_t *face = realloc(p->face, cap * sizeof(uint32_t));

		if (!face) {
			scene_error(p->err, "%s:%zu: out of memory", p->path, p->line);
			return -ENOMEM;
		}
		p->face = face;
		p->face_cap = cap;
	}
	p->face[n] = index;
	return 0;
}

/* A polygon, fan-triangulated around its first corner. */
static int parse_face(struct obj_parser *p, const char *s, const char *end)
{
	size_t n = 0;
	int64_t v;
	uint32_t index = 0;
	int ret;

	for (s = skip_space(s, end); s < end && *s != '#'; s = skip_space(s, end), n++) {
		const char *tok = s;

		if (!parse_corner(&s, end, &v))
			return parse_error(p, "malformed face vertex", tok, end);
		ret = resolve_index(p, v, tok, end, &index);
		if (!ret)
			ret = add_corner(p, n, index);
		if (ret)
			return ret;
	}
	if (n < 3) {
		scene_error(p->err, "%s:%zu: face with %zu vertices (needs at least 3)", p->path,
		            p->line, n);
		return -EINVAL;
	}
	if (scene_mesh_reserve(&p->mesh, 0, n - 2)) {
		scene_error(p->err, "%s:%zu: out of memory", p->path, p->line);
		return -ENOMEM;
	}
	for (size_t i = 1; i + 1 < n; i++)
		scene_mesh_put_triangle(&p->mesh, p->face[0], p->face[i], p->face[i + 1]);
	return 0;
}

/* Statements that carry nothing a BVH needs. */
static bool ignored_statement(const char *s, const char *e)
{
	static const char *const words[] = { "vt", "vn", "vp", "g", "o", "s", "usemtl", "mtllib" };

	for (size_t i = 0; i < sizeof(words) / sizeof(words[0]); i++)
		if (token_is(s, e, words[i]))
			return true;
	return false;
}

static int parse_line(struct obj_parser *p, const char *s, const char *end)
{
	const char *e;

	s = skip_space(s, end);
	if (s == end || *s == '#')
		return 0;
	e = token_end(s, end);
	if (token_is(s, e, "v"))
		return parse_vertex(p, e, end);
	if (token_is(s, e, "f"))
		return parse_face(p, e, end);
	if (!ignored_statement(s, e))
		p->stats.unknown_statements++;
	return 0;
}

static int parse_buffer(struct obj_parser *p, const char *data, size_t size)
{
	const char *s = data, *end = data + size;
	int ret;

	for (p->line = 1; s < end; p->line++) {
		const char *eol = memchr(s, '\n', (size_t)(end - s));

		if (!eol)
			eol = end;
		ret = parse_line(p, s, eol);
		if (ret)
			return ret;
		s = eol + 1;
	}
	return 0;
}

/* The checks that need the whole file. */
static int check_complete(struct obj_parser *p)
{
	if (p->max_index > p->mesh.vertex_count) {
		scene_error(p->err, "%s:%zu: vertex index %llu out of range (the file has %zu "
		            "vertices)", p->path, p->max_index_line,
		            (unsigned long long)p->max_index, p->mesh.vertex_count);
		return -EINVAL;
	}
	if (p->mesh.triangle_count == 0) {
		scene_error(p->err, "%s: no faces", p->path);
		return -EINVAL;
	}
	return 0;
}

int scene_load_obj_stats(const char *path, bvhlab_scene **out,
                         struct scene_load_stats *stats, bvhlab_error *err)
{
	struct obj_parser p = { .path = path, .err = err };
	char *data = NULL;
	size_t size;
	int ret;

	ret = scene_read_file(path, &data, &size, err);
	if (ret)
		return ret;
	ret = parse_buffer(&p, data, size);
	if (!ret)
		ret = check_complete(&p);
	if (!ret)
		ret = scene_mesh_finish(&p.mesh, path, out, err);
	if (stats)
		*stats = p.stats;
	scene_mesh_free(&p.mesh);
	free(p.face);
	free(data);
	return ret;
}

int bvhlab_scene_load_obj(const char *path, bvhlab_scene **out, bvhlab_error *err)
{
	return scene_load_obj_stats(path, out, NULL, err);
}
