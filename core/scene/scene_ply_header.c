/*
 * PLY header parser: format, elements and their properties, in file order.
 * Errors read "PATH:LINE: message".
 */
#include <errno.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_ply.h"
#include "scene/scene_private.h"

#define MAX_TOKENS 8

/* One header line split into blank-separated tokens (not NUL-terminated). */
struct line_tokens {
	const char *start[MAX_TOKENS];
	size_t len[MAX_TOKENS];
	size_t count; /* may exceed MAX_TOKENS: only the first ones are kept */
};

struct header_parser {
	const char *path;
	size_t line;
	struct ply_header *header;
	bvhlab_error *err;
};

static const struct {
	const char *name;
	enum ply_type type;
} type_names[] = {
	{ "char", PLY_INT8 },     { "int8", PLY_INT8 },       { "uchar", PLY_UINT8 },
	{ "uint8", PLY_UINT8 },   { "short", PLY_INT16 },     { "int16", PLY_INT16 },
	{ "ushort", PLY_UINT16 }, { "uint16", PLY_UINT16 },   { "int", PLY_INT32 },
	{ "int32", PLY_INT32 },   { "uint", PLY_UINT32 },     { "uint32", PLY_UINT32 },
	{ "float", PLY_FLOAT32 }, { "float32", PLY_FLOAT32 }, { "double", PLY_FLOAT64 },
	{ "float64", PLY_FLOAT64 },
};

size_t ply_type_size(enum ply_type type)
{
	static const size_t sizes[] = { 0, 1, 1, 2, 2, 4, 4, 4, 8 };

	return sizes[type];
}

long ply_find_property(const struct ply_element *element, const char *name)
{
	for (size_t i = 0; i < element->prop_count; i++)
		if (strcmp(element->props[i].name, name) == 0)
			return (long)i;
	return -1;
}

static bool tok_is(const struct line_tokens *t, size_t i, const char *word)
{
	return i < t->count && i < MAX_TOKENS && t->len[i] == strlen(word) &&
	       memcmp(t->start[i], word, t->len[i]) == 0;
}

static void split_line(const char *s, const char *end, struct line_tokens *t)
{
	t->count = 0;
	for (;;) {
		while (s < end && (*s == ' ' || *s == '\t' || *s == '\r'))
			s++;
		if (s == end)
			return;
		if (t->count < MAX_TOKENS)
			t->start[t->count] = s;
		while (s < end && *s != ' ' && *s != '\t' && *s != '\r')
			s++;
		if (t->count < MAX_TOKENS)
			t->len[t->count] = (size_t)(s - t->start[t->count]);
		t->count++;
	}
}

static int header_error(struct header_parser *p, const char *msg)
{
	scene_error(p->err, "%s:%zu: bad PLY header: %s", p->path, p->line, msg);
	return -EINVAL;
}

static int parse_type(struct header_parser *p, const struct line_tokens *t, size_t i,
                      enum ply_type *out)
{
	for (size_t k = 0; k < sizeof(type_names) / sizeof(type_names[0]); k++) {
		if (tok_is(t, i, type_names[k].name)) {
			*out = type_names[k].type;
			return 0;
		}
	}
	scene_error(p->err, "%s:%zu: bad PLY header: unknown property type '%.*s'", p->path,
	            p->line, (int)(t->len[i] > 40 ? 40 : t->len[i]), t->start[i]);
	return -EINVAL;
}

static int parse_format(struct header_parser *p, const struct line_tokens *t)
{
	if (t->count != 3)
		return header_error(p, "expected 'format TYPE 1.0'");
	if (tok_is(t, 1, "ascii"))
		p->header->format = PLY_ASCII;
	else if (tok_is(t, 1, "binary_little_endian"))
		p->header->format = PLY_BINARY_LE;
	else if (tok_is(t, 1, "binary_big_endian"))
		p->header->format = PLY_BINARY_BE;
	else
		return header_error(p, "unknown format (ascii, binary_little_endian or "
		                       "binary_big_endian)");
	if (!tok_is(t, 2, "1.0"))
		return header_error(p, "unsupported version (only 1.0)");
	return 0;
}

