/*
 * Source positions for cJSON trees (private to the core).
 *
 * cJSON keeps no positions, yet every config error must say
 * FILE:LINE:COLUMN. A second, minimal scan over the same text records where
 * each value and each object key starts, in document order; walking the
 * cJSON tree in the same order pairs every item with its positions.
 *
 * Lines and columns are 1-based; a column counts characters (UTF-8 code
 * points, a tab is one), not bytes.
 */
#ifndef BVHLAB_CORE_JSON_LOCATE_H
#define BVHLAB_CORE_JSON_LOCATE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include <bvhlab/types.h>

struct cJSON;
struct json_locations;

/*
 * Parses `text` (NUL-terminated; nothing but whitespace may follow the
 * value) and indexes it. On a syntax error err reads
 *   PATH:LINE:COL: JSON syntax error near '...'
 * Strings holding "\u0000" are refused too, since cJSON would cut them
 * short. `text` must outlive *locations. Returns 0, -EINVAL or -ENOMEM.
 */
int json_parse_located(const char *path, const char *text, struct cJSON **root,
                       struct json_locations **locations, bvhlab_error *err);

/*
 * Indexes a tree cJSON parsed from `text` (which must outlive *out).
 * -EINVAL if the text and the tree disagree, -ENOMEM.
 */
int json_locations_build(struct json_locations **out, const char *text,
                         const struct cJSON *root);
void json_locations_destroy(struct json_locations *locations); /* NULL is fine */

/* Where the item's key starts (object members only) / where its value starts. */
bool json_locate_key(const struct json_locations *locations, const struct cJSON *item,
                     int *line, int *col);
bool json_locate_value(const struct json_locations *locations, const struct cJSON *item,
                       int *line, int *col);

/* The source text from where the item's value starts, or NULL. */
const char *json_value_text(const struct json_locations *locations, const struct cJSON *item);

/* Line and column of byte `offset` in `text` (clamped to its end). */
void json_offset_position(const char *text, size_t offset, int *line, int *col);

/*
 * The exact integer a number item spells, read from the source text, so
 * that 2.5 is refused and 12345678901234567891 is not rounded through a
 * double. Exponents are fine when the result is whole (1e3, 2.50e1).
 * Returns 0, -EINVAL (not a number, or not whole) or -ERANGE.
 */
int json_get_int64(const struct json_locations *locations, const struct cJSON *item,
                   int64_t *out);
int json_get_uint64(const struct json_locations *locations, const struct cJSON *item,
                    uint64_t *out);

#endif /* BVHLAB_CORE_JSON_LOCATE_H */
