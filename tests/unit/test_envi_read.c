/* ENVI reader (envi_read_float32, behind thz_cube_read and classify) on headers thzmap
 * does not write: what api.md and analysis.h say it reads (float32, band-sequential,
 * either byte order) it reads, and a header that describes anything else, or disagrees
 * with its data, is refused naming the file (and the line) instead of read as a wrong
 * picture. Every refusal below was accepted by a mutant of the reader that passed every
 * other test (session 55's mutation review). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <malloc.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/alloc.h"
#include "io/envi.h"

static char dir[512];

static int setup(void **state)
{
    (void)state;
    const char *base = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/thz-test-envi-read-XXXXXX", base && *base ? base : "/tmp");
    return mkdtemp(dir) ? 0 : -1;
}

static int teardown(void **state)
{
    (void)state;
    char path[1024];
    snprintf(path, sizeof path, "%s/o.hdr", dir);
    unlink(path);
    snprintf(path, sizeof path, "%s/o.img", dir);
    unlink(path);
    return rmdir(dir);
}

/* Writes dir/o.hdr (the text, as given) and dir/o.img (n little-endian floats 1, 2, ...). */
static void write_pair(const char *hdr, size_t hdr_bytes, size_t n)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/o.hdr", dir);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(hdr, 1, hdr_bytes, f), hdr_bytes);
    fclose(f);
    snprintf(path, sizeof path, "%s/o.img", dir);
    f = fopen(path, "wb");
    assert_non_null(f);
    for (size_t i = 0; i < n; i++) {
        float x = (float)(i + 1);
        uint32_t w;
        memcpy(&w, &x, 4);
        for (int k = 0; k < 4; k++)
            fputc((int)(w >> (8 * k)) & 0xff, f);
    }
    fclose(f);
}

/* The header text with n floats of data must be refused as bad input whose message holds
 * `want` (and names the header or the data file). */
static void expect_refused(const char *hdr, size_t n, const char *want)
{
    write_pair(hdr, strlen(hdr), n);
    envi_cube c;
    thz_error err = {0};
    thz_status st = envi_read_float32(dir, "o", &c, &err);
    if (st == THZ_OK)
        fail_msg("accepted (%u x %u x %zu), expected a refusal with '%s':\n%s", c.samples, c.lines,
                 c.bands, want, hdr);
    assert_int_equal(st, THZ_ERR_INPUT);
    if (!strstr(err.message, want) || !strstr(err.message, "/o."))
        fail_msg("message '%s' lacks '%s' or the file's name", err.message, want);
    assert_null(c.data);
}

/* What the header says, read: a 3 x 2 x 2 cube. */
static void expect_read(const char *hdr, size_t hdr_bytes, envi_cube *c)
{
    write_pair(hdr, hdr_bytes, 12);
    thz_error err = {0};
    thz_status st = envi_read_float32(dir, "o", c, &err);
    if (st != THZ_OK)
        fail_msg("refused: %s\n%s", err.message, hdr);
    assert_int_equal(c->samples, 3);
    assert_int_equal(c->lines, 2);
    assert_int_equal(c->bands, 2);
    for (size_t i = 0; i < 12; i++)
        assert_true(c->data[i] == (float)(i + 1));
}

#define DIMS "samples = 3\nlines = 2\nbands = 2\n"

/* Headers of other programs: any key order, keys and interleave in capitals, a list over
 * several lines (as ENVI writes a long wavelength list), comments, CRLF line ends. */
static void test_reads_foreign_layouts(void **state)
{
    (void)state;
    envi_cube c;
    const char *text = "ENVI\r\n; written by another program\r\nData Type = 4\r\n"
                       "wavelength units = GHz\r\nwavelength = {\r\n 200.5,\r\n 1234.5678 }\r\n"
                       "Interleave = BSQ\r\nBANDS = 2\r\nlines = 2\r\nSamples = 3\r\n";
    expect_read(text, strlen(text), &c);
    assert_non_null(c.wavelength);
    assert_true(c.wavelength[0] == 200.5 && c.wavelength[1] == 1234.5678);
    assert_string_equal(c.wavelength_units, "GHz");
    envi_cube_fini(&c);
    /* one band: every interleave is the same layout */
    const char *one = "ENVI\nsamples = 3\nlines = 2\nbands = 1\ndata type = 4\ninterleave = bil\n";
    write_pair(one, strlen(one), 6);
    thz_error err = {0};
    assert_int_equal(envi_read_float32(dir, "o", &c, &err), THZ_OK);
    assert_true(c.data[5] == 6.0f);
    envi_cube_fini(&c);
}

