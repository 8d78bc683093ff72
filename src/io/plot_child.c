/* PLplot's figures, each drawn in a child process (plot_draw.h says why): one at a time
 * (plot_image, plot_classes, plot_lines, plot_attenuation) or a batch of them by a few children at
 * once (plot_batch_*).
 */
#include <pthread.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/child.h"
#include "io/plot_draw.h"

enum { PLOT_CHILD_TEXT = 4200 };

/* PLplot reads the working directory into 1024 bytes and ends the process when it is
 * longer ("get_tmpdir_list: getcwd error"): every figure failed from a directory deeper
 * than that. In a figure's child, before PLplot: such a child moves to "/" and keeps the
 * directory it came from in cwd (else cwd is ""), for plot_child_path. */
static void plot_child_short_cwd(char *cwd, size_t size)
{
    char probe[1024];
    cwd[0] = '\0';
    if (getcwd(probe, sizeof probe) || !getcwd(cwd, size) || chdir("/") != 0)
        cwd[0] = '\0';
}

/* In a figure's child, before PLplot loads its cairo driver (and with it GLib): GLib's
 * slice allocator, when an allocation in its own set-up fails, logs the failure through
 * code that allocates a slice again and waits on its own lock for ever (seen under
 * tests/cli/test_alloc_fail.sh's failing allocator: render hung past the test's 90 s,
 * the figures' time limit being 60 s each). With plain malloc GLib aborts instead, and
 * the run fails at once "while plotting". Set in the child alone, which one thread runs. */
static void plot_child_begin(char *cwd, size_t size)
{
    setenv("G_SLICE", "always-malloc", 0);
    plot_child_short_cwd(cwd, size);
}

/* path as the child must name it: as given, or after cwd when the child moved. */
static const char *plot_child_path(const char *cwd, const char *path, char *buf, size_t size)
{
    if (!cwd[0] || path[0] == '/')
        return path;
    int n = snprintf(buf, size, "%s/%s", cwd, path);
    return n > 0 && (size_t)n < size ? buf : path;
}

static thz_status plot_check_device_child(void *arg, thz_error *err)
{
    char cwd[PLOT_CHILD_TEXT];
    plot_child_begin(cwd, sizeof cwd);
    return plot_check_device_here(arg, err);
}

/* The PLPLOT_DRV_DIR of the last check that found the device ("" when unset), and
 * whether there was one; guarded by the mutex (runs may write outputs from several
 * threads: the GUI server's jobs). */
static pthread_mutex_t plot_device_lock = PTHREAD_MUTEX_INITIALIZER;
static bool plot_device_found;
static char plot_device_dir[PLOT_CHILD_TEXT];

thz_status plot_check_device(thz_error *err)
{
    const char *env = getenv("PLPLOT_DRV_DIR");
    const char *dir = env ? env : "";
    pthread_mutex_lock(&plot_device_lock);
    bool known = plot_device_found && strcmp(plot_device_dir, dir) == 0;
    pthread_mutex_unlock(&plot_device_lock);
    if (known)
        return THZ_OK;
    thz_status st = child_run("checking PLplot's devices", plot_check_device_child, NULL,
                              plot_timeout_s(0), err);
    if (st == THZ_OK && strlen(dir) < sizeof plot_device_dir) {
        pthread_mutex_lock(&plot_device_lock);
        strcpy(plot_device_dir, dir);
        plot_device_found = true;
        pthread_mutex_unlock(&plot_device_lock);
    }
    return st;
}

/* plot_attenuation's arguments, passed to its child (which sees the caller's memory). */
typedef struct plot_attenuation_args {
    const char *path, *title, *x_label, *y_label;
    size_t n_x, n_curves, n_bands;
    const double *x;
    const plot_curve *curves;
    const plot_band *bands;
} plot_attenuation_args;

static thz_status plot_attenuation_child(void *arg, thz_error *err)
{
    const plot_attenuation_args *a = arg;
    char cwd[PLOT_CHILD_TEXT], path[2 * PLOT_CHILD_TEXT];
    plot_child_begin(cwd, sizeof cwd);
    return plot_attenuation_draw(plot_child_path(cwd, a->path, path, sizeof path), a->n_x, a->x,
                                 a->n_curves, a->curves, a->n_bands, a->bands, a->title, a->x_label,
                                 a->y_label, err);
}

