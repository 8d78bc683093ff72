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

#endif
