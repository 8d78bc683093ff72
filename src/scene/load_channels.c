/* The scene's `channels` block: a list of channels (each a Gaussian of relative_width
 * or a measured response, inline or from a CSV file) or an evenly spaced range of
 * Gaussians, and the default names of unnamed channels (unique, so that ENVI band names
 * are). */
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
        st = load_number(ctx, c, "from_thz", LOAD_FREQUENCY, true, 0, &from);
    if (st == THZ_OK)
        st = load_number(ctx, c, "to_thz", LOAD_FREQUENCY, true, 0, &to);
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
        return load_fail(ctx, &k, "expected a number > from_thz (%s), got %s", LOAD_G(from),
                         LOAD_G(to));
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

/* The measured response of list entry e (`response` or `response_file`, which the
 * caller has found) as a table of at least 2 points with a weight > 0. */
static thz_status load_channel_table(load_ctx *ctx, const load_cursor *e, thz_spectrum *out)
{
    load_cursor k = load_key(e, "response");
    thz_status st = THZ_OK;
    const char *where = NULL; /* the CSV file, for messages */
    csv_table t = {0};
    if (k.value) {
        bool present;
        if (!json_is_array(k.value))
            return load_fail(ctx, &k, "expected a table [[frequency_thz, weight], ...], got %s",
                             load_type_name(k.value));
        if (json_array_size(k.value) < 2)
            return load_fail(ctx, &k, "expected at least 2 points [frequency_thz, weight], got %zu",
                             json_array_size(k.value));
        st = load_spectrum(ctx, e, "response", LOAD_NONNEGATIVE, out, &present);
    } else {
        k = load_key(e, "response_file");
        st = load_csv(ctx, e, "response_file", &t);
        if (st == THZ_OK) {
            static const char *const columns[] = {"weight", NULL};
            where = t.label;
            st = load_csv_columns(ctx, &k, &t, columns, "weight");
        }
        if (st == THZ_OK && t.n_rows < 2)
            st = load_fail(ctx, &k, "%s: expected at least 2 rows (frequency_thz, weight), got %zu",
                           t.label, t.n_rows);
        if (st == THZ_OK)
            st = load_csv_spectrum(ctx, &k, &t, "weight", LOAD_NONNEGATIVE, out);
    }
    double peak = 0.0;
    for (size_t i = 0; st == THZ_OK && i < out->n; i++)
        peak = out->value[i] > peak ? out->value[i] : peak;
    if (st == THZ_OK && !(peak > 0.0))
        st = load_fail(ctx, &k, "%s%severy weight is 0 (expected at least one > 0)",
                       where ? where : "", where ? ": " : "");
    csv_fini(&t);
    return st;
}

/* The spectral response of list entry e: relative_width (the Gaussian), or a measured
 * `response` or `response_file`, exactly one of them. frequency_thz (*thz) is required
 * with the Gaussian; with a table it is optional (0: the response-weighted mean) and
 * must lie where the response is > 0. */
static thz_status load_channel_response(load_ctx *ctx, const load_cursor *e, thz_channel *ch)
{
    static const char *const forms[] = {"relative_width", "response", "response_file"};
    size_t given = 0, which = 0;
    for (size_t i = 0; i < 3; i++)
        if (json_object_get(e->value, forms[i])) {
            given++;
            which = given == 1 ? i : which;
        }
    if (given != 1)
        return load_fail(ctx, e,
                         "%s (expected exactly one of relative_width, response, "
                         "response_file)",
                         given ? "conflicting responses" : "missing spectral response");
    double thz = 0.0;
    thz_status st = load_number(ctx, e, "frequency_thz", LOAD_FREQUENCY, which == 0, 0.0, &thz);
    if (st != THZ_OK)
        return st;
    if (which == 0) {
        ch->center_hz = thz * 1e12;
        return load_number(ctx, e, "relative_width", load_relative_width, true, 0,
                           &ch->relative_width);
    }
    thz_spectrum table = {0};
    st = load_channel_table(ctx, e, &table);
    if (st == THZ_OK) {
        thz_error inner = {0};
        st = channel_set_response(ch, table.n, table.freq_hz, table.value, thz * 1e12, &inner);
        if (st != THZ_OK)
            st = load_fail(ctx, e, "%s", inner.message);
    }
    spectrum_fini(&table);
    double lo = 0.0, hi = 0.0;
    if (st == THZ_OK)
        channel_support_hz(ch, 0.0, &lo, &hi);
    if (st == THZ_OK && hi > LOAD_MAX_FREQUENCY_THZ * 1e12)
        st = load_fail(ctx, e,
                       "expected a response that is 0 above %g THz (the frequencies' limit), it "
                       "is > 0 up to %s THz",
                       LOAD_MAX_FREQUENCY_THZ, LOAD_G(hi * 1e-12));
    if (st == THZ_OK && thz > 0.0) {
        if (!(ch->center_hz >= lo && ch->center_hz <= hi)) {
            load_cursor k = load_key(e, "frequency_thz");
            st = load_fail(ctx, &k,
                           "expected a frequency where the response is > 0 (%g to %g THz), got %g",
                           lo * 1e-12, hi * 1e-12, thz);
        }
    }
    return st;
}

thz_status load_channels(load_ctx *ctx, const load_cursor *root)
{
    static const char *const keys[] = {"name",     "frequency_thz", "relative_width",
                                       "response", "response_file", NULL};
    thz_scene *s = ctx->scene;
    load_cursor c = load_key(root, "channels");
    const char *what = "a list of channels [{\"frequency_thz\": ..., \"relative_width\": ...} or "
                       "{\"response\": [[frequency_thz, weight], ...]}] or "
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
        const char *name = NULL;
        thz_status st = load_expect_object(ctx, &e, keys);
        if (st == THZ_OK)
            st = load_channel_response(ctx, &e, ch);
        if (st == THZ_OK)
            st = load_unique_name(ctx, &c, i, "channel", false, &name);
        if (st != THZ_OK)
            return st;
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
