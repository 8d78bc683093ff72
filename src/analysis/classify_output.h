/* The files `thzmap classify` writes (scene-format.md "thzmap classify"):
 * classification.json, S.class.hdr/.img (ENVI float32, the object index of each pixel's
 * class, -1 where nothing is hit) and S.class.png (a figure of the map: classes in the
 * colours the JSON lists, nothing hit in black, and a legend naming them).
 */
#ifndef THZ_ANALYSIS_CLASSIFY_OUTPUT_H
#define THZ_ANALYSIS_CLASSIFY_OUTPUT_H

#include "analysis/classify.h"

/* What the files say besides the result. */
typedef struct classify_report {
    const classify_result *result;
    const char *run_dir; /* or NULL */
    const char *sensor;  /* or NULL (file stem "cube") */
    const char *source;  /* the cube's file stem */
    classify_method method;
    uint64_t seed;
    double train_fraction, netd_k;
    uint32_t columns, rows;
    const char *const *class_names; /* n_classes */
    char *const *object_names;      /* the truth's `object names`, or NULL */
    size_t n_object_names;
} classify_report;

/* Class k's colour (sRGB) in rgb[k] for k < n_classes: a fixed qualitative palette for
 * the first 20, then hues generated far from every earlier colour, black and white;
 * every colour distinct, the same for the same count (classification.json's `color`
 * and S.class.png's). */
void classify_class_colours(size_t n_classes, unsigned char (*rgb)[3]);

/* classification.json's text (malloc'd), NULL with err set when out of memory. */
char *classify_json(const classify_report *rep, thz_error *err);

/* Writes the three files into dir. */
thz_status classify_write_files(const char *dir, const classify_report *rep, const char *json_text,
                                thz_error *err);

#endif
