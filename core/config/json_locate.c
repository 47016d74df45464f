/*
 * Source positions for cJSON trees: a minimal scanner over text cJSON has
 * already accepted, paired with the tree in document (pre-)order.
 */
#include <errno.h>
#include <stdlib.h>
#include <string.h>

#include <cJSON.h>

#include "config/json_locate.h"
#include "util/util.h"

#define NO_OFFSET SIZE_MAX
/* Above cJSON's own nesting limit (1000): any tree it returns fits. */
#define MAX_DEPTH 4096
#define EXCERPT_BYTES 24

struct entry {
	const cJSON *item;
	size_t key, value; /* byte offsets; key is NO_OFFSET outside objects */
	int key_line, key_col, value_line, value_col;
};

struct json_locations {
	const char *text;
	struct entry *entries; /* document order while building, then by item address */
	size_t count, capacity;
};

struct scanner {
	const char *text;
	size_t pos;
	struct json_locations *loc;
	size_t nul_escape; /* first "\u0000" in a string, or NO_OFFSET */
};

static size_t bom_length(const char *text)
{
	/* cJSON skips a UTF-8 byte order mark; so must the scan and the columns. */
	return strncmp(text, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
}

static void skip_space(struct scanner *s)
{
	/* cJSON treats every byte up to ' ' as whitespace; match it exactly. */
	while (s->text[s->pos] != '\0' && (unsigned char)s->text[s->pos] <= ' ')
		s->pos++;
}

static int record(struct scanner *s, size_t key, size_t value)
{
	struct json_locations *loc = s->loc;
	if (loc->count == loc->capacity) {
		size_t capacity = loc->capacity ? 2 * loc->capacity : 64;
		struct entry *grown = realloc(loc->entries, capacity * sizeof(*grown));
		if (!grown)
			return -ENOMEM;
		loc->entries = grown;
		loc->capacity = capacity;
	}
	loc->entries[loc->count++] = (struct entry){ .key = key, .value = value };
	return 0;
}

static int skip_string(struct scanner *s)
{
	size_t p = s->pos + 1;
	while (s->text[p] != '"') {
		if (s->text[p] == '\0')
			return -EINVAL;
		if (s->text[p] == '\\') {
			if (s->text[p + 1] == '\0')
				return -EINVAL;
			if (strncmp(s->text + p + 1, "u0000", 5) == 0 && s->nul_escape == NO_OFFSET)
				s->nul_escape = p;
			p++;
		}
		p++;
	}
	s->pos = p + 1;
	return 0;
}

static int scan_value(struct scanner *s, size_t key, int depth);

static int scan_member(struct scanner *s, bool object, int depth)
{
	size_t key = NO_OFFSET;
	if (object) {
		if (s->text[s->pos] != '"')
			return -EINVAL;
		key = s->pos;
		int rc = skip_string(s);
		if (rc)
			return rc;
		skip_space(s);
		if (s->text[s->pos] != ':')
			return -EINVAL;
		s->pos++;
		skip_space(s);
	}
	return scan_value(s, key, depth + 1);
}

static int scan_container(struct scanner *s, char close, int depth)
{
	s->pos++;
	skip_space(s);
	if (s->text[s->pos] == close) {
		s->pos++;
		return 0;
	}
	for (;;) {
		int rc = scan_member(s, close == '}', depth);
		if (rc)
			return rc;
		skip_space(s);
		char c = s->text[s->pos++];
		if (c == close)
			return 0;
		if (c != ',')
			return -EINVAL;
		skip_space(s);
	}
}

static int scan_value(struct scanner *s, size_t key, int depth)
{
	if (depth > MAX_DEPTH)
		return -EINVAL;
	int rc = record(s, key, s->pos);
	if (rc)
		return rc;
	switch (s->text[s->pos]) {
	case '{':
		return scan_container(s, '}', depth);
	case '[':
		return scan_container(s, ']', depth);
	case '"':
		return skip_string(s);
	case '\0':
		return -EINVAL;
	default: /* number or literal: cJSON has checked it */
		while ((unsigned char)s->text[s->pos] > ' ' && !strchr(",]}", s->text[s->pos]))
			s->pos++;
		return 0;
	}
}

static bool kind_matches(const cJSON *item, char first)
{
	if (cJSON_IsObject(item))
		return first == '{';
	if (cJSON_IsArray(item))
		return first == '[';
	if (cJSON_IsString(item))
		return first == '"';
	return first != '{' && first != '[' && first != '"';
}

static int pair_items(struct json_locations *loc, const cJSON *item, size_t *next, int depth)
{
	for (; item; item = item->next) {
		if (*next >= loc->count || depth > MAX_DEPTH)
			return -EINVAL;
		struct entry *e = &loc->entries[(*next)++];
		if (!kind_matches(item, loc->text[e->value]))
			return -EINVAL;
		e->item = item;
		if (cJSON_IsObject(item) || cJSON_IsArray(item)) {
			int rc = pair_items(loc, item->child, next, depth + 1);
			if (rc)
				return rc;
		}
	}
	return 0;
}

struct cursor {
	size_t pos;
	int line, col;
};

static void advance(const char *text, struct cursor *c, size_t to)
{
	while (c->pos < to && text[c->pos] != '\0') {
		unsigned char ch = (unsigned char)text[c->pos++];
		if (ch == '\n') {
			c->line++;
			c->col = 1;
		} else if ((ch & 0xC0) != 0x80) { /* continuation bytes share a column */
			c->col++;
		}
	}
}

static void compute_positions(struct json_locations *loc)
{
	/* Entries are in document order, so one forward pass serves them all. */
	struct cursor c = { bom_length(loc->text), 1, 1 };
	for (size_t i = 0; i < loc->count; i++) {
		struct entry *e = &loc->entries[i];
		if (e->key != NO_OFFSET) {
			advance(loc->text, &c, e->key);
			e->key_line = c.line;
			e->key_col = c.col;
		}
		advance(loc->text, &c, e->value);
		e->value_line = c.line;
		e->value_col = c.col;
	}
}

static int by_item(const void *a, const void *b)
{
	uintptr_t x = (uintptr_t)((const struct entry *)a)->item;
	uintptr_t y = (uintptr_t)((const struct entry *)b)->item;
	return (x > y) - (x < y);
}

static int index_text(struct json_locations **out, const char *text, const cJSON *root,
                      size_t *nul_escape)
{
	struct json_locations *loc = calloc(1, sizeof(*loc));
	if (!loc)
		return -ENOMEM;
	loc->text = text;
	struct scanner s = { text, bom_length(text), loc, NO_OFFSET };
	skip_space(&s);
	size_t paired = 0;
	int rc = scan_value(&s, NO_OFFSET, 0);
	if (!rc)
		rc = pair_items(loc, root, &paired, 0);
	if (!rc && paired != loc->count)
		rc = -EINVAL;
	if (rc) {
		json_locations_destroy(loc);
		return rc;
	}
	compute_positions(loc);
	qsort(loc->entries, loc->count, sizeof(*loc->entries), by_item);
	*nul_escape = s.nul_escape;
	*out = loc;
	return 0;
}

int json_locations_build(struct json_locations **out, const char *text, const cJSON *root)
{
	size_t nul_escape;
	*out = NULL;
	return index_text(out, text, root, &nul_escape);
}

void json_locations_destroy(struct json_locations *locations)
{
	if (!locations)
		return;
	free(locations->entries);
	free(locations);
}

static const struct entry *find(const struct json_locations *loc, const cJSON *item)
{
	if (!loc || !item)
		return NULL;
	struct entry key = { .item = item };
	return bsearch(&key, loc->entries, loc->count, sizeof(key), by_item);
}

bool json_locate_key(const struct json_locations *locations, const cJSON *item, int *line,
                     int *col)
{
	const struct entry *e = find(locations, item);
	if (!e || e->key == NO_OFFSET)
		return false;
	*line = e->key_line;
	*col = e->key_col;
	return true;
}

bool json_locate_value(const struct json_locations *locations, const cJSON *item, int *line,
                       int *col)
{
	const struct entry *e = find(locations, item);
	if (!e)
		return false;
	*line = e->value_line;
	*col = e->value_col;
	return true;
}

const char *json_value_text(const struct json_locations *locations, const cJSON *item)
{
	const struct entry *e = find(locations, item);
	return e ? locations->text + e->value : NULL;
}

void json_offset_position(const char *text, size_t offset, int *line, int *col)
{
	size_t bom = bom_length(text);
	struct cursor c = { bom, 1, 1 };
	advance(text, &c, offset < bom ? bom : offset);
	*line = c.line;
	*col = c.col;
}

/* ---- syntax errors and parsing -------------------------------------------- */

static void excerpt(const char *at, char *buf, size_t size)
{
	size_t n = 0;
	while (n + 1 < size && n < EXCERPT_BYTES && at[n] != '\0' && at[n] != '\n' &&
	       at[n] != '\r')
		n++;
	/* Never end inside a UTF-8 sequence. */
	while (n > 0 && at[n] != '\0' && ((unsigned char)at[n] & 0xC0) == 0x80)
		n--;
	for (size_t i = 0; i < n; i++)
		buf[i] = (unsigned char)at[i] < ' ' ? ' ' : at[i];
	buf[n] = '\0';
}

/* Open arrays and objects before text[offset], strings skipped: cJSON
 * stops at CJSON_NESTING_LIMIT levels, which is not a syntax error. */
static size_t depth_at(const char *text, size_t offset)
{
	size_t depth = 0;
	bool in_string = false;
	for (size_t i = 0; i < offset; i++) {
		char c = text[i];
		if (in_string && c == '\\' && i + 1 < offset)
			i++;
		else if (c == '"')
			in_string = !in_string;
		else if (!in_string && (c == '[' || c == '{'))
			depth++;
		else if (!in_string && (c == ']' || c == '}') && depth)
			depth--;
	}
	return depth;
}

static int syntax_error(const char *path, const char *text, const char *at, bvhlab_error *err)
{
	if (!at)
		at = cJSON_GetErrorPtr();
	size_t len = strlen(text);
	size_t offset = at && at >= text && at <= text + len ? (size_t)(at - text) : len;
	int line, col;
	json_offset_position(text, offset, &line, &col);
	if (depth_at(text, offset) >= CJSON_NESTING_LIMIT) {
		error_set(err, "%s:%d:%d: JSON nested deeper than %d levels (arrays and objects "
		          "within each other), more than bvhlab reads", path, line, col,
		          CJSON_NESTING_LIMIT);
		return -EINVAL;
	}
	char near[EXCERPT_BYTES + 1];
	excerpt(text + offset, near, sizeof(near));
	if (near[0] == '\0') {
		error_set(err, "%s:%d:%d: JSON syntax error: unexpected end of text", path, line, col);
		return -EINVAL;
	}
	bool cut = strlen(near) < strcspn(text + offset, "\r\n");
	error_set(err, "%s:%d:%d: JSON syntax error near '%s%s'", path, line, col, near,
	          cut ? "..." : "");
	return -EINVAL;
}

int json_parse_located(const char *path, const char *text, cJSON **root,
                       struct json_locations **locations, bvhlab_error *err)
{
	const char *end = NULL;
	*root = NULL;
	*locations = NULL;
	cJSON *tree = cJSON_ParseWithOpts(text, &end, 1);
	if (!tree)
		return syntax_error(path, text, end, err);
	size_t nul_escape;
	int rc = index_text(locations, text, tree, &nul_escape);
	if (rc) {
		error_set(err, "%s: cannot index the JSON text: %s", path, strerror(-rc));
		goto fail;
	}
	if (nul_escape != NO_OFFSET) {
		int line, col;
		json_offset_position(text, nul_escape, &line, &col);
		error_set(err, "%s:%d:%d: strings must not contain \\u0000", path, line, col);
		rc = -EINVAL;
		goto fail;
	}
	*root = tree;
	return 0;
fail:
	json_locations_destroy(*locations);
	*locations = NULL;
	cJSON_Delete(tree);
	return rc;
}

/* ---- exact integers --------------------------------------------------------- */

struct number_text {
	const char *digits[2]; /* integer part, fraction part */
	size_t length[2];
	long exponent;         /* saturated: the value is absurd long before */
};

static void split_number(const char *p, struct number_text *n)
{
	n->digits[0] = p;
	n->length[0] = strspn(p, "0123456789");
	p += n->length[0];
	n->digits[1] = p;
	n->length[1] = 0;
	if (*p == '.') {
		n->digits[1] = ++p;
		n->length[1] = strspn(p, "0123456789");
		p += n->length[1];
	}
	n->exponent = 0;
	if (*p != 'e' && *p != 'E')
		return;
	p++;
	long sign = *p == '-' ? -1 : 1;
	if (*p == '-' || *p == '+')
		p++;
	for (; *p >= '0' && *p <= '9'; p++)
		if (n->exponent < 1000000)
			n->exponent = n->exponent * 10 + (*p - '0');
	n->exponent *= sign;
}

static int digit_at(const struct number_text *n, size_t i)
{
	return i < n->length[0] ? n->digits[0][i] - '0' : n->digits[1][i - n->length[0]] - '0';
}

/* Magnitude of the number spelt at p (after any '-'). */
static int exact_magnitude(const char *p, uint64_t *out)
{
	struct number_text n;
	split_number(p, &n);
	size_t total = n.length[0] + n.length[1], first = 0, last = total;
	while (first < total && digit_at(&n, first) == 0)
		first++;
	*out = 0;
	if (first == total)
		return 0;
	while (digit_at(&n, last - 1) == 0)
		last--;
	/* Decimal exponent of the last significant digit. */
	long scale = n.exponent - (long)n.length[1] + (long)(total - last);
	if (scale < 0)
		return -EINVAL;
	if ((long)(last - first) + scale > 20)
		return -ERANGE;
	uint64_t m = 0;
	for (size_t i = first; i < last + (size_t)scale; i++) {
		unsigned d = i < last ? (unsigned)digit_at(&n, i) : 0;
		if (m > (UINT64_MAX - d) / 10)
			return -ERANGE;
		m = m * 10 + d;
	}
	*out = m;
	return 0;
}

static int number_text(const struct json_locations *loc, const cJSON *item, const char **p)
{
	*p = cJSON_IsNumber(item) ? json_value_text(loc, item) : NULL;
	return *p ? 0 : -EINVAL;
}

/* A JSON integer as its sign and exact magnitude. */
static int signed_magnitude(const struct json_locations *loc, const cJSON *item, bool *negative,
                            uint64_t *m)
{
	const char *p;
	int rc = number_text(loc, item, &p);
	if (rc)
		return rc;
	*negative = *p == '-';
	return exact_magnitude(p + *negative, m);
}

int json_get_int64(const struct json_locations *locations, const cJSON *item, int64_t *out)
{
	bool negative;
	uint64_t m;
	int rc = signed_magnitude(locations, item, &negative, &m);
	if (rc)
		return rc;
	if (m > (uint64_t)INT64_MAX + negative)
		return -ERANGE;
	if (!negative)
		*out = (int64_t)m;
	else /* reaches INT64_MIN without overflowing on the way */
		*out = m == 0 ? 0 : -(int64_t)(m - 1) - 1;
	return 0;
}

int json_get_uint64(const struct json_locations *locations, const cJSON *item, uint64_t *out)
{
	bool negative;
	uint64_t m;
	int rc = signed_magnitude(locations, item, &negative, &m);
	if (rc)
		return rc;
	if (negative && m != 0)
		return -ERANGE;
	*out = m;
	return 0;
}
