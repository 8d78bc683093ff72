/* Sequences through the API (thzmap/batch.h; scene-format.md "Sequences, sweeps and
 * movies"), without running them: frame numbering over a sweep (sweep-major), each frame's
 * time, directory and input hash, its scene as JSON text and as a loaded scene, with
 * keyframe values interpolated linearly in time and held beyond the ends, and frames out
 * of range refused. The values are worked out by hand from the files below.
 * argv: the thzmap binary (unused), the repository. */
#include <math.h>

#include "api_test.h"

static const char scene_json[] =
    "{\"format\": \"thzmap-scene/1\", \"name\": \"seq-test\",\n"
    " \"channels\": [{\"frequency_thz\": 0.35, \"relative_width\": 0.05}],\n"
    " \"materials\": {\"wall\": {\"reflectivity\": 0.2}},\n"
    " \"atmosphere\": {\"model\": \"constant\", \"attenuation_per_m\": 0.05},\n"
    " \"objects\": [\n"
    "  {\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\", \"temperature_k\": 295,\n"
    "   \"shape\": {\"type\": \"box\", \"size_m\": [4, 4, 4], \"inward\": true}},\n"
    "  {\"name\": \"plate\", \"type\": \"solid\", \"material\": \"wall\", \"temperature_k\": 300,\n"
    "   \"shape\": {\"type\": \"box\", \"size_m\": [0.4, 0.1, 0.1]},\n"
    "   \"transform\": {\"translate_m\": [0, 0.5, 0]}}],\n"
    " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -1.5, 0], \"look_at_m\": [0, 0, 0],\n"
    "   \"fov_deg\": 60, \"resolution\": [8, 6]}],\n"
    " \"photons\": {\"per_channel\": 1000, \"seed\": 1}}\n";

/* 5 frames at 2 fps (t = 0, 0.5, 1, 1.5, 2 s); the plate (0.4 m along x, 0.1 m across)
 * moves from x = -1 to x = 1 between t = 0.5 and 1.5 s, turns by 90 degrees about z (by
 * quaternion slerp: 45 degrees at t = 1 s) and warms from 300 to 320 K; held outside;
 * two sweep values of the air's attenuation: 10 frames in all. */
static const char sequence_json[] =
    "{\"format\": \"thzmap-sequence/1\", \"scene\": \"scene.json\", \"fps\": 2, \"frames\": 5,\n"
    " \"keyframes\": [\n"
    "  {\"time_s\": 0.5, \"objects\": {\"plate\": {\n"
    "     \"transform\": {\"translate_m\": [-1, 0.5, 0], \"rotate_deg\": [0, 0, 0]},\n"
    "     \"temperature_k\": 300}}},\n"
    "  {\"time_s\": 1.5, \"objects\": {\"plate\": {\n"
    "     \"transform\": {\"translate_m\": [1, 0.5, 0], \"rotate_deg\": [0, 0, 90]},\n"
    "     \"temperature_k\": 320}}}],\n"
    " \"sweep\": {\"atmosphere.attenuation_per_m\": [0.01, 0.2]}}\n";

/* The plate's centre x (its bounding box's middle), its extent along x and its
 * temperature in frame i's scene. */
static void plate_in_frame(const thz_sequence *seq, size_t i, double *x, double *width, double *t_k)
{
    thz_error err = {0};
    thz_scene *scene = NULL;
    *x = NAN;
    *width = NAN;
    *t_k = NAN;
    thz_status st = thz_sequence_frame_scene(seq, i, &scene, &err);
    CHECK(st == THZ_OK, "frame %zu's scene: %s", i, err.message);
    if (st != THZ_OK)
        return;
    long k = thz_scene_object_index(scene, "plate");
    thz_object_info oi;
    if (k >= 0 && thz_scene_object(scene, (size_t)k, &oi) == THZ_OK) {
        *x = 0.5 * (oi.bbox_min_m[0] + oi.bbox_max_m[0]);
        *width = oi.bbox_max_m[0] - oi.bbox_min_m[0];
        *t_k = oi.temperature_k;
    }
    thz_scene_destroy(scene);
}