thz_status plot_attenuation(const char *path, size_t n_x, const double *x, size_t n_curves,
                            const plot_curve *curves, size_t n_bands, const plot_band *bands,
                            const char *title, const char *x_label, const char *y_label,
                            thz_error *err)
{
    plot_attenuation_args a = {.path = path,
                               .title = title,
                               .x_label = x_label,
                               .y_label = y_label,
                               .n_x = n_x,
                               .n_curves = n_curves,
                               .n_bands = n_bands,
                               .x = x,
                               .curves = curves,
                               .bands = bands};
    char what[PLOT_CHILD_TEXT];
    snprintf(what, sizeof what, "plotting %s", path);
    return child_run(what, plot_attenuation_child, &a, plot_timeout_s(n_x * n_curves), err);
}

/* plot_classes' arguments, passed to its child. */
typedef struct plot_classes_args {
    const char *path, *title;
    const int32_t *classes;
    uint32_t columns, rows;
    size_t n_classes;
    const char *const *names;
    const unsigned char (*rgb)[3];
} plot_classes_args;

static thz_status plot_classes_child(void *arg, thz_error *err)
{
    const plot_classes_args *a = arg;
    char cwd[PLOT_CHILD_TEXT], path[2 * PLOT_CHILD_TEXT];
    plot_child_short_cwd(cwd, sizeof cwd);
    return plot_classes_draw(plot_child_path(cwd, a->path, path, sizeof path), a->classes,
                             a->columns, a->rows, a->n_classes, a->names, a->rgb, a->title, err);
}

thz_status plot_classes(const char *path, const int32_t *classes, uint32_t columns, uint32_t rows,
                        size_t n_classes, const char *const *names, const unsigned char (*rgb)[3],
                        const char *title, thz_error *err)
{
    plot_classes_args a = {.path = path,
                           .title = title,
                           .classes = classes,
                           .columns = columns,
                           .rows = rows,
                           .n_classes = n_classes,
                           .names = names,
                           .rgb = rgb};
    char what[PLOT_CHILD_TEXT];
    snprintf(what, sizeof what, "plotting %s", path);
    return child_run(what, plot_classes_child, &a, plot_timeout_s((size_t)columns * rows), err);
}

/* ---- batches ------------------------------------------------------------------------ */

typedef enum plot_item_kind { PLOT_ITEM_IMAGE, PLOT_ITEM_LINES } plot_item_kind;

/* One figure of a batch: its own copies of every text and of a line plot's arrays; an
 * image's values are the caller's. */
typedef struct plot_item {
    plot_item_kind kind;
    char *path, *title, *x_label, *y_label;
    const float *values;
    uint32_t columns, rows;
    size_t n_x, n_lines;
    double *x, *y;
    char **names;
    bool whole_x; /* a line plot's x: whole numbers (plot_lines_whole_x) */
} plot_item;

struct plot_batch {
    plot_item *items;
    size_t n, capacity;
};

plot_batch *plot_batch_create(void)
{
    return thz_calloc(1, sizeof(plot_batch));
}

static void plot_item_fini(plot_item *it)
{
    free(it->path);
    free(it->title);
    free(it->x_label);
    free(it->y_label);
    free(it->x);
    free(it->y);
    for (size_t i = 0; it->names && i < it->n_lines; i++)
        free(it->names[i]);
    free(it->names);
}

void plot_batch_destroy(plot_batch *b)
{
    if (!b)
        return;
    for (size_t i = 0; i < b->n; i++)
        plot_item_fini(&b->items[i]);
    free(b->items);
    free(b);
}