/* What the reader does not read: other value types, interleaves, byte orders. */
static void test_refuses_other_layouts(void **state)
{
    (void)state;
    /* int32 values (data type 3): as many bytes as float32, but other numbers */
    expect_refused("ENVI\nsamples = 3\nlines = 2\nbands = 1\ndata type = 3\n", 6,
                   "data type 3; only 4 (float32) is read");
    expect_refused("ENVI\n" DIMS "data type = 4\ninterleave = bil\n", 12,
                   "interleave bil; only bsq is read");
    expect_refused("ENVI\n" DIMS "data type = 4\ninterleave = bip\n", 12,
                   "interleave bip; only bsq is read");
    expect_refused("ENVI\n" DIMS "data type = 4\nbyte order = 2\n", 12,
                   "byte order: expected a whole number up to 1, got '2'");
    expect_refused("ENVI\n" DIMS "data type = 4\nbyte order = 1x\n", 12,
                   "byte order: expected a whole number up to 1, got '1x'");
    expect_refused("ENVI\nsamples = 3.5\nlines = 2\nbands = 2\ndata type = 4\n", 12,
                   "o.hdr:2: samples: expected a whole number");
}

/* A header that is not one, lacks a key, or disagrees with its own data. */
static void test_refuses_inconsistent(void **state)
{
    (void)state;
    expect_refused("ENVIRONMENT\n" DIMS "data type = 4\n", 12, "not an ENVI header");
    expect_refused("ENVI\n" DIMS, 12, "no 'data type' key");
    expect_refused("ENVI\nsamples = 3\nlines = 2\ndata type = 4\n", 6, "no 'bands' key");
    expect_refused("ENVI\nsamples = 3\nlines = 2\nbands = 0\ndata type = 4\n", 0,
                   "an image of no pixels");
    /* the data a value longer or shorter than the header's 3 x 2 x 2 */
    expect_refused("ENVI\n" DIMS "data type = 4\n", 13, "52 bytes, but its header says 3 x 2 x 2");
    expect_refused("ENVI\n" DIMS "data type = 4\n", 11, "44 bytes, but its header says 3 x 2 x 2");
    /* three wavelengths for two bands, the list starting on line 6 and spanning two */
    expect_refused("ENVI\n" DIMS "data type = 4\nwavelength = {1,\n 2, 3}\n", 12,
                   "o.hdr:6: 3 wavelengths for 2 bands");
    expect_refused("ENVI\n" DIMS "data type = 4\nwavelength = {1,\n 2}\nbands = x\n", 12,
                   "o.hdr:8: bands: expected a whole number");
    expect_refused("ENVI\n" DIMS "data type = 4\nwavelength = {1, 2 GHz}\n", 12,
                   "o.hdr:6: wavelength 2: not a number");
    expect_refused("ENVI\n" DIMS "data type = 4\nwavelength = {1, 2\n", 12,
                   "o.hdr:6: unclosed '{'");
    const char nul[] = "ENVI\n" DIMS "data type = 4\n\0junk\n";
    write_pair(nul, sizeof nul - 1, 12);
    envi_cube c;
    thz_error err = {0};
    assert_int_equal(envi_read_float32(dir, "o", &c, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "holds a NUL byte"));
}

/* The heap's bytes in use (glibc; 0 under ASan, whose leak check covers the test there). */
static size_t heap_in_use(void)
{
    return mallinfo2().uordblks;
}

/* A key given twice: the last value counts, and nothing of the first stays allocated (a
 * second `object names` list leaked the first; the fuzzer found it). */
static void test_repeated_keys(void **state)
{
    (void)state;
    const char *text = "ENVI\n" DIMS "data type = 4\nobject names = {room, person}\n"
                       "wavelength = {1, 2}\nwavelength units = GHz\nobject names = {a, b, c}\n"
                       "wavelength units = THz\nwavelength = {3, 4}\n";
    envi_cube c;
    expect_read(text, strlen(text), &c); /* the files are written before the count */
    envi_cube_fini(&c);
    size_t before = heap_in_use();
    expect_read(text, strlen(text), &c);
    assert_int_equal(c.n_object_names, 3);
    assert_string_equal(c.object_names[0], "a");
    assert_string_equal(c.object_names[2], "c");
    assert_true(c.wavelength[0] == 3.0 && c.wavelength[1] == 4.0);
    assert_string_equal(c.wavelength_units, "THz");
    envi_cube_fini(&c);
    assert_int_equal(heap_in_use(), before);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reads_foreign_layouts),
        cmocka_unit_test(test_refuses_other_layouts),
        cmocka_unit_test(test_refuses_inconsistent),
        cmocka_unit_test(test_repeated_keys),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
