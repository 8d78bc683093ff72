/* Fuzzes the numeric CSV reader (src/core/csv.c): the input is a file given to csv_read
 * and, when it holds no NUL byte, the same text given to csv_parse; both must agree,
 * and a table they accept must keep csv.h's promises (finite values, increasing lines).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/csv.h"
#include "fuzz.h"

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    return 0;
}

static void check_table(const csv_table *t)
{
    if (t->n_columns == 0 || !t->names)
        abort();
    for (size_t c = 0; c < t->n_columns; c++)
        if (!t->names[c] || csv_column(t, t->names[c]) < 0)
            abort();
    for (size_t r = 0; r < t->n_rows; r++) {
        if (r > 0 && t->row_lines[r] <= t->row_lines[r - 1])
            abort();
        for (size_t c = 0; c < t->n_columns; c++)
            if (!isfinite(csv_value(t, r, c)))
                abort();
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_temp_file("input.csv", data, size);
    csv_table file_table, text_table;
    thz_error err = {0};
    thz_status st = csv_read(path, "input.csv", &file_table, &err);
    if (st == THZ_OK)
        check_table(&file_table);
    else if (fuzz_report(err.message), !err.message[0])
        abort(); /* a refusal says why */
    if (!memchr(data, '\0', size)) {
        char *text = malloc(size + 1);
        memcpy(text, data, size);
        text[size] = '\0';
        thz_error err2 = {0};
        thz_status st2 = csv_parse(text, "input.csv", &text_table, &err2);
        if (st2 != st)
            abort();
        if (st2 == THZ_OK) {
            check_table(&text_table);
            if (text_table.n_rows != file_table.n_rows ||
                text_table.n_columns != file_table.n_columns)
                abort();
        }
        csv_fini(&text_table);
        free(text);
    }
    csv_fini(&file_table);
    return 0;
}