/* A new item at the batch's end (zeroed, its texts copied), or NULL. */
static plot_item *plot_batch_add(plot_batch *b, plot_item_kind kind, const char *path,
                                 const char *title, const char *x_label, const char *y_label)
{
    if (b->n == b->capacity) {
        plot_item *p = thz_grow_array(b->items, &b->capacity, 16, sizeof *p);
        if (!p)
            return NULL;
        b->items = p;
    }
    plot_item *it = &b->items[b->n];
    memset(it, 0, sizeof *it);
    it->kind = kind;
    it->path = thz_strdup(path ? path : "");
    it->title = thz_strdup(title ? title : "");
    it->x_label = thz_strdup(x_label ? x_label : "");
    it->y_label = thz_strdup(y_label ? y_label : "");
    if (!it->path || !it->title || !it->x_label || !it->y_label) {
        plot_item_fini(it);
        return NULL;
    }
    b->n++;
    return it;
}

thz_status plot_batch_image(plot_batch *b, const char *path, const float *values, uint32_t columns,
                            uint32_t rows, const char *title, const char *value_label,
                            thz_error *err)
{
    plot_item *it = plot_batch_add(b, PLOT_ITEM_IMAGE, path, title, "", value_label);
    if (!it)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
    it->values = values;
    it->columns = columns;
    it->rows = rows;
    return THZ_OK;
}

static thz_status plot_batch_lines_x(plot_batch *b, const char *path, size_t n_x, const double *x,
                                     size_t n_lines, const char *const *names, const double *y,
                                     const char *title, const char *x_label, const char *y_label,
                                     bool whole_x, thz_error *err)
{
    plot_item *it = plot_batch_add(b, PLOT_ITEM_LINES, path, title, x_label, y_label);
    if (!it)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
    it->n_x = n_x;
    it->x = thz_malloc_array(n_x ? n_x : 1, sizeof *it->x);
    const size_t n_y = n_x * n_lines;
    it->y = thz_malloc_array(n_y > 0 ? n_y : 1, sizeof *it->y);
    it->names = thz_calloc(n_lines ? n_lines : 1, sizeof *it->names);
    bool ok = it->x && it->y && it->names;
    for (size_t i = 0; ok && i < n_lines; i++) {
        it->names[i] = thz_strdup(names[i] ? names[i] : "");
        it->n_lines = i + 1;
        ok = it->names[i] != NULL;
    }
    if (!ok) {
        plot_item_fini(it);
        b->n--;
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
    }
    if (n_x)
        memcpy(it->x, x, n_x * sizeof *x);
    if (n_y > 0)
        memcpy(it->y, y, n_y * sizeof *y);
    it->whole_x = whole_x;
    return THZ_OK;
}

thz_status plot_batch_lines(plot_batch *b, const char *path, size_t n_x, const double *x,
                            size_t n_lines, const char *const *names, const double *y,
                            const char *title, const char *x_label, const char *y_label,
                            thz_error *err)
{
    return plot_batch_lines_x(b, path, n_x, x, n_lines, names, y, title, x_label, y_label, false,
                              err);
}

/* A child's share of a batch: items [lo, hi). */
typedef struct plot_share {
    const plot_batch *b;
    size_t lo, hi;
} plot_share;

/* In the child: its figures in order, stopping at the first that fails. */
static thz_status plot_share_child(void *arg, thz_error *err)
{
    const plot_share *sh = arg;
    char cwd[PLOT_CHILD_TEXT], buf[2 * PLOT_CHILD_TEXT];
    plot_child_begin(cwd, sizeof cwd);
    for (size_t i = sh->lo; i < sh->hi; i++) {
        const plot_item *it = &sh->b->items[i];
        const char *path = plot_child_path(cwd, it->path, buf, sizeof buf);
        thz_status st =
            it->kind == PLOT_ITEM_IMAGE
                ? plot_image_draw(path, it->values, it->columns, it->rows, it->title, it->y_label,
                                  err)
                : plot_lines_draw(path, it->n_x, it->x, it->n_lines, (const char *const *)it->names,
                                  it->y, it->title, it->x_label, it->y_label, it->whole_x, err);
        if (st != THZ_OK)
            return st;
    }
    return THZ_OK;
}

static size_t plot_item_cells(const plot_item *it)
{
    return it->kind == PLOT_ITEM_IMAGE ? (size_t)it->columns * it->rows : it->n_x * it->n_lines;
}

