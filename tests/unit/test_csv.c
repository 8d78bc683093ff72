/* The CSV reader: comments, blank lines, CRLF and blanks around fields; rows in
 * order with their file lines; and errors that name the file, line, row and column. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include "core/csv.h"
#include "core/error.h"

#define INPUTS THZ_SOURCE_DIR "/tests/inputs/csv/"

static void test_good_file(void **state)
{
    (void)state;
    csv_table t;
    thz_error err = {0};
    assert_int_equal(csv_read(INPUTS "good.csv", "good.csv", &t, &err), THZ_OK);
    assert_int_equal(t.n_columns, 2);
    assert_string_equal(t.names[0], "frequency_thz");
    assert_string_equal(t.names[1], "reflectivity");
    assert_int_equal(csv_column(&t, "reflectivity"), 1);
    assert_int_equal(csv_column(&t, "emissivity"), -1);
    assert_int_equal(t.n_rows, 3);
    assert_true(csv_value(&t, 0, 0) == 0.2 && csv_value(&t, 0, 1) == 0.1);
    assert_true(csv_value(&t, 2, 0) == 1.0 && csv_value(&t, 2, 1) == 0.35);
    assert_int_equal(t.row_lines[0], 5);
    assert_int_equal(t.row_lines[2], 8);
    csv_fini(&t);
    csv_fini(&t); /* idempotent */
}

static void expect_error(const char *file, const char *substrings[])
{
    char path[512];
    snprintf(path, sizeof path, INPUTS "%s", file);
    csv_table t;
    thz_error err = {0};
    assert_int_equal(csv_read(path, file, &t, &err), THZ_ERR_INPUT);
    for (size_t i = 0; substrings[i]; i++) {
        if (!strstr(err.message, substrings[i]))
            fail_msg("message '%s' lacks '%s'", err.message, substrings[i]);
    }
    assert_int_equal(t.n_rows, 0);
    assert_null(t.names);
    csv_fini(&t);
}

static void test_errors(void **state)
{
    (void)state;
    expect_error("bad_number.csv",
                 (const char *[]){"bad_number.csv:3:", "row 2", "'reflectivity'", "'abc'", NULL});
    expect_error("bad_fields.csv",
                 (const char *[]){"bad_fields.csv:3:", "row 2", "1 fields", NULL});
    expect_error("empty.csv", (const char *[]){"empty.csv", "no header", NULL});
    expect_error("header_only.csv", (const char *[]){"header_only.csv", "no data rows", NULL});
    expect_error("missing.csv", (const char *[]){"missing.csv", "cannot open", NULL});
}

/* A FIFO given as a material or atmosphere table is refused before it is opened (the
 * open would block for ever). */
static void test_fifo_refused(void **state)
{
    (void)state;
    char dir[] = "/tmp/thz-test-csv-XXXXXX";
    assert_non_null(mkdtemp(dir));
    char path[64];
    snprintf(path, sizeof path, "%s/table.csv", dir);
    assert_int_equal(mkfifo(path, 0600), 0);
    csv_table t;
    thz_error err = {0};
    assert_int_equal(csv_read(path, "materials.cloth.file", &t, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "materials.cloth.file"));
    assert_non_null(strstr(err.message, "FIFO"));
    unlink(path);
    rmdir(dir);
}

static void test_parse_text(void **state)
{
    (void)state;
    csv_table t;
    thz_error err = {0};
    assert_int_equal(csv_parse("a,b,c\n1,2,3\n4,5,6", "mem", &t, &err), THZ_OK);
    assert_int_equal(t.n_rows, 2);
    assert_true(csv_value(&t, 1, 2) == 6.0);
    csv_fini(&t);
    assert_int_equal(csv_parse("a,b\n1,nan\n", "mem", &t, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "mem:2:"));
    assert_int_equal(csv_parse("a,b\n1,1e999\n", "mem", &t, &err), THZ_ERR_INPUT);
    assert_int_equal(csv_parse("a,b\n1,1e-400\n", "mem", &t, &err), THZ_OK); /* underflow: 0 */
    csv_fini(&t);
    assert_int_equal(csv_parse("a,a\n1,2\n", "mem", &t, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "twice"));
    assert_int_equal(csv_parse("a,\n1,2\n", "mem", &t, &err), THZ_ERR_INPUT);
    assert_int_equal(csv_parse("1,2\n1,2\n", "mem", &t, &err), THZ_ERR_INPUT);
    assert_non_null(strstr(err.message, "header"));
    assert_int_equal(csv_parse("a\n1,\n", "mem", &t, &err), THZ_ERR_INPUT);
}

