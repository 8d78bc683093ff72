/* Text for a JSON document (json_text.h). */
#include "core/json_text.h"

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
