/* Text for a JSON document (json_text.h). */
#include "core/json_text.h"

#include <stdio.h>
#include <stdlib.h>

#include "core/error.h"

json_t *thz_json_text(const char *s)
{
    if (!s)
        return json_null();
    json_t *j = json_string(s);
    if (j)
        return j;
    char *clean = thz_text_clean(s);
    j = clean ? json_string(clean) : NULL;
    free(clean);
    return j;
}

void thz_number_text(double x, char *buf, size_t size)
{
    if (!size)
        return;
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(buf, size, "%.*g", digits, x);
        if (strtod(buf, NULL) == x || x != x)
            return;
    }
}
