/* Text for a JSON document. jansson takes only valid UTF-8: json_string returned NULL for
 * a file path with other bytes, which the writers took for out of memory after the whole
 * run ("summary.json: out of memory" for a scene in a directory named in Latin-1).
 */
#ifndef THZ_CORE_JSON_TEXT_H
#define THZ_CORE_JSON_TEXT_H

#include <jansson.h>

/* s as a JSON string: itself when it is valid UTF-8, else with each byte that starts no
 * valid character (and each control byte) written as the text \xNN, as error messages
 * show them (thz_text_clean). JSON null for NULL; NULL only when out of memory. */
json_t *thz_json_text(const char *s);

/* x in the fewest significant digits (at most 17) that read back as the same double,
 * for messages: 0.1, not 0.10000000000000001 ("%.17g"); nan and inf as "nan", "inf". */
void thz_number_text(double x, char *buf, size_t size);

/* v as compact JSON text ({"a": 0.3, "b": [1, 2]}) whose reals are written in the fewest
 * digits that read back as the same double (thz_number_text, with ".0" when they look
 * whole): a value as its file wrote it, where json_dumps writes 0.3 as
 * 0.29999999999999999 (17 digits) or rounds to JSON_REAL_PRECISION. malloc'd; NULL
 * when out of memory. */
char *thz_json_shortest(const json_t *v);

/* A placeholder for the JSON text `raw` (e.g. thz_json_shortest's) in a document that
 * thz_json_dumps_raw writes: a string jansson escapes, which no other string can equal
 * (it starts with a NUL character, which C strings and jansson's default decoding never
 * hold). NULL when out of memory. */
json_t *thz_json_raw(const char *raw);

/* json_dumps(root, flags), with each thz_json_raw placeholder replaced by its text as
 * it is. malloc'd; NULL when out of memory. */
char *thz_json_dumps_raw(const json_t *root, size_t flags);

#endif