/* A sweep of n values of one frame each: its first and last directories, which must sort
 * in order (two digits to 100 values, three beyond). */
static void sweep_dirs(const char *dir, size_t n, const char *first, const char *last)
{
    char path[4200], *text = malloc(64 * n + 200);
    if (!text) {
        CHECK(0, "out of memory");
        return;
    }
    size_t k = (size_t)sprintf(text, "{\"format\": \"thzmap-sequence/1\", \"scene\": "
                                     "\"scene.json\", \"frames\": 1, \"sweep\": "
                                     "{\"objects.plate.temperature_k\": [");
    for (size_t i = 0; i < n; i++)
        k += (size_t)sprintf(text + k, "%s%zu", i ? ", " : "", 300 + i);
    sprintf(text + k, "]}}\n");
    snprintf(path, sizeof path, "%s/sweep-%zu.json", dir, n);
    test_write_file(path, text);
    free(text);
    thz_error err = {0};
    thz_sequence *seq = NULL;
    thz_frame_info a = {0}, b = {0};
    REQUIRE_OK(thz_sequence_load(path, &seq, &err), &err);
    CHECK(thz_sequence_frame_count(seq) == n && thz_sequence_frame(seq, 0, &a) == THZ_OK &&
              thz_sequence_frame(seq, n - 1, &b) == THZ_OK && !strcmp(a.dir, first) &&
              !strcmp(b.dir, last),
          "%zu sweep values: %zu frames in %s .. %s, expected %s .. %s", n,
          thz_sequence_frame_count(seq), a.dir ? a.dir : "?", b.dir ? b.dir : "?", first, last);
    thz_sequence_destroy(seq);
}

