/* Scenes and sequences loaded within a root (thz_scene_load_within and friends, the
 * loading `thzmap serve --root` does): in a temporary tree
 *
 *   T/outside.csv                 a valid table outside the root, holding a marker
 *   T/other/scene.json            a valid scene outside the root
 *   T/root/s/in.csv               a table inside
 *   T/root/s/link.csv -> T/outside.csv, T/root/s/dangling.csv -> T/nothing.csv
 *   T/root/s/scene.json           a scene naming in.csv
 *   T/root/seq-in.json, seq-out.json, seq-list.json, seq-abs.json   sequences
 *
 * a table named inside loads; by "..", by an absolute path or through the symlink it
 * is refused at the key's JSON path without a word of its content, and so is a missing
 * one (the same words whether or not the name exists outside); a mesh likewise; a scene
 * or sequence file outside, and a sequence naming a scene outside, are refused; without
 * a root the same scenes load as before. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "thzmap/thzmap.h"

#define MARKER "OUTSIDE-MARKER-5c1e9a"

static char tree[64];         /* T */
static char root[128];        /* T/root */
static char scene_dir[160];   /* T/root/s */
static char created[16][256]; /* files and directories, removed in reverse order */
static size_t n_created;

static const char *at(const char *rel)
{
    static char path[4][256];
    static int next;
    char *p = path[next++ % 4];
    snprintf(p, sizeof path[0], "%s/%s", tree, rel);
    return p;
}

static void remember(const char *path)
{
    assert_true(n_created < sizeof created / sizeof created[0]);
    snprintf(created[n_created++], sizeof created[0], "%s", path);
}

static void make_dir(const char *rel)
{
    assert_int_equal(mkdir(at(rel), 0700), 0);
    remember(at(rel));
}