static int parse_element(struct header_parser *p, const struct line_tokens *t)
{
	struct ply_header *h = p->header;
	struct ply_element *e;
	char *stop;
	unsigned long long count;

	if (t->count != 3)
		return header_error(p, "expected 'element NAME COUNT'");
	count = strtoull(t->start[2], &stop, 10);
	if (t->start[2][0] < '0' || t->start[2][0] > '9' || stop != t->start[2] + t->len[2])
		return header_error(p, "element count is not a number");
	if (h->element_count == h->element_cap) {
		size_t cap = h->element_cap ? 2 * h->element_cap : 4;
		void *q = realloc(h->elements, cap * sizeof(*h->elements));
		if (!q)
			return -ENOMEM;
		h->elements = q;
		h->element_cap = cap;
	}
	e = &h->elements[h->element_count];
	memset(e, 0, sizeof(*e));
	e->name = strndup(t->start[1], t->len[1]);
	if (!e->name)
		return -ENOMEM;
	h->element_count++;
	e->count = count;
	e->line = p->line;
	return 0;
}

static int add_property(struct ply_element *e, const char *name, size_t len,
                        enum ply_type type, enum ply_type count_type)
{
	struct ply_property *prop;

	if (e->prop_count == e->prop_cap) {
		size_t cap = e->prop_cap ? 2 * e->prop_cap : 8;
		void *q = realloc(e->props, cap * sizeof(*e->props));
		if (!q)
			return -ENOMEM;
		e->props = q;
		e->prop_cap = cap;
	}
	prop = &e->props[e->prop_count];
	prop->name = strndup(name, len);
	if (!prop->name)
		return -ENOMEM;
	prop->type = type;
	prop->count_type = count_type;
	e->prop_count++;
	return 0;
}

static int parse_property(struct header_parser *p, const struct line_tokens *t)
{
	enum ply_type type, count_type = PLY_NONE;
	bool list = tok_is(t, 1, "list");
	size_t name = list ? 4 : 2;
	int ret;

	if (p->header->element_count == 0)
		return header_error(p, "property before any element");
	if (t->count != name + 1)
		return header_error(p, list ? "expected 'property list COUNT_TYPE TYPE NAME'"
		                            : "expected 'property TYPE NAME'");
	if (list) {
		ret = parse_type(p, t, 2, &count_type);
		if (ret)
			return ret;
		if (!ply_type_is_integer(count_type))
			return header_error(p, "list count type must be an integer type");
	}
	ret = parse_type(p, t, name - 1, &type);
	if (ret)
		return ret;
	return add_property(&p->header->elements[p->header->element_count - 1], t->start[name],
	                    t->len[name], type, count_type);
}

/* One header line; *done set at end_header. */
static int parse_header_line(struct header_parser *p, const struct line_tokens *t, bool *done)
{
	if (p->line == 1 && !(tok_is(t, 0, "ply") && t->count == 1))
		return header_error(p, "not a PLY file (no 'ply' line)");
	if (p->line == 1)
		return 0;
	if (p->line == 2 && !tok_is(t, 0, "format"))
		return header_error(p, "the second line must be 'format ...'");
	if (t->count == 0 || tok_is(t, 0, "comment") || tok_is(t, 0, "obj_info"))
		return 0;
	if (tok_is(t, 0, "format"))
		return p->line == 2 ? parse_format(p, t) : header_error(p, "repeated 'format'");
	if (tok_is(t, 0, "element"))
		return parse_element(p, t);
	if (tok_is(t, 0, "property"))
		return parse_property(p, t);
	if (tok_is(t, 0, "end_header")) {
		*done = true;
		return 0;
	}
	return header_error(p, "unknown keyword");
}

int ply_header_parse(const char *path, const char *data, size_t size, struct ply_header *header,
                     bvhlab_error *err)
{
	struct header_parser p = { .path = path, .header = header, .err = err };
	const char *s = data, *end = data + size;
	struct line_tokens t;
	bool done = false;
	int ret;

	memset(header, 0, sizeof(*header));
	for (p.line = 1; !done; p.line++, s++) {
		const char *eol = memchr(s, '\n', (size_t)(end - s));

		if (!eol)
			return header_error(&p, "missing 'end_header' (truncated header?)");
		split_line(s, eol, &t);
		ret = parse_header_line(&p, &t, &done);
		if (ret == -ENOMEM)
			scene_error(err, "%s: out of memory reading the PLY header", path);
		if (ret)
			return ret;
		s = eol;
	}
	header->end_line = p.line - 1;
	header->body_line = p.line;
	header->body_offset = (size_t)(s - data);
	return 0;
}

void ply_header_free(struct ply_header *header)
{
	for (size_t i = 0; i < header->element_count; i++) {
		struct ply_element *e = &header->elements[i];

		for (size_t k = 0; k < e->prop_count; k++)
			free(e->props[k].name);
		free(e->props);
		free(e->name);
	}
	free(header->elements);
	memset(header, 0, sizeof(*header));
}