/* A refused cell is quoted in the message; bytes that are no UTF-8 text, and control
 * bytes (an escape sequence for the terminal), come out as \xNN, valid UTF-8 as it is.
 * Raw, they reached the terminal, and the GUI server's JSON reply (which jansson refuses
 * to build from invalid UTF-8) said "out of memory" instead of the message. */
static void test_bytes_escaped(void **state)
{
    (void)state;
    csv_table t;
    thz_error err = {0};
    assert_int_equal(csv_parse("a,b\n1,\xff\xfe\x1b[31m\xe2\x82\n", "mem", &t, &err),
                     THZ_ERR_INPUT);
    if (!strstr(err.message, "got '\\xff\\xfe\\x1b[31m\\xe2\\x82'"))
        fail_msg("message '%s'", err.message);
    assert_int_equal(csv_parse("a,b\n1,2\xc2\xb5m\n", "mem", &t, &err), THZ_ERR_INPUT);
    if (!strstr(err.message, "got '2\xc2\xb5m'")) /* 2 micro m */
        fail_msg("message '%s'", err.message);
    thz_error long_err = {0}; /* escapes that overflow the message stop at a character */
    char cell[2000];
    memset(cell, 0xff, sizeof cell - 1);
    cell[sizeof cell - 1] = '\0';
    thz_error_set(&long_err, THZ_ERR_INPUT, "%s", cell);
    size_t n = strlen(long_err.message);
    assert_true(n <= sizeof long_err.message - 1 && n >= sizeof long_err.message - 4);
    assert_int_equal(n % 4, 0);
    assert_memory_equal(long_err.message + n - 4, "\\xff", 4);
}

/* What spreadsheets write: a UTF-8 byte-order mark (before the header, or before a comment
 * that precedes it) and fields in double quotes. The mark was part of the first name and
 * the quotes of every name: "the header names no column 'frequency_thz'". */
static void test_spreadsheet_csv(void **state)
{
    (void)state;
    /* the mark EF BB BF in octal: a hex escape would run on into the "f" after it */
    const char *texts[] = {"\357\273\277frequency_thz,n\r\n0.2,2\r\n",
                           "\357\273\277# made by hand\nfrequency_thz,n\n0.2,2\n",
                           "\"frequency_thz\",\"n\"\n\"0.2\", 2\n"};
    for (size_t i = 0; i < 3; i++) {
        csv_table t;
        thz_error err = {0};
        if (csv_parse(texts[i], "mem", &t, &err) != THZ_OK)
            fail_msg("text %zu: %s", i, err.message);
        assert_int_equal(csv_column(&t, "frequency_thz"), 0);
        assert_int_equal(csv_column(&t, "n"), 1);
        assert_true(t.n_rows == 1 && csv_value(&t, 0, 0) == 0.2 && csv_value(&t, 0, 1) == 2.0);
        csv_fini(&t);
    }
    csv_table t;
    thz_error err = {0};
    assert_int_equal(csv_parse("\"a\"b\",n\n1,2\n", "mem", &t, &err), THZ_OK); /* kept whole */
    assert_int_equal(csv_column(&t, "\"a\"b\""), 0);
    csv_fini(&t);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_good_file),    cmocka_unit_test(test_errors),
        cmocka_unit_test(test_parse_text),   cmocka_unit_test(test_spreadsheet_csv),
        cmocka_unit_test(test_fifo_refused), cmocka_unit_test(test_bytes_escaped),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
