/* Text for a JSON document (json_text.h). */
#include "core/json_text.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/c_locale.h"
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
    locale_t previous = thz_locale_enter(); /* "0.1" in any host's locale */
    for (int digits = 1; digits <= 17; digits++) {
        snprintf(buf, size, "%.*g", digits, x);
        if (strtod(buf, NULL) == x || x != x)
            break;
    }
    thz_locale_leave(previous);
}

/* A growing text. */
typedef struct text_buf {
    char *s;
    size_t len, cap;
    int failed;
} text_buf;

static void text_add(text_buf *t, const char *s, size_t n)
{
    if (t->failed)
        return;
    if (t->len + n + 1 > t->cap) {
        size_t cap = t->cap ? t->cap : 64;
        while (cap < t->len + n + 1)
            cap *= 2;
        char *grown = realloc(t->s, cap);
        if (!grown) {
            t->failed = 1;
            return;
        }
        t->s = grown;
        t->cap = cap;
    }
    memcpy(t->s + t->len, s, n);
    t->len += n;
    t->s[t->len] = '\0';
}

static void text_add_json(text_buf *t, const json_t *v)
{
    char num[64];
    switch (json_typeof(v)) {
    case JSON_OBJECT: {
        const char *key;
        json_t *child;
        int first = 1;
        text_add(t, "{", 1);
        json_object_foreach((json_t *)v, key, child)
        {
            json_t *k = json_string(key);
            char *kt = k ? json_dumps(k, JSON_ENCODE_ANY) : NULL;
            if (!kt)
                t->failed = 1;
            else {
                if (!first)
                    text_add(t, ", ", 2);
                text_add(t, kt, strlen(kt));
                text_add(t, ": ", 2);
                text_add_json(t, child);
            }
            free(kt);
            json_decref(k);
            first = 0;
        }
        text_add(t, "}", 1);
        return;
    }
    case JSON_ARRAY:
        text_add(t, "[", 1);
        for (size_t i = 0; i < json_array_size(v); i++) {
            if (i)
                text_add(t, ", ", 2);
            text_add_json(t, json_array_get(v, i));
        }
        text_add(t, "]", 1);
        return;
    case JSON_REAL:
        thz_number_text(json_real_value(v), num, sizeof num - 2);
        if (!strpbrk(num, ".eEni")) /* a real stays one: 310.0, not 310 */
            strcat(num, ".0");
        text_add(t, num, strlen(num));
        return;
    default: {
        char *s = json_dumps(v, JSON_ENCODE_ANY);
        if (!s)
            t->failed = 1;
        else
            text_add(t, s, strlen(s));
        free(s);
        return;
    }
    }
}

char *thz_json_shortest(const json_t *v)
{
    text_buf t = {0};
    text_add_json(&t, v);
    text_add(&t, "", 0);
    if (t.failed) {
        free(t.s);
        return NULL;
    }
    return t.s;
}

json_t *thz_json_raw(const char *raw)
{
    size_t n = strlen(raw);
    char *s = malloc(n + 1);
    if (!s)
        return NULL;
    s[0] = '\0';
    memcpy(s + 1, raw, n);
    json_t *j = json_stringn(s, n + 1);
    free(s);
    return j;
}

char *thz_json_dumps_raw(const json_t *root, size_t flags)
{
    char *text = json_dumps(root, flags);
    if (!text || !strstr(text, "\"\\u0000"))
        return text;
    text_buf out = {0};
    const char *p = text, *hit;
    while ((hit = strstr(p, "\"\\u0000")) != NULL) {
        /* the placeholder's string: to its closing quote, past escapes */
        const char *end = hit + 1;
        while (*end && *end != '"')
            end += end[0] == '\\' && end[1] ? 2 : 1;
        json_t *s =
            json_loadb(hit, (size_t)(end - hit) + 1, JSON_DECODE_ANY | JSON_ALLOW_NUL, NULL);
        text_add(&out, p, (size_t)(hit - p));
        if (!s || json_string_length(s) < 1)
            out.failed = 1;
        else
            text_add(&out, json_string_value(s) + 1, json_string_length(s) - 1);
        json_decref(s);
        p = *end ? end + 1 : end;
    }
    text_add(&out, p, strlen(p));
    free(text);
    if (out.failed) {
        free(out.s);
        return NULL;
    }
    return out.s;
}
