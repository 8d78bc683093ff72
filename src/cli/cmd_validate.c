/* thzmap validate SCENE.json: loads and checks a scene, prints what it holds (its
 * channels, materials, objects with their geometry, sensors, and the emitted spectral
 * power per channel) and its warnings. Exit 0 when the scene is valid, 2 when not.
 * thzmap validate SEQUENCE.json: the same for a sequence's frames. */
#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "frame_warnings.h"
#include "progress.h"
#include "thzmap/thzmap.h"

static void validate_usage(FILE *f)
{
    fprintf(f, "usage: thzmap validate SCENE.json\n"
               "       thzmap validate SEQUENCE.json\n\n"
               "Loads the scene, checks it completely (exit 0 when valid, 2 when not, naming\n"
               "the file and the line:column or JSON path of the problem) and prints its\n"
               "channels, materials, objects (triangles, area, temperature), sensors and the\n"
               "surfaces' emitted spectral power per channel (P_A without the air's\n"
               "emission, which a run adds: summary.json); for sensors with optics or\n"
               "noise, each channel's NETD (K) and diffraction spot (mrad, and its size at\n"
               "the nearest and farthest object centre). Warnings (emissivity breaking\n"
               "Kirchhoff's law, channel bands leaving a material table, inconsistent mesh\n"
               "winding) go to standard error as \"thzmap validate: warning: ...\", as every\n"
               "command prints them.\n\n"
               "Given a sequence file (\"thzmap-sequence/1\", which `thzmap batch` runs), it\n"
               "checks the sequence and every frame's scene, prints the number of frames and\n"
               "the first frame's scene as above, and each frame's warnings once, naming the\n"
               "first frame that has it by its directory (frame-00001: ...) and then how\n"
               "many later frames repeat it.\n\n"
               "options:\n"
               "  -h, --help   show this help\n");
}

/* The atmosphere's line: its model, the air's state (itu-p676, lines) and what the air
 * emits at, which defaults to the temperature of the enclosure around the sensors. */
static void validate_print_atmosphere(const thz_scene *s, const char *model)
{
    printf("\natmosphere: %s", model);
    thz_atm *atm = NULL;
    thz_atm_info ai = {0};
    if (thz_atm_from_scene(s, &atm, NULL) == THZ_OK)
        thz_atm_get_info(atm, &ai);
    thz_atm_destroy(atm);
    if (ai.has_air)
        printf("; air at %.2f K and %.2f hPa, water vapour %.4g hPa (%.4g g/m³)", ai.temperature_k,
               ai.pressure_hpa, ai.h2o_pressure_hpa, ai.h2o_density_g_m3);
    if (ai.emitting)
        printf("; emitting at %.2f K, background %.2f K", ai.emission_temperature_k,
               ai.background_temperature_k);
    else if (strcmp(model, "none") != 0)
        printf("; not emitting");
    printf("\n");
}

/* "0.05", or "table (3 points, 0.2 to 1.2 THz; 0.05 to 0.12)". */
static void validate_describe_spectrum(char *out, size_t n, const thz_spectrum_info *sp)
{
    if (sp->kind == THZ_SPECTRUM_ABSENT)
        snprintf(out, n, "-");
    else if (sp->kind == THZ_SPECTRUM_CONSTANT)
        snprintf(out, n, "%g", sp->value);
    else
        snprintf(out, n, "table (%zu points, %g to %g THz; %g to %g)", sp->n_points, sp->from_thz,
                 sp->to_thz, sp->min_value, sp->max_value);
}

/* The nearest and farthest distance (m) from point p to the centres of the objects'
 * bounding boxes, leaving out boxes that hold p (the enclosure around a sensor); false
 * when no object is left. */
static bool validate_object_distances(const thz_scene *s, const double p[3], double *near_m,
                                      double *far_m)
{
    bool any = false;
    for (size_t i = 0; i < thz_scene_object_count(s); i++) {
        thz_object_info o;
        thz_scene_object(s, i, &o);
        bool inside = true;
        double d2 = 0.0;
        for (int k = 0; k < 3; k++) {
            inside = inside && p[k] >= o.bbox_min_m[k] && p[k] <= o.bbox_max_m[k];
            double d = 0.5 * (o.bbox_min_m[k] + o.bbox_max_m[k]) - p[k];
            d2 += d * d;
        }
        if (inside)
            continue;
        double d = sqrt(d2);
        *near_m = any && *near_m < d ? *near_m : d;
        *far_m = any && *far_m > d ? *far_m : d;
        any = true;
    }
    return any;
}

/* "12.3 mm" or "4.56 cm" or "1.2 m": a length in the unit that reads best. */
static void validate_length(char *out, size_t n, double m)
{
    if (m < 0.01)
        snprintf(out, n, "%.3g mm", m * 1e3);
    else if (m < 1.0)
        snprintf(out, n, "%.3g cm", m * 1e2);
    else
        snprintf(out, n, "%.3g m", m);
}