int main(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    char dir[4096], path[4200];
    test_temp_dir(dir, sizeof dir);
    snprintf(path, sizeof path, "%s/scene.json", dir);
    test_write_file(path, scene_json);
    snprintf(path, sizeof path, "%s/sequence.json", dir);
    test_write_file(path, sequence_json);

    thz_error err = {0};
    thz_sequence *seq = NULL;
    REQUIRE_OK(thz_sequence_load(path, &seq, &err), &err);
    CHECK(thz_sequence_frame_count(seq) == 10 && thz_sequence_sweep_count(seq) == 2 &&
              thz_sequence_frames_per_sweep(seq) == 5,
          "%zu frames, %zu sweep values, %zu per value", thz_sequence_frame_count(seq),
          thz_sequence_sweep_count(seq), thz_sequence_frames_per_sweep(seq));

    /* numbering: sweep-major, times i / fps, directories by sweep and frame */
    thz_frame_info fi[10];
    for (size_t i = 0; i < 10; i++) {
        REQUIRE_OK(thz_sequence_frame(seq, i, &fi[i]), &err);
        char want[64];
        snprintf(want, sizeof want, "sweep-%02zu/frame-%05zu", i / 5, i % 5);
        CHECK(fi[i].sweep == i / 5 && fi[i].index == i % 5, "frame %zu: sweep %zu, index %zu", i,
              fi[i].sweep, fi[i].index);
        CHECK(fi[i].time_s == (double)(i % 5) / 2.0, "frame %zu at %g s", i, fi[i].time_s);
        CHECK(fi[i].dir && strcmp(fi[i].dir, want) == 0, "frame %zu's directory %s, not %s", i,
              fi[i].dir ? fi[i].dir : "(null)", want);
    }
    /* the hash names the inputs: frames 0 and 1 (the plate held at its first keyframe)
     * have the same scene, and so frames 3 and 4 (held at the last); every other pair
     * differs, across the sweep too */
    for (size_t i = 0; i < 10; i++)
        for (size_t j = i + 1; j < 10; j++) {
            int same_scene = j == i + 1 && (i % 5 == 0 || i % 5 == 3);
            CHECK((fi[i].hash == fi[j].hash) == same_scene, "frames %zu and %zu: hashes %s", i, j,
                  fi[i].hash == fi[j].hash ? "equal" : "differ");
        }
    thz_frame_info none = {.index = 99};
    CHECK(thz_sequence_frame(seq, 10, &none) == THZ_ERR_INPUT, "frame 10 of 10 accepted");

    /* interpolation: held before 0.5 s and after 1.5 s, linear between; the plate's extent
     * along x is 0.4 m unturned, (0.4 + 0.1) / sqrt 2 at 45 degrees, 0.1 m at 90 */
    const double want_x[5] = {-1.0, -1.0, 0.0, 1.0, 1.0};
    const double want_t[5] = {300.0, 300.0, 310.0, 320.0, 320.0};
    const double want_w[5] = {0.4, 0.4, 0.5 / sqrt(2.0), 0.1, 0.1};
    for (size_t i = 0; i < 10; i++) {
        double x, w, t_k;
        plate_in_frame(seq, i, &x, &w, &t_k);
        CHECK(fabs(x - want_x[i % 5]) < 1e-6 && fabs(t_k - want_t[i % 5]) < 1e-9,
              "frame %zu: plate at x = %g m, %g K; expected %g m, %g K", i, x, t_k, want_x[i % 5],
              want_t[i % 5]);
        CHECK(fabs(w - want_w[i % 5]) < 1e-6, "frame %zu: plate %g m wide along x, expected %g m",
              i, w, want_w[i % 5]);
    }

    /* the JSON text: snprintf's contract, the sweep's value in place, loadable as the scene */
    size_t n = thz_sequence_frame_json(seq, 7, NULL, 0);
    CHECK(n > 100, "frame 7's JSON: %zu characters", n);
    char *text = malloc(n + 1);
    char small[16];
    CHECK(thz_sequence_frame_json(seq, 7, small, sizeof small) == n && small[15] == '\0' &&
              strlen(small) == 15,
          "a short buffer: truncated with a NUL, the full length returned");
    CHECK(text && thz_sequence_frame_json(seq, 7, text, n + 1) == n && strlen(text) == n,
          "the full text");
    if (text) {
        CHECK(strncmp(text, small, 15) == 0, "the truncated text is not the text's start");
        CHECK(strstr(text, "\"attenuation_per_m\":0.2") != NULL,
              "frame 7 (sweep 1) lacks the sweep's attenuation 0.2: %.400s", text);
        CHECK(strchr(text, '\n') == NULL, "not compact: %.200s", text);
        thz_scene *scene = NULL;
        REQUIRE_OK(thz_scene_load_string(text, dir, "frame-7.json", &scene, &err), &err);
        long k = thz_scene_object_index(scene, "plate");
        thz_object_info oi;
        CHECK(k >= 0 && thz_scene_object(scene, (size_t)k, &oi) == THZ_OK &&
                  fabs(0.5 * (oi.bbox_min_m[0] + oi.bbox_max_m[0])) < 1e-6 &&
                  oi.temperature_k == 310.0,
              "frame 7 from its JSON text: the plate not at x = 0 m, 310 K");
        thz_scene_destroy(scene);
    }
    free(text);
    CHECK(thz_sequence_frame_json(seq, 10, small, sizeof small) == 0 && small[0] == '\0',
          "frame 10's JSON: not refused");

    thz_scene *bad = NULL;
    CHECK(thz_sequence_frame_scene(seq, 10, &bad, &err) == THZ_ERR_INPUT && bad == NULL,
          "frame 10's scene: not refused");

    /* a batch's and a sequence load's failures stay in the context, as every call that
     * takes one keeps its last failure (docs/api.md; they were not recorded) */
    thz_context *ctx = thz_context_create();
    CHECK(thz_batch_run(ctx, seq, path, NULL, NULL, NULL) == THZ_ERR_INPUT &&
              thz_context_last_status(ctx) == THZ_ERR_INPUT &&
              strstr(thz_context_last_message(ctx), "not a directory"),
          "a batch into a file: context says %d '%s'", (int)thz_context_last_status(ctx),
          thz_context_last_message(ctx));
    thz_sequence *missing = NULL;
    CHECK(thz_sequence_load_ctx(ctx, "/nonexistent/sequence.json", NULL, &missing, NULL) ==
                  THZ_ERR_INPUT &&
              strstr(thz_context_last_message(ctx), "/nonexistent/sequence.json"),
          "a missing sequence: context says '%s'", thz_context_last_message(ctx));
    thz_context_destroy(ctx);
    thz_sequence_destroy(seq);

    /* a material the scene lacks, misspelt in a keyframe or a sweep: refused with its
     * path (it made a new material that no object uses: the value changed nothing) */
    static const char *const misspelt[][2] = {
        {"{\"format\": \"thzmap-sequence/1\", \"scene\": \"scene.json\", \"fps\": 2,\n"
         " \"keyframes\": [{\"time_s\": 0, \"materials\": {\"wal\": {\"reflectivity\": 0.5}}}]}\n",
         "keyframes[0].materials.wal: the scene has no material named \"wal\""},
        {"{\"format\": \"thzmap-sequence/1\", \"scene\": \"scene.json\",\n"
         " \"sweep\": {\"materials.wal.reflectivity\": [0.1, 0.5]}}\n",
         "sweep.materials.wal.reflectivity: the scene has no material named \"wal\""}};
    for (size_t i = 0; i < sizeof misspelt / sizeof misspelt[0]; i++) {
        snprintf(path, sizeof path, "%s/misspelt-%zu.json", dir, i);
        test_write_file(path, misspelt[i][0]);
        thz_sequence *m = NULL;
        thz_error merr = {0};
        CHECK(thz_sequence_load(path, &m, &merr) == THZ_ERR_INPUT && m == NULL &&
                  strstr(merr.message, misspelt[i][1]),
              "misspelt material %zu: status %d '%s'", i, (int)merr.status, merr.message);
        thz_sequence_destroy(m);
    }

    /* keyframe times strictly increasing: two at the same time are refused, naming the
     * later one (accepted, the segment between them had length 0) */
    snprintf(path, sizeof path, "%s/same-time.json", dir);
    test_write_file(path,
                    "{\"format\": \"thzmap-sequence/1\", \"scene\": \"scene.json\", \"fps\": 2,\n"
                    " \"keyframes\": [{\"time_s\": 1, \"objects\": {\"plate\": {\"temperature_k\": "
                    "300}}},\n  {\"time_s\": 1, \"objects\": {\"plate\": {\"temperature_k\": "
                    "310}}}]}\n");
    thz_sequence *same = NULL;
    thz_error serr = {0};
    CHECK(thz_sequence_load(path, &same, &serr) == THZ_ERR_INPUT && same == NULL &&
              strstr(serr.message,
                     "keyframes[1].time_s: expected keyframe times in increasing order"),
          "keyframes at the same time: status %d '%s'", (int)serr.status, serr.message);
    thz_sequence_destroy(same);

    /* a sweep of two keys runs every combination, the first key varying slowest: sweep s
     * has the plate at 300 + 10 (s / 3) K (the sweep's values of the other key, 3, vary
     * fastest; every key indexed by s alone passed the other tests) */
    snprintf(path, sizeof path, "%s/two-keys.json", dir);
    test_write_file(path, "{\"format\": \"thzmap-sequence/1\", \"scene\": \"scene.json\",\n"
                          " \"sweep\": {\"objects.plate.temperature_k\": [300, 310],\n"
                          "  \"atmosphere.attenuation_per_m\": [0.01, 0.1, 0.2]}}\n");
    thz_sequence *two = NULL;
    REQUIRE_OK(thz_sequence_load(path, &two, &err), &err);
    CHECK(thz_sequence_frame_count(two) == 6, "two keys of 2 and 3 values: %zu frames",
          thz_sequence_frame_count(two));
    for (size_t i = 0; i < 6 && i < thz_sequence_frame_count(two); i++) {
        double x, width, t_k;
        plate_in_frame(two, i, &x, &width, &t_k);
        char json[4096];
        thz_sequence_frame_json(two, i, json, sizeof json);
        static const double att[3] = {0.01, 0.1, 0.2};
        const char *a = strstr(json, "\"attenuation_per_m\":");
        double got = a ? strtod(a + strlen("\"attenuation_per_m\":"), NULL) : NAN;
        CHECK(t_k == 300.0 + 10.0 * (double)(i / 3) && got == att[i % 3],
              "sweep %zu: the plate at %g K, attenuation %g per m; expected %g K, %g per m", i, t_k,
              got, 300.0 + 10.0 * (double)(i / 3), att[i % 3]);
    }
    thz_sequence_destroy(two);

    /* a frame's input hash covers the files its scene names under any "*_file" key: a
     * channel's response_file changed under the same name changes the hash, so that a
     * resumed batch redoes the frame (only "file" was hashed in a helper's mutant, and
     * every test passed: a resumed batch kept frames of the old response) */
    snprintf(path, sizeof path, "%s/resp.csv", dir);
    test_write_file(path, "frequency_thz,weight\n0.58,0\n0.60,1\n0.62,0\n");
    snprintf(path, sizeof path, "%s/resp-scene.json", dir);
    test_write_file(
        path, "{\"format\": \"thzmap-scene/1\", \"name\": \"resp\",\n"
              " \"channels\": [{\"frequency_thz\": 0.6, \"response_file\": \"resp.csv\"}],\n"
              " \"materials\": {\"wall\": {\"reflectivity\": 0.2}},\n"
              " \"objects\": [{\"name\": \"room\", \"type\": \"solid\", \"material\": \"wall\",\n"
              "   \"temperature_k\": 295, \"shape\": {\"type\": \"box\", \"size_m\": [4, 4, 4],\n"
              "   \"inward\": true}}],\n"
              " \"sensors\": [{\"name\": \"cam\", \"position_m\": [0, -1.5, 0], \"look_at_m\": [0, "
              "0, 0],\n   \"fov_deg\": 60, \"resolution\": [8, 6]}]}\n");
    snprintf(path, sizeof path, "%s/resp-seq.json", dir);
    test_write_file(path, "{\"format\": \"thzmap-sequence/1\", \"scene\": \"resp-scene.json\"}\n");
    uint64_t resp_hash[3] = {0, 0, 0};
    for (int k = 0; k < 3; k++) {
        if (k == 2) { /* the same name, another response */
            char csv[4200];
            snprintf(csv, sizeof csv, "%s/resp.csv", dir);
            test_write_file(csv, "frequency_thz,weight\n0.59,0\n0.61,1\n0.63,0\n");
        }
        thz_sequence *r = NULL;
        thz_frame_info ri = {0};
        REQUIRE_OK(thz_sequence_load(path, &r, &err), &err);
        REQUIRE_OK(thz_sequence_frame(r, 0, &ri), &err);
        resp_hash[k] = ri.hash;
        thz_sequence_destroy(r);
    }
    CHECK(resp_hash[0] == resp_hash[1] && resp_hash[1] != resp_hash[2],
          "input hashes %016llx, %016llx (the same file), %016llx (its content changed)",
          (unsigned long long)resp_hash[0], (unsigned long long)resp_hash[1],
          (unsigned long long)resp_hash[2]);

    /* sweep directories sort in order: sweep-00 .. sweep-99, sweep-000 .. sweep-100 (the
     * batch writes where these say: test_batch.sh) */
    sweep_dirs(dir, 100, "sweep-00/frame-00000", "sweep-99/frame-00000");
    sweep_dirs(dir, 101, "sweep-000/frame-00000", "sweep-100/frame-00000");

    return test_finish(argv[0], dir);
}
