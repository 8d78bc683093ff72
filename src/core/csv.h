/* The one reader of numeric CSV tables: those scenes refer to (material properties,
 * atmospheric attenuation) and the line catalogues and tables of data/atmosphere/. Lines starting
 * with `#` (after optional blanks) and blank lines are comments, the first other line is a header
 * of column names, every further line a row of numbers, one per column, separated by commas. Errors
 * name the file and its line, the row and the column.
 */
#ifndef THZ_CORE_CSV_H
#define THZ_CORE_CSV_H

#include <stddef.h>

#include "core/error.h"

typedef struct csv_table {
    char *label; /* the file name as used in messages */
    size_t n_columns;
    char **names; /* n_columns header names, blanks trimmed */
    size_t n_rows;
    double *values;    /* n_rows * n_columns, row-major; all finite */
    size_t *row_lines; /* n_rows: the 1-based line of each row in the file */
} csv_table;

/* Reads the file at path; `label` (NULL: path) names it in messages. On error the
 * table is left empty (csv_fini is still safe). THZ_ERR_INPUT when the file cannot
 * be read or its content is bad (both are the user's input), THZ_ERR_NOMEM. */
thz_status csv_read(const char *path, const char *label, csv_table *table, thz_error *err);

/* The same from text held in memory. */
thz_status csv_parse(const char *text, const char *label, csv_table *table, thz_error *err);

/* Index of the column named `name`, or -1. */
long csv_column(const csv_table *table, const char *name);

/* The same as a status: THZ_ERR_INPUT naming the table when there is no such column
 * (err may be NULL). */
thz_status csv_column_index(const csv_table *table, const char *name, size_t *column,
                            thz_error *err);

/* Value of column `column` in row `row` (both 0-based, in range). */
double csv_value(const csv_table *table, size_t row, size_t column);

void csv_fini(csv_table *table);

#endif
