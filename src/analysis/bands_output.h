/* What `thzmap bands` writes (scene-format.md "thzmap bands"): bands.json and the
 * figures bands-score.png (the best set's worst-pair JM against K), bands-spectra.png
 * (each class's mean brightness temperature against the candidates) and, where the air
 * attenuates, bands-air.png (its attenuation with the chosen bands shaded).
 */
#ifndef THZ_ANALYSIS_BANDS_OUTPUT_H
#define THZ_ANALYSIS_BANDS_OUTPUT_H

#include "analysis/bands_search.h"
#include "analysis/bands_values.h"

typedef struct bands_report {
    const char *scene_path, *scene_name, *sensor;
    const bands_setup *setup;
    double from_thz, to_thz, step_ghz;
    const bands_values *values;
    const bands_search_result *search;
    const double *air_db_per_km; /* per candidate, or NULL (no attenuating air) */
    const char *netd_source;     /* where the NETD came from, e.g. "--netd-k" */
    const double *width_list;    /* the n_widths relative widths searched, ascending; the
                                    candidates are centre-major (c = centre * n_widths + w) */
    size_t n_widths;
    double noise_b;      /* the worst pair's B from the render's Monte Carlo noise alone */
    const char *warning; /* NULL, or the worst pair cannot be told apart */
} bands_report;

/* bands.json's text (malloc'd), NULL with err set when out of memory. */
char *bands_json(const bands_report *rep, thz_error *err);

/* Every file bands_write_files may write (some only for some scenes): an output
 * directory's claims (io/output.h output_stage_claim). */
#define BANDS_OUTPUT_FILES 4
extern const char *const bands_output_files[BANDS_OUTPUT_FILES];

/* Writes bands.json (json_text) and the figures into dir. */
thz_status bands_write_files(const char *dir, const bands_report *rep, const char *json_text,
                             thz_error *err);

#endif