static void write_file(const char *rel, const char *text)
{
    FILE *f = fopen(at(rel), "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
    remember(at(rel));
}

/* A scene whose material "m" reads the table `file` and whose object is `shape`. */
static const char *scene_text(const char *file, const char *shape)
{
    static char text[2048];
    snprintf(text, sizeof text,
             "{\"format\": \"thzmap-scene/1\", "
             "\"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.01}], "
             "\"materials\": {\"m\": {\"file\": \"%s\"}}, "
             "\"objects\": [{\"name\": \"o\", \"type\": \"solid\", \"material\": \"m\", "
             "\"temperature_k\": 300, \"shape\": %s}], "
             "\"sensors\": [{\"name\": \"c\", \"position_m\": [0, -5, 0], "
             "\"look_at_m\": [0, 0, 0], \"fov_deg\": 40, \"resolution\": [16, 8]}]}",
             file, shape ? shape : "{\"type\": \"box\", \"size_m\": [1, 1, 1]}");
    return text;
}

static const char table[] = "# " MARKER "\n"
                            "frequency_thz,reflectivity\n"
                            "0.1,0.1\n"
                            "2.0,0.2\n";

static int setup(void **state)
{
    (void)state;
    snprintf(tree, sizeof tree, "/tmp/thz-within-XXXXXX");
    if (!mkdtemp(tree))
        return -1;
    snprintf(root, sizeof root, "%s/root", tree);
    snprintf(scene_dir, sizeof scene_dir, "%s/root/s", tree);
    write_file("outside.csv", table);
    make_dir("other");
    write_file("other/in.csv", table);
    write_file("other/scene.json", scene_text("in.csv", NULL));
    make_dir("root");
    make_dir("root/s");
    write_file("root/s/in.csv", table);
    write_file("root/s/scene.json", scene_text("in.csv", NULL));
    write_file("root/s/scene-out.json", scene_text("../../outside.csv", NULL));
    if (symlink(at("outside.csv"), at("root/s/link.csv")) != 0)
        return -1;
    remember(at("root/s/link.csv"));
    if (symlink(at("nothing.csv"), at("root/s/dangling.csv")) != 0)
        return -1;
    remember(at("root/s/dangling.csv"));
    write_file("root/seq-in.json",
               "{\"format\": \"thzmap-sequence/1\", \"scene\": \"s/scene.json\"}");
    write_file("root/seq-out.json",
               "{\"format\": \"thzmap-sequence/1\", \"scene\": \"../other/scene.json\"}");
    write_file("root/seq-list.json", "{\"format\": \"thzmap-sequence/1\", "
                                     "\"scenes\": [\"s/scene.json\", \"s/scene-out.json\"]}");
    char abs_seq[512];
    snprintf(abs_seq, sizeof abs_seq,
             "{\"format\": \"thzmap-sequence/1\", \"scenes\": [\"%s/other/scene.json\"]}", tree);
    write_file("root/seq-abs.json", abs_seq);
    return 0;
}

static int teardown(void **state)
{
    (void)state;
    while (n_created > 0) {
        const char *p = created[--n_created];
        if (unlink(p) != 0)
            rmdir(p);
    }
    rmdir(tree);
    return 0;
}

/* The scene text naming `file` (and `shape`) from T/root/s: loads without a root. */
static void loads_unconfined(const char *file, const char *shape)
{
    thz_scene *s = NULL;
    thz_error err = {0};
    thz_status st = thz_scene_load_string(scene_text(file, shape), scene_dir, "t.json", &s, &err);
    if (st != THZ_OK)
        fail_msg("%s without a root: %s", file, err.message);
    thz_scene_destroy(s);
}

/* ... and is refused within the root, at `json_path` naming `name` (the table or the
 * mesh), saying `why`, quoting nothing. */
static void refused_at(const char *file, const char *shape, const char *json_path, const char *name,
                       const char *why)
{
    thz_scene *s = (thz_scene *)1;
    thz_error err = {0};
    thz_status st =
        thz_scene_load_string_within(scene_text(file, shape), scene_dir, "t.json", root, &s, &err);
    if (st != THZ_ERR_INPUT)
        fail_msg("%s within the root: status %d (%s), expected an input error", file, (int)st,
                 err.message);
    assert_null(s);
    char expect[256];
    snprintf(expect, sizeof expect, "t.json: %s: \"%s\" ", json_path, name);
    if (strncmp(err.message, expect, strlen(expect)) != 0 || !strstr(err.message, why))
        fail_msg("message '%s': expected '%s...%s'", err.message, expect, why);
    if (strstr(err.message, MARKER) || strstr(err.message, "reflectivity"))
        fail_msg("message '%s' quotes a file", err.message);
}

static void refused(const char *file, const char *why)
{
    refused_at(file, NULL, "materials.m.file", file, why);
}

static void test_inside_loads(void **state)
{
    (void)state;
    thz_scene *s = NULL;
    thz_error err = {0};
    thz_status st = thz_scene_load_string_within(scene_text("in.csv", NULL), scene_dir, "t.json",
                                                 root, &s, &err);
    if (st != THZ_OK)
        fail_msg("in.csv within the root: %s", err.message);
    thz_scene_destroy(s);
    /* the root given with a trailing slash and "." components, the scene by its path */
    char loose[256], path[256];
    snprintf(loose, sizeof loose, "%s/./", root);
    snprintf(path, sizeof path, "%s/scene.json", scene_dir);
    st = thz_scene_load_within(path, loose, &s, &err);
    if (st != THZ_OK)
        fail_msg("%s within %s: %s", path, loose, err.message);
    thz_scene_destroy(s);
    loads_unconfined("in.csv", NULL);
}

static void test_table_outside(void **state)
{
    (void)state;
    char abs[256];
    snprintf(abs, sizeof abs, "%s/outside.csv", tree);
    const char *outside[] = {"../../outside.csv", abs, "link.csv"};
    const char *why[] = {"is outside the served root", "is an absolute path",
                         "is outside the served root"};
    for (size_t i = 0; i < 3; i++) {
        loads_unconfined(outside[i], NULL);
        refused(outside[i], why[i]);
    }
    /* inside, through "..": fine */
    thz_scene *s = NULL;
    thz_error err = {0};
    if (thz_scene_load_string_within(scene_text("../s/in.csv", NULL), scene_dir, "t.json", root, &s,
                                     &err) != THZ_OK)
        fail_msg("../s/in.csv: %s", err.message);
    thz_scene_destroy(s);
}

static void test_missing(void **state)
{
    (void)state;
    refused("missing.csv", "does not exist under the served root");
    refused("no/such/dir/x.csv", "does not exist under the served root");
    /* outside, whether or not the name exists there: the same words */
    refused("../../nothing.csv", "is outside the served root");
    refused("../../nothing/x.csv", "is outside the served root");
    refused("../../other/x.csv", "is outside the served root");
    refused("dangling.csv", "cannot be resolved under the served root");
}

static void test_mesh_outside(void **state)
{
    (void)state;
    refused_at("in.csv", "{\"type\": \"mesh\", \"file\": \"../../other/m.obj\"}",
               "objects[0].shape.file", "../../other/m.obj", "is outside the served root");
}

static void test_scene_file_outside(void **state)
{
    (void)state;
    thz_scene *s = (thz_scene *)1;
    thz_error err = {0};
    assert_int_equal(thz_scene_load_within(at("other/scene.json"), root, &s, &err), THZ_ERR_INPUT);
    assert_null(s);
    assert_non_null(strstr(err.message, "the scene file is outside the served root"));
    /* a scene file inside whose table is outside: refused at the key */
    char path[256];
    snprintf(path, sizeof path, "%s/scene-out.json", scene_dir);
    assert_int_equal(thz_scene_load_within(path, root, &s, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "materials.m.file: \"../../outside.csv\" is outside"));
    assert_int_equal(thz_scene_load(path, &s, &err), THZ_OK);
    thz_scene_destroy(s);
    /* a root that is no directory */
    assert_int_equal(thz_scene_load_within(path, at("outside.csv"), &s, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "the root is not a directory"));
}

/* Loads sequence `rel` (under T/root) within the root: the message when refused. */
static const char *sequence_refusal(const char *rel)
{
    static thz_error err;
    char path[256];
    snprintf(path, sizeof path, "%s/%s", root, rel);
    thz_sequence *seq = NULL;
    memset(&err, 0, sizeof err);
    thz_status st = thz_sequence_load_within(path, root, &seq, &err);
    thz_sequence_destroy(seq);
    if (st == THZ_OK)
        return NULL;
    assert_int_equal(st, THZ_ERR_INPUT);
    return err.message;
}

static void test_sequences(void **state)
{
    (void)state;
    assert_null(sequence_refusal("seq-in.json"));
    const char *m = sequence_refusal("seq-out.json");
    if (!m || !strstr(m, "scene: \"../other/scene.json\" is outside the served root"))
        fail_msg("seq-out.json: %s", m ? m : "loaded");
    m = sequence_refusal("seq-abs.json");
    if (!m || !strstr(m, "scenes[0]: \"") || !strstr(m, "is an absolute path"))
        fail_msg("seq-abs.json: %s", m ? m : "loaded");
    /* the second scene of the list names a table outside: its frame is refused */
    m = sequence_refusal("seq-list.json");
    if (!m || !strstr(m, "frame-00001 (scenes[1]") ||
        !strstr(m, "materials.m.file: \"../../outside.csv\" is outside the served root") ||
        strstr(m, MARKER))
        fail_msg("seq-list.json: %s", m ? m : "loaded");
    /* the sequence file itself outside the root */
    thz_sequence *seq = NULL;
    thz_error err = {0};
    char path[256];
    snprintf(path, sizeof path, "%s/root/s", tree);
    assert_int_equal(thz_sequence_load_within(at("other/scene.json"), path, &seq, &err),
                     THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "the sequence file is outside the served root"));
    /* without a root all of them load, as before */
    const char *all[] = {"seq-in.json", "seq-out.json", "seq-list.json", "seq-abs.json"};
    for (size_t i = 0; i < 4; i++) {
        snprintf(path, sizeof path, "%s/%s", root, all[i]);
        if (thz_sequence_load(path, &seq, &err) != THZ_OK)
            fail_msg("%s without a root: %s", all[i], err.message);
        thz_sequence_destroy(seq);
    }
    /* a frame loaded later keeps to the root */
    snprintf(path, sizeof path, "%s/seq-in.json", root);
    assert_int_equal(thz_sequence_load_within(path, root, &seq, &err), THZ_OK);
    thz_scene *s = NULL;
    assert_int_equal(thz_sequence_frame_scene(seq, 0, &s, &err), THZ_OK);
    thz_scene_destroy(s);
    thz_sequence_destroy(seq);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_inside_loads),
        cmocka_unit_test(test_table_outside),
        cmocka_unit_test(test_missing),
        cmocka_unit_test(test_mesh_outside),
        cmocka_unit_test(test_scene_file_outside),
        cmocka_unit_test(test_sequences),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