thz_status plot_batch_run(plot_batch *b, int processes, const cancel_check *cancel, thz_error *err)
{
    if (!b || b->n == 0)
        return THZ_OK;
    size_t k = processes > 0 ? (size_t)processes : 0;
    if (k == 0) {
        long cpus = sysconf(_SC_NPROCESSORS_ONLN);
        k = cpus > 0 ? (size_t)cpus : 1;
    }
    size_t most = b->n / PLOT_FIGURES_PER_CHILD; /* a child's set-up is worth it */
    most = most > 0 ? most : 1;
    k = k < most ? k : most;
    k = k < CHILD_GROUP_MAX ? k : CHILD_GROUP_MAX;
    plot_share shares[CHILD_GROUP_MAX];
    void *args[CHILD_GROUP_MAX];
    char(*whats)[PLOT_CHILD_TEXT] = thz_malloc_array(k, sizeof *whats);
    if (!whats)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory while plotting %s",
                             b->items[0].path);
    const char *what_ptrs[CHILD_GROUP_MAX];
    double timeout_s = 0.0;
    for (size_t c = 0; c < k; c++) {
        /* contiguous shares in order: the first failing child holds the first failing
         * figure, whatever the number of children */
        shares[c] = (plot_share){.b = b, .lo = b->n * c / k, .hi = b->n * (c + 1) / k};
        args[c] = &shares[c];
        size_t more = shares[c].hi - shares[c].lo - 1;
        if (more)
            snprintf(whats[c], sizeof whats[c], "plotting %s and %zu more figure%s",
                     b->items[shares[c].lo].path, more, more == 1 ? "" : "s");
        else
            snprintf(whats[c], sizeof whats[c], "plotting %s", b->items[shares[c].lo].path);
        what_ptrs[c] = whats[c];
        double t = 0.0;
        for (size_t i = shares[c].lo; i < shares[c].hi; i++)
            t += plot_timeout_s(plot_item_cells(&b->items[i]));
        timeout_s = t > timeout_s ? t : timeout_s;
    }
    thz_status st = child_run_group(what_ptrs, plot_share_child, args, k, timeout_s, cancel, err);
    free(whats);
    return st;
}

/* ---- one figure: a batch of one ---------------------------------------------------- */

thz_status plot_image(const char *path, const float *values, uint32_t columns, uint32_t rows,
                      const char *title, const char *value_label, thz_error *err)
{
    plot_batch *b = plot_batch_create();
    if (!b)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
    thz_status st = plot_batch_image(b, path, values, columns, rows, title, value_label, err);
    if (st == THZ_OK)
        st = plot_batch_run(b, 1, NULL, err);
    plot_batch_destroy(b);
    return st;
}

static thz_status plot_lines_one(const char *path, size_t n_x, const double *x, size_t n_lines,
                                 const char *const *names, const double *y, const char *title,
                                 const char *x_label, const char *y_label, bool whole_x,
                                 thz_error *err)
{
    plot_batch *b = plot_batch_create();
    if (!b)
        return thz_error_set(err, THZ_ERR_NOMEM, "%s: out of memory", path);
    thz_status st = plot_batch_lines_x(b, path, n_x, x, n_lines, names, y, title, x_label, y_label,
                                       whole_x, err);
    if (st == THZ_OK)
        st = plot_batch_run(b, 1, NULL, err);
    plot_batch_destroy(b);
    return st;
}

thz_status plot_lines(const char *path, size_t n_x, const double *x, size_t n_lines,
                      const char *const *names, const double *y, const char *title,
                      const char *x_label, const char *y_label, thz_error *err)
{
    return plot_lines_one(path, n_x, x, n_lines, names, y, title, x_label, y_label, false, err);
}

thz_status plot_lines_whole_x(const char *path, size_t n_x, const double *x, size_t n_lines,
                              const char *const *names, const double *y, const char *title,
                              const char *x_label, const char *y_label, thz_error *err)
{
    return plot_lines_one(path, n_x, x, n_lines, names, y, title, x_label, y_label, true, err);
}
