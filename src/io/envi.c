/* ENVI writer: raw little-endian BSQ data plus a text header. */
#include "io/envi.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/c_locale.h"
#include "core/path.h"
#include "thzmap/thzmap.h"

/* Values converted per fwrite: bounds the stack buffer, keeps writes large. */
enum { ENVI_CHUNK = 4096 };

/* "dir/stem.ext" into buf (THZ_PATH_MAX bytes). */
static thz_status envi_path(char *buf, const char *dir, const char *stem, const char *ext,
                            thz_error *err)
{
    char name[THZ_PATH_MAX];
    int n = snprintf(name, sizeof name, "%s.%s", stem, ext);
    if (n < 0 || (size_t)n >= sizeof name)
        return thz_error_set(err, THZ_ERR_INPUT,
                             "file name longer than the limit of %zu bytes: %s.%s", sizeof name - 1,
                             stem, ext);
    return thz_path_join(buf, THZ_PATH_MAX, dir, name, err);
}

/* Writes s with the characters that end ENVI values or lists replaced. */
static void envi_put_text(FILE *f, const char *s)
{
    for (; *s; s++) {
        char c = *s;
        if (c == '{' || c == '}' || c == '\n' || c == '\r')
            c = ' ';
        else if (c == ',')
            c = ';';
        fputc(c, f);
    }
}

static void envi_put_name_list(FILE *f, const char *key, const char *const *names, size_t n)
{
    fprintf(f, "%s = {", key);
    for (size_t i = 0; i < n; i++) {
        if (i)
            fputs(", ", f);
        envi_put_text(f, names[i] ? names[i] : "");
    }
    fputs("}\n", f);
}

static void envi_put_number_list(FILE *f, const char *key, const double *v, size_t n)
{
    fprintf(f, "%s = {", key);
    for (size_t i = 0; i < n; i++)
        fprintf(f, "%s%.10g", i ? ", " : "", v[i]);
    fputs("}\n", f);
}

static thz_status envi_write_header(const char *dir, const char *stem, const envi_info *info,
                                    thz_error *err)
{
    char path[THZ_PATH_MAX];
    thz_status status = envi_path(path, dir, stem, "hdr", err);
    if (status != THZ_OK)
        return status;
    FILE *f = fopen(path, "w");
    if (!f)
        return thz_error_set(err, thz_errno_status(errno, THZ_ERR_IO), "%s: cannot create: %s",
                             path, strerror(errno));
    locale_t previous = thz_locale_enter(); /* "352.5", never "352,5" */
    fputs("ENVI\ndescription = {", f);
    envi_put_text(f, info->description ? info->description : "");
    fputs("}\n", f);
    fprintf(f, "samples = %u\nlines = %u\nbands = %zu\n", info->samples, info->lines, info->bands);
    fputs("header offset = 0\nfile type = ENVI Standard\ndata type = 4\n", f);
    fputs("interleave = bsq\nbyte order = 0\n", f);
    if (info->data_units) {
        fputs("data units = ", f);
        envi_put_text(f, info->data_units);
        fputc('\n', f);
    }
    if (info->has_ignore_value)
        fprintf(f, "data ignore value = %.10g\n", info->ignore_value);
    if (info->band_names)
        envi_put_name_list(f, "band names", info->band_names, info->bands);
    if (info->wavelength_ghz) {
        fputs("wavelength units = GHz\n", f);
        envi_put_number_list(f, "wavelength", info->wavelength_ghz, info->bands);
    }
    if (info->fwhm_ghz)
        envi_put_number_list(f, "fwhm", info->fwhm_ghz, info->bands);
    if (info->object_names)
        envi_put_name_list(f, "object names", info->object_names, info->n_object_names);
    thz_locale_leave(previous);
    int failed = ferror(f);
    if (fclose(f) != 0 || failed)
        return thz_error_set(err, THZ_ERR_IO, "%s: write failed: %s", path, strerror(errno));
    return THZ_OK;
}

/* Writes n floats, as their bit patterns, in little-endian byte order. */
static thz_status envi_write_words(const char *dir, const char *stem, const float *data, size_t n,
                                   thz_error *err)
{
    char path[THZ_PATH_MAX];
    thz_status status = envi_path(path, dir, stem, "img", err);
    if (status != THZ_OK)
        return status;
    FILE *f = fopen(path, "wb");
    if (!f)
        return thz_error_set(err, thz_errno_status(errno, THZ_ERR_IO), "%s: cannot create: %s",
                             path, strerror(errno));
    unsigned char buf[ENVI_CHUNK * 4];
    int failed = 0;
    for (size_t done = 0; done < n && !failed;) {
        size_t m = n - done < ENVI_CHUNK ? n - done : ENVI_CHUNK;
        for (size_t i = 0; i < m; i++) {
            uint32_t w;
            memcpy(&w, &data[done + i], 4);
            buf[4 * i + 0] = (unsigned char)(w & 0xffu);
            buf[4 * i + 1] = (unsigned char)((w >> 8) & 0xffu);
            buf[4 * i + 2] = (unsigned char)((w >> 16) & 0xffu);
            buf[4 * i + 3] = (unsigned char)((w >> 24) & 0xffu);
        }
        if (fwrite(buf, 4, m, f) != m)
            failed = 1;
        done += m;
    }
    failed |= ferror(f);
    if (fclose(f) != 0 || failed)
        return thz_error_set(err, THZ_ERR_IO, "%s: write failed: %s", path, strerror(errno));
    return THZ_OK;
}

thz_status envi_write_float32(const char *dir, const char *stem, const envi_info *info,
                              const float *data, thz_error *err)
{
    _Static_assert(sizeof(float) == 4, "ENVI data type 4 is IEEE single precision");
    size_t pixels = (size_t)info->samples * info->lines;
    if (info->bands && pixels > SIZE_MAX / 4 / info->bands)
        return thz_error_set(err, THZ_ERR_LIMIT, "%s/%s.img: image too large", dir, stem);
    thz_status status = envi_write_words(dir, stem, data, pixels * info->bands, err);
    if (status != THZ_OK)
        return status;
    return envi_write_header(dir, stem, info, err);
}
