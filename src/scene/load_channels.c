/* The scene's `channels` block: a list of channels or an evenly spaced range, and the
 * default names of unnamed channels (unique, so that ENVI band names are). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "scene/load.h"

#define LOAD_MAX_CHANNELS 4096u

/* Default names show the frequency with 3 decimals, more where that is what tells two
 * channels apart (0.350 and 0.3501 THz become "0.3500 THz" and "0.3501 THz"), up to
 * 1 Hz; channels at the same frequency get their index too. */
#define LOAD_NAME_MIN_DECIMALS 3
#define LOAD_NAME_MAX_DECIMALS 12

typedef struct load_name_entry {
    char name[sizeof(((thz_channel *)NULL)->name)];
    size_t channel;
} load_name_entry;

static int load_name_cmp(const void *a, const void *b)
{
    const load_name_entry *x = a, *y = b;
    int c = strcmp(x->name, y->name);
    return c ? c : (x->channel > y->channel) - (x->channel < y->channel);
}

/* Fills e with every channel's name, or for unnamed channels their frequency with
 * `decimals` decimals, sorted by name. */
static void load_name_entries(const thz_scene *s, load_name_entry *e, int decimals)
{
    for (size_t i = 0; i < s->n_channels; i++) {
        const thz_channel *ch = &s->channels[i];
        e[i].channel = i;
        if (ch->name[0])
            memcpy(e[i].name, ch->name, sizeof e[i].name);
        else
            snprintf(e[i].name, sizeof e[i].name, "%.*f THz", decimals, ch->center_hz * 1e-12);
    }
    qsort(e, s->n_channels, sizeof *e, load_name_cmp);
}

/* Names the channels that have no name (c: the channels key; `list`: the list form,
 * whose entries' paths then name a channel). */
static thz_status load_channel_default_names(load_ctx *ctx, const load_cursor *c, bool list)
{
    thz_scene *s = ctx->scene;
    size_t n = s->n_channels;
    load_name_entry *e = thz_malloc_array(n, sizeof *e);
    bool *unnamed = thz_malloc_array(n, sizeof *unnamed);
    thz_status st = THZ_OK;
    if (!e || !unnamed) {
        st = thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
        goto cleanup;
    }
    size_t left = 0;
    for (size_t i = 0; i < n; i++) {
        unnamed[i] = !s->channels[i].name[0];
        left += unnamed[i];
    }
    /* Names of different widths never coincide, so a name unique among those of its
     * width (and the given ones) is unique. */
    for (int d = LOAD_NAME_MIN_DECIMALS; d <= LOAD_NAME_MAX_DECIMALS && left > 0; d++) {
        load_name_entries(s, e, d);
        for (size_t i = 0; i < n; i++) {
            thz_channel *ch = &s->channels[e[i].channel];
            bool alone = (i == 0 || strcmp(e[i].name, e[i - 1].name) != 0) &&
                         (i + 1 == n || strcmp(e[i].name, e[i + 1].name) != 0);
            if (alone && !ch->name[0]) {
                memcpy(ch->name, e[i].name, sizeof ch->name);
                left--;
            }
        }
    }
    for (size_t i = 0; i < n && left > 0; i++) {
        thz_channel *ch = &s->channels[i];
        if (!ch->name[0])
            snprintf(ch->name, sizeof ch->name, "%.*f THz #%zu", LOAD_NAME_MIN_DECIMALS,
                     ch->center_hz * 1e-12, i);
    }
    /* Only a given name that looks like a default one can still coincide with it. */
    load_name_entries(s, e, 0);
    for (size_t i = 1; i < n; i++) {
        if (strcmp(e[i].name, e[i - 1].name) != 0)
            continue;
        size_t mine = unnamed[e[i].channel] ? e[i].channel : e[i - 1].channel;
        size_t other = mine == e[i].channel ? e[i - 1].channel : e[i].channel;
        load_cursor k = list ? load_index(c, mine) : *c;
        st = load_fail(ctx, &k,
                       "the default name \"%s\" of channels[%zu] is already used by "
                       "channels[%zu] (expected a \"name\" for it)",
                       s->channels[mine].name, mine, other);
        goto cleanup;
    }
cleanup:
    free(e);
    free(unnamed);
    return st;
}