/* Sensor i's optics and noise per channel: NETD and the diffraction spot. */
static void validate_print_sensor_model(const thz_scene *s, size_t i, const double position_m[3])
{
    thz_sensor_channel_info m;
    thz_scene_sensor_channel(s, i, 0, &m);
    if (strcmp(m.psf, "none") == 0 && strcmp(m.noise, "none") == 0)
        return;
    double near_m = 0.0, far_m = 0.0;
    bool dist = validate_object_distances(s, position_m, &near_m, &far_m);
    printf("      psf %s", m.psf);
    if (m.aperture_diameter_m > 0.0)
        printf(", aperture diameter D %g m", m.aperture_diameter_m);
    printf("; noise %s", m.noise);
    if (strcmp(m.noise, "none") != 0) {
        if (m.noise_seed_given)
            printf(", noise seed %llu", (unsigned long long)m.noise_seed);
        else
            printf(", noise seed the run's");
    }
    printf("\n");
    for (size_t c = 0; c < thz_scene_channel_count(s); c++) {
        thz_channel_info ch;
        thz_scene_channel(s, c, &ch);
        thz_scene_sensor_channel(s, i, c, &m);
        printf("      %-16s", ch.name);
        if (m.netd_k > 0.0) {
            printf(" NETD %.4g K", m.netd_k);
            if (m.netd_at_k > 0.0)
                printf(" at Tb %.5g K (B_n %.4g GHz)", m.netd_at_k, m.noise_bandwidth_hz * 1e-9);
        }
        if (m.spot_rad > 0.0) {
            printf("%s %s %.4g mrad", m.netd_k > 0.0 ? ";" : "",
                   strcmp(m.psf, "airy") == 0 ? "spot 1.22 lambda/D" : "PSF FWHM",
                   m.spot_rad * 1e3);
            /* the width an angle spans at a distance, 2 d tan(angle / 2): distance x angle
             * said 6.37 m at 2.147 m for a FWHM of 170 deg; from 90 deg on a width at a
             * distance says little of a spot that wide (at 180 deg it is infinite) */
            if (dist && m.spot_rad < M_PI / 2.0) {
                char a[32], b[32];
                validate_length(a, sizeof a, 2.0 * near_m * tan(m.spot_rad / 2.0));
                validate_length(b, sizeof b, 2.0 * far_m * tan(m.spot_rad / 2.0));
                printf(" = %s at %.4g m, %s at %.4g m (nearest and farthest object centre)", a,
                       near_m, b, far_m);
            }
        }
        printf("\n");
    }
}

