/*
 * The position index under config errors (json_locate): the line and
 * column of every key and value, duplicates kept in order, columns counted
 * in characters; and integers read exactly from their JSON text.
 */
#include <errno.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include <cJSON.h>

#include "config/json_locate.h"
#include "testutil.h"

static void check_pos(const struct json_locations *loc, const cJSON *item, bool key,
                      int line, int col)
{
	int l = 0, c = 0;
	bool found = key ? json_locate_key(loc, item, &l, &c)
	                 : json_locate_value(loc, item, &l, &c);
	if (!found || l != line || c != col) {
		fprintf(stderr, "%s: %s of '%s' at %d:%d, expected %d:%d\n", __FILE__,
		        key ? "key" : "value", item->string ? item->string : "", l, c, line, col);
		test_failures++;
	}
}

static void test_locate(void)
{
	const char *text = "{\"a\": [1, {\"b\": true, \"b\": null}],\n"
	                   " \"c\": \"x\", \"\xC3\xA9\": 1, \"k\": 2}";
	cJSON *root = cJSON_Parse(text);
	struct json_locations *loc = NULL;
	CHECK_INT(json_locations_build(&loc, text, root), 0);
	const cJSON *a = root->child, *arr0 = a->child, *obj = arr0->next;
	int l, c;
	check_pos(loc, root, false, 1, 1);
	CHECK(!json_locate_key(loc, root, &l, &c) && !json_locate_key(loc, arr0, &l, &c));
	check_pos(loc, a, true, 1, 2);
	check_pos(loc, a, false, 1, 7);
	check_pos(loc, arr0, false, 1, 8);
	check_pos(loc, obj, false, 1, 11);
	check_pos(loc, obj->child, true, 1, 12);
	check_pos(loc, obj->child, false, 1, 17);
	check_pos(loc, obj->child->next, true, 1, 23); /* the duplicate, kept in order */
	check_pos(loc, obj->child->next, false, 1, 28);
	check_pos(loc, a->next, true, 2, 2);
	check_pos(loc, a->next->next->next, true, 2, 20); /* "é" is one column */
	json_locations_destroy(loc);
	json_locations_destroy(NULL);
	cJSON_Delete(root);
	json_offset_position("ab\ncd", 4, &l, &c);
	CHECK(l == 2 && c == 2);

	const char *numbers = "[0, -0, 9223372036854775807, -9223372036854775808, "
	                      "9223372036854775808, 1e3, 2.50e1, 1.5, 1e-1, 0e999999, 10e-1, "
	                      "123456789012345678901234, 0.000, 18446744073709551615, "
	                      "18446744073709551616, -1, \"7\"]";
	static const struct { int rc; int64_t v; } want[] = {
		{ 0, 0 }, { 0, 0 }, { 0, INT64_MAX }, { 0, INT64_MIN }, { -ERANGE, 0 },
		{ 0, 1000 }, { 0, 25 }, { -EINVAL, 0 }, { -EINVAL, 0 }, { 0, 0 }, { 0, 1 },
		{ -ERANGE, 0 }, { 0, 0 }, { -ERANGE, 0 }, { -ERANGE, 0 }, { 0, -1 }, { -EINVAL, 0 },
	};
	root = cJSON_Parse(numbers);
	CHECK_INT(json_locations_build(&loc, numbers, root), 0);
	size_t i = 0;
	for (const cJSON *e = root->child; e; e = e->next, i++) {
		int64_t v = 0;
		int rc = json_get_int64(loc, e, &v);
		if (rc != want[i].rc || (rc == 0 && v != want[i].v)) {
			fprintf(stderr, "%s: number %zu: rc %d, %lld\n", __FILE__, i, rc, (long long)v);
			test_failures++;
		}
	}
	uint64_t u = 0;
	CHECK(json_get_uint64(loc, cJSON_GetArrayItem(root, 13), &u) == 0 && u == UINT64_MAX);
	CHECK_INT(json_get_uint64(loc, cJSON_GetArrayItem(root, 14), &u), -ERANGE);
	CHECK_INT(json_get_uint64(loc, cJSON_GetArrayItem(root, 15), &u), -ERANGE);
	CHECK(json_get_uint64(loc, cJSON_GetArrayItem(root, 1), &u) == 0 && u == 0);
	json_locations_destroy(loc);
	cJSON_Delete(root);
}

int main(void)
{
	test_locate();
	return test_finish();
}