static const load_range load_relative_width = {0.0, 0.5, true, false};

static thz_status load_channel_range(load_ctx *ctx, const load_cursor *c)
{
    static const char *const keys[] = {"from_thz", "to_thz", "count", "relative_width", NULL};
    thz_scene *s = ctx->scene;
    double from, to, width;
    uint64_t count;
    thz_status st = load_expect_object(ctx, c, keys);
    if (st == THZ_OK)
        st = load_number(ctx, c, "from_thz", LOAD_POSITIVE, true, 0, &from);
    if (st == THZ_OK)
        st = load_number(ctx, c, "to_thz", LOAD_POSITIVE, true, 0, &to);
    if (st == THZ_OK)
        st = load_integer(ctx, c, "count", 1, LOAD_MAX_CHANNELS, true, 0, &count);
    if (st == THZ_OK)
        st = load_number(ctx, c, "relative_width", load_relative_width, true, 0, &width);
    if (st != THZ_OK)
        return st;
    load_cursor k = load_key(c, "to_thz");
    if (count == 1 && to != from)
        return load_fail(ctx, &k, "with count 1, to_thz must equal from_thz (%g)", from);
    if (count > 1 && !(to > from))
        return load_fail(ctx, &k, "expected a number > from_thz (%g), got %g", from, to);
    s->channels = thz_calloc(count, sizeof *s->channels);
    if (!s->channels)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    s->n_channels = count;
    for (size_t i = 0; i < count; i++) {
        thz_channel *ch = &s->channels[i];
        double thz = count == 1 ? from : from + (to - from) * (double)i / (double)(count - 1);
        if (i + 1 == count)
            thz = to; /* exactly the given end */
        ch->center_hz = thz * 1e12;
        ch->relative_width = width;
    }
    return load_channel_default_names(ctx, c, false);
}

thz_status load_channels(load_ctx *ctx, const load_cursor *root)
{
    static const char *const keys[] = {"name", "frequency_thz", "relative_width", NULL};
    thz_scene *s = ctx->scene;
    load_cursor c = load_key(root, "channels");
    const char *what = "a list of channels [{\"frequency_thz\": ..., \"relative_width\": ...}] or "
                       "a range {\"from_thz\", \"to_thz\", \"count\", \"relative_width\"}";
    if (!c.value)
        return load_fail(ctx, &c, "missing key (expected %s)", what);
    if (json_is_object(c.value))
        return load_channel_range(ctx, &c);
    if (!json_is_array(c.value))
        return load_fail(ctx, &c, "expected %s, got %s", what, load_type_name(c.value));
    size_t n = json_array_size(c.value);
    if (n == 0)
        return load_fail(ctx, &c, "expected at least one channel, got an empty list");
    if (n > LOAD_MAX_CHANNELS)
        return load_fail(ctx, &c, "expected at most %u channels, got %zu", LOAD_MAX_CHANNELS, n);
    s->channels = thz_calloc(n, sizeof *s->channels);
    if (!s->channels)
        return thz_error_set(ctx->err, THZ_ERR_NOMEM, "out of memory");
    s->n_channels = n;
    for (size_t i = 0; i < n; i++) {
        load_cursor e = load_index(&c, i);
        thz_channel *ch = &s->channels[i];
        double thz;
        const char *name = NULL;
        thz_status st = load_expect_object(ctx, &e, keys);
        if (st == THZ_OK)
            st = load_number(ctx, &e, "frequency_thz", LOAD_POSITIVE, true, 0, &thz);
        if (st == THZ_OK)
            st = load_number(ctx, &e, "relative_width", load_relative_width, true, 0,
                             &ch->relative_width);
        if (st == THZ_OK)
            st = load_unique_name(ctx, &c, i, "channel", false, &name);
        if (st != THZ_OK)
            return st;
        ch->center_hz = thz * 1e12;
        if (name && strlen(name) >= sizeof ch->name) {
            load_cursor k = load_key(&e, "name");
            return load_fail(ctx, &k, "channel names are at most %zu characters",
                             sizeof ch->name - 1);
        }
        if (name)
            memcpy(ch->name, name, strlen(name) + 1);
    }
    return load_channel_default_names(ctx, &c, true);
}