static void validate_print(const thz_scene *s)
{
    thz_scene_info si;
    thz_scene_get_info(s, &si);
    printf("scene \"%s\" (%s): valid\n", si.name, si.path);
    printf("\nchannels: %zu\n", si.n_channels);
    for (size_t c = 0; c < si.n_channels; c++) {
        thz_channel_info ch;
        thz_scene_channel(s, c, &ch);
        char response[64];
        if (ch.response_points)
            snprintf(response, sizeof response, "measured response (%zu points)",
                     ch.response_points);
        else
            snprintf(response, sizeof response, "Gaussian");
        printf("  [%zu] %-16s centre %.4f THz  FWHM %.3f GHz  bandwidth B_c %.3f GHz  noise "
               "bandwidth B_n %.3f GHz  %s\n",
               c, ch.name, ch.frequency_hz * 1e-12, ch.fwhm_hz * 1e-9, ch.bandwidth_hz * 1e-9,
               ch.noise_bandwidth_hz * 1e-9, response);
    }
    printf("\nmaterials: %zu\n", si.n_materials);
    for (size_t m = 0; m < si.n_materials; m++) {
        thz_material_info mat;
        thz_scene_material(s, m, &mat);
        char r[160], a[160], e[160];
        validate_describe_spectrum(r, sizeof r, &mat.reflectivity);
        validate_describe_spectrum(a, sizeof a, &mat.attenuation_per_m);
        if (mat.emissivity.kind == THZ_SPECTRUM_ABSENT)
            snprintf(e, sizeof e, "Kirchhoff");
        else
            validate_describe_spectrum(e, sizeof e, &mat.emissivity);
        if (mat.index_model && mat.reflectivity.kind == THZ_SPECTRUM_ABSENT)
            snprintf(r, sizeof r, "Fresnel of the index");
        if (mat.index_model && mat.attenuation_per_m.kind == THZ_SPECTRUM_ABSENT)
            snprintf(a, sizeof a, "4 pi k nu / c of the index");
        else
            strncat(a, " 1/m", sizeof a - strlen(a) - 1);
        printf("  %s: reflectivity %s; attenuation %s; emissivity %s; transmission %s", mat.name, r,
               a, e, mat.transmission);
        if (mat.index_model)
            printf("; complex index %s", mat.index_model);
        if (strcmp(mat.reflection, "ward") == 0)
            printf("; reflection ward (alpha_x %g, alpha_y %g)", mat.ward_alpha_x,
                   mat.ward_alpha_y);
        else
            printf("; reflection %s", mat.reflection);
        printf("\n");
    }
    validate_print_atmosphere(s, si.atmosphere_model);
    printf("\nobjects: %zu\n", si.n_objects);
    double total_area = 0.0;
    size_t total_triangles = 0;
    for (size_t i = 0; i < si.n_objects; i++) {
        thz_object_info o;
        thz_scene_object(s, i, &o);
        total_area += o.area_m2;
        total_triangles += o.triangles;
        char kind[64];
        if (strcmp(o.type, "shell") == 0)
            snprintf(kind, sizeof kind, "shell %g mm", o.thickness_m * 1e3);
        else
            snprintf(kind, sizeof kind, "%s", o.two_sided ? "solid two-sided" : "solid");
        /* the vertices are floats: a coordinate below their resolution at the object's
         * extent is rounding (a rotated screen's bottom at 2.384e-08 m), shown as 0 */
        double b[6], extent = 0.0;
        for (int a = 0; a < 3; a++) {
            b[a] = o.bbox_min_m[a];
            b[3 + a] = o.bbox_max_m[a];
        }
        for (int k = 0; k < 6; k++)
            extent = fmax(extent, fabs(b[k]));
        for (int k = 0; k < 6; k++)
            if (fabs(b[k]) < 4.0 * FLT_EPSILON * extent)
                b[k] = 0.0;
        printf("  [%zu] %s: %s, material %s, %zu triangles, area %.6g m², temperature %.2f K, "
               "bounds [%.4g, %.4g, %.4g] to [%.4g, %.4g, %.4g] m\n",
               i, o.name, kind, o.material_name, o.triangles, o.area_m2, o.temperature_k, b[0],
               b[1], b[2], b[3], b[4], b[5]);
    }
    printf("  total: %zu triangles, area %.6g m²\n", total_triangles, total_area);
    printf("\nsensors: %zu\n", si.n_sensors);
    for (size_t i = 0; i < si.n_sensors; i++) {
        thz_sensor_info sn;
        thz_scene_sensor(s, i, &sn);
        printf("  [%zu] %s: %u x %u pixels, fov %g deg, oversampling %u x %u, aperture %g m², "
               "at [%g, %g, %g] m looking along [%.4f, %.4f, %.4f], T_ref %g K\n",
               i, sn.name, sn.columns, sn.rows, sn.fov_deg, sn.oversampling, sn.oversampling,
               sn.aperture_m2, sn.position_m[0], sn.position_m[1], sn.position_m[2],
               sn.direction[0], sn.direction[1], sn.direction[2], sn.normalize_to_k);
        validate_print_sensor_model(s, i, sn.position_m);
    }
    printf("\nphotons: %llu per channel, seed %llu, min_relative_power %g, gather_min_photons %u\n",
           (unsigned long long)si.photons_per_channel, (unsigned long long)si.seed,
           si.min_relative_power, si.gather_min_photons);
    printf("render: integrator %s, gather_rays %u, paths_per_sample %u\n", si.integrator,
           si.gather_rays, si.paths_per_sample);
    thz_scene_fingerprint fp;
    if (thz_scene_get_fingerprint(s, &fp) == THZ_OK)
        printf("fingerprint: geometry %016llx, optics %016llx, channels %016llx, run %016llx "
               "(summary.json's scene.fingerprint; run as the scene's own settings give it)\n",
               (unsigned long long)fp.geometry, (unsigned long long)fp.optics,
               (unsigned long long)fp.channels, (unsigned long long)fp.run);
    printf("\nemitted spectral power of the surfaces (band mean P_A; a run's photon phase "
           "also fires the air's own emission, in summary.json's energy_balance):\n");
    for (size_t c = 0; c < si.n_channels; c++) {
        thz_channel_info ch;
        thz_scene_channel(s, c, &ch);
        printf("  %-16s %.6e W/Hz\n", ch.name, ch.emitted_power_w_per_hz);
    }
}

/* thzmap validate SEQUENCE.json: the sequence loads (so does every frame's scene); its
 * frames, the first frame's scene as a scene's, and every frame's warnings, each printed
 * once with its first frame and then the number of later frames that repeat it, as
 * `thzmap batch` prints them. */
typedef struct validate_count {
    cli_count_line line;
    const char *what;
    bool line_open; /* on the terminal, without its newline */
} validate_count;

static void validate_count_show(validate_count *v, uint64_t done, uint64_t total)
{
    if (cli_count_line_show(&v->line, "validate", v->what, done, total))
        v->line_open = v->line.tty;
}

static void validate_count_end(validate_count *v)
{
    if (v->line_open)
        fputs("\r\033[K", stderr);
    v->line_open = false;
}

static int validate_on_load_progress(void *user, const thz_progress *p)
{
    validate_count_show(user, p->done, p->total);
    return 0;
}

static int validate_sequence(const char *path)
{
    thz_sequence *seq = NULL;
    thz_error err = {0};
    /* a long sequence's two passes over its frames (the load checks each one's scene,
     * then each is loaded again for its warnings) are counted as `thzmap batch` counts */
    bool tty = isatty(STDERR_FILENO) != 0;
    validate_count count = {.what = "the frames' scenes"};
    cli_count_line_start(&count.line, tty);
    thz_context *ctx = thz_context_create();
    if (!ctx) {
        fprintf(stderr, "thzmap validate: out of memory\n");
        return CLI_EXIT_FAILURE;
    }
    thz_context_set_progress(ctx, validate_on_load_progress, &count);
    thz_status st = thz_sequence_load_ctx(ctx, path, NULL, &seq, &err);
    thz_context_destroy(ctx);
    validate_count_end(&count);
    if (st != THZ_OK)
        return cli_fail(&err);
    size_t n = thz_sequence_frame_count(seq), per = thz_sequence_frames_per_sweep(seq);
    thz_frame_info last;
    thz_sequence_frame(seq, per - 1, &last);
    printf("sequence (%s): valid\n", path);
    printf("frames: %zu (%zu sweep value%s x %zu frame%s, t = 0 to %g s)\n", n,
           thz_sequence_sweep_count(seq), thz_sequence_sweep_count(seq) == 1 ? "" : "s", per,
           per == 1 ? "" : "s", last.time_s);
    fflush(stdout);
    cli_frame_warnings warnings = {0};
    int rc = CLI_EXIT_OK;
    count.what = "the frames' warnings";
    cli_count_line_start(&count.line, tty);
    for (size_t f = 0; f < n && rc == CLI_EXIT_OK; f++) {
        validate_count_show(&count, f, n);
        thz_scene *scene = NULL;
        st = thz_sequence_frame_scene(seq, f, &scene, &err);
        if (st != THZ_OK) {
            validate_count_end(&count); /* each line to come starts on its own */
            rc = cli_fail(&err);
            break;
        }
        if (f == 0) {
            validate_count_end(&count);
            thz_frame_info fi;
            thz_sequence_frame(seq, 0, &fi);
            printf("\nthe first frame's scene (%s):\n\n", fi.dir);
            validate_print(scene);
            fflush(stdout);
        }
        for (size_t i = 0; i < thz_scene_warning_count(scene); i++) {
            const char *w = thz_scene_warning(scene, i);
            thz_frame_info fi;
            if (!cli_frame_warnings_first(&warnings, f, w))
                continue;
            validate_count_end(&count);
            fprintf(stderr, "thzmap validate: warning: %s: %s\n",
                    thz_sequence_frame(seq, f, &fi) == THZ_OK ? fi.dir : "?", w);
        }
        thz_scene_destroy(scene);
    }
    validate_count_end(&count);
    cli_frame_warnings_finish(&warnings, "validate", NULL, rc == CLI_EXIT_OK);
    thz_sequence_destroy(seq);
    return rc;
}

int cmd_validate(int argc, char **argv)
{
    const char *path = NULL;
    for (int i = 1; i < argc; i++) {
        if (cli_is_help(argv[i])) {
            validate_usage(stdout);
            return CLI_EXIT_OK;
        }
        if (argv[i][0] == '-' && argv[i][1] != '\0')
            return cli_usage_error("validate", "unknown option '%s'", argv[i]);
        if (path)
            return cli_usage_error("validate", "expected one scene file, got '%s' and '%s'", path,
                                   argv[i]);
        path = argv[i];
    }
    if (!path)
        return cli_usage_error("validate", "expected a scene file (thzmap validate SCENE.json)");
    thz_scene *scene = NULL;
    thz_error err = {0};
    thz_file_kind kind = THZ_FILE_OTHER;
    if (thz_file_identify(path, &kind, &err) != THZ_OK)
        return cli_fail(&err);
    if (kind == THZ_FILE_SEQUENCE)
        return validate_sequence(path);
    if (thz_scene_load(path, &scene, &err) != THZ_OK)
        return cli_fail(&err);
    validate_print(scene);
    fflush(stdout);
    for (size_t i = 0; i < thz_scene_warning_count(scene); i++)
        fprintf(stderr, "thzmap validate: warning: %s\n", thz_scene_warning(scene, i));
    thz_scene_destroy(scene);
    return CLI_EXIT_OK;
}
