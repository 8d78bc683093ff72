/* thzmap public API: scenes (include thzmap/thzmap.h, which includes this).
 *
 * A thz_scene is a loaded and completely checked thzmap-scene/1 document: channels,
 * materials, atmosphere, objects (triangle meshes), sensors and run settings. It is
 * read-only once loaded, so concurrent runs may share it. Indices are 0-based in the
 * order of the scene file; info structs are filled by value, their strings belong to
 * the scene.
 */
#include "thzmap/thzmap.h" /* every part, in order: this one among them */

#ifndef THZMAP_SCENE_H
#define THZMAP_SCENE_H

#ifdef __cplusplus
extern "C" {
#endif

typedef struct thz_scene thz_scene;

/* Loads and checks a scene file. On success *out owns the scene (thz_scene_destroy);
 * errors name the file and line:column or JSON path (THZ_ERR_INPUT). Checked also is what
 * a run would refuse of the scene before its work: sensors whose images would not fit in
 * memory (sensors[i].resolution), and PSFs too much wider than the image to fold onto it
 * (sensors[i].psf_fwhm_deg or .aperture_diameter_m). */
THZ_API thz_status thz_scene_load(const char *path, thz_scene **out, thz_error *err);
/* The same from JSON text. `base_dir` resolves the relative file paths in it (NULL:
 * the current directory); `label` names the text in messages as a file name would
 * (NULL: "<string>"). */
THZ_API thz_status thz_scene_load_string(const char *json_text, const char *base_dir,
                                         const char *label, thz_scene **out, thz_error *err);
/* Both confined to the directory `root` (NULL: not confined, as above), for a program
 * that loads scenes on behalf of others (thzmap serve --root): every file the scene names
 * (meshes, CSV tables, channel responses, line catalogues), and the scene file itself,
 * must lie under root once symlinks are resolved, and is opened by that resolved path.
 * A named file that is absolute, lies outside, or does not exist is refused with
 * THZ_ERR_INPUT at the JSON path of the key naming it, in words that quote nothing of
 * any file. Built-in data (the material library, the ITU tables) is not confined. */
THZ_API thz_status thz_scene_load_within(const char *path, const char *root, thz_scene **out,
                                         thz_error *err);
THZ_API thz_status thz_scene_load_string_within(const char *json_text, const char *base_dir,
                                                const char *label, const char *root,
                                                thz_scene **out, thz_error *err);
THZ_API void thz_scene_destroy(thz_scene *scene);

/* The kinds of file thzmap reads, as thz_file_identify tells them apart. */
typedef enum thz_file_kind {
    THZ_FILE_OTHER = 0,     /* none of these: not JSON, or JSON of another format */
    THZ_FILE_SCENE = 1,     /* a JSON object whose "format" is "thzmap-scene/1" or "/1.1" */
    THZ_FILE_SEQUENCE = 2,  /* "format": "thzmap-sequence/1" (thzmap/batch.h) */
    THZ_FILE_PHOTON_MAP = 3 /* a photon-map file (thz_photons_save), by its first bytes */
} thz_file_kind;

/* What kind of thzmap file `path` is, for a program that takes any of them (thzmap
 * validate does): a photon-map file by its magic, a scene or sequence by the "format" of
 * its JSON object. It tells, it does not check: the loader says whether the file is valid.
 * THZ_OK with THZ_FILE_OTHER for any other file (also one that is not JSON, or JSON larger
 * than a scene may be); THZ_ERR_INPUT when path is not a regular file (a directory, a FIFO,
 * missing) or cannot be read; THZ_ERR_NOMEM. */
THZ_API thz_status thz_file_identify(const char *path, thz_file_kind *out, thz_error *err);

/* The scene as a whole and its run settings (the `photons` and `render` blocks). */
typedef struct thz_scene_info {
    const char *name;
    const char *path;             /* the file as given, or the label of a string */
    const char *atmosphere_model; /* "none", "constant", "table", "itu-p676", "lines" */
    size_t n_channels, n_materials, n_objects, n_sensors, n_warnings;
    uint64_t photons_per_channel;
    uint64_t seed;
    double min_relative_power;
    uint32_t gather_min_photons;
    const char *integrator; /* "photon-map", "final-gather", "path" */
    uint32_t gather_rays;
    uint32_t paths_per_sample;
} thz_scene_info;

typedef struct thz_channel_info {
    const char *name;
    double frequency_hz;           /* centre */
    double frequency_thz;          /* centre, as in the scene file */
    double relative_width;         /* FWHM / centre of the Gaussian; 0 for a measured response */
    double bandwidth_hz;           /* B_c: the response's integral (physics.md) */
    double emitted_power_w_per_hz; /* band mean of the surfaces' emitted power (P_A without
                                      the air's, which thz_photons_stats adds) */
    /* (added with measured responses. The library fills the whole struct: a program built
     * against an older header must be rebuilt; the ABI is not stable before 1.0) */
    double noise_bandwidth_hz; /* B_n = (int g)^2 / int g^2 */
    double fwhm_hz;            /* full width at half maximum of the response */
    size_t response_points;    /* points of the measured response table; 0: Gaussian */
} thz_channel_info;

/* A spectral property of a material: absent, a constant, or a table. */
typedef enum thz_spectrum_kind {
    THZ_SPECTRUM_ABSENT = 0,
    THZ_SPECTRUM_CONSTANT,
    THZ_SPECTRUM_TABLE
} thz_spectrum_kind;

typedef struct thz_spectrum_info {
    thz_spectrum_kind kind;
    size_t n_points;             /* table: its points; constant: 1 */
    double value;                /* constant: the value */
    double from_thz, to_thz;     /* table: first and last frequency */
    double min_value, max_value; /* table: range of its values */
} thz_spectrum_info;

typedef struct thz_material_info {
    const char *name;
    thz_spectrum_info reflectivity;
    thz_spectrum_info attenuation_per_m;
    thz_spectrum_info emissivity; /* ABSENT: Kirchhoff's law */
    const char *transmission;     /* "diffuse" or "straight" */
    double color[3];              /* rgb 0..1 of the visual truth image */
    /* The complex index (refractive_index, permittivity_model or library): NULL when
     * none, else "constant", "table", "debye", "double-debye", "lorentz", "drude" or
     * "itu-p2040". Absent reflectivity and attenuation then come from it. */
    const char *index_model;
    /* (added with reflection lobes; as above, a program built earlier must be rebuilt) */
    const char *reflection; /* the `reflection` key: "diffuse", "specular" or "ward" */
    double ward_alpha_x;    /* Ward's slopes (0 < alpha <= 1) along each triangle's first edge */
    double ward_alpha_y;    /* (x) and across it (y); both 0 unless reflection is "ward" */
} thz_material_info;

typedef struct thz_object_info {
    const char *name;
    const char *type;   /* "solid" or "shell" */
    int two_sided;      /* the `two_sided` key (solids) */
    double thickness_m; /* shells; 0 for solids */
    size_t material;    /* index of its material */
    const char *material_name;
    double temperature_k;
    size_t triangles;
    double area_m2;
    double bbox_min_m[3], bbox_max_m[3]; /* the float vertices' box, each as its shortest
                                          * decimal (0.6, not 0.6000000238418579) */
} thz_object_info;

typedef struct thz_sensor_info {
    const char *name;
    uint32_t columns, rows;
    size_t channels; /* bands of its cubes: the scene's channels */
    double fov_deg;  /* horizontal */
    uint32_t oversampling;
    double aperture_m2;
    double position_m[3];
    double direction[3]; /* unit viewing direction */
    double up[3];
    double normalize_to_k;
} thz_sensor_info;

/* A sensor's optics and noise in one channel (scene-format.md "Sensors: optics and
 * noise"). */
typedef struct thz_sensor_channel_info {
    const char *psf;            /* "airy", "gaussian" or "none" */
    double aperture_diameter_m; /* D, m; 0 when not given */
    double spot_rad;            /* airy: 1.22 lambda_c / D, the first dark ring's angular radius;
                                   gaussian: its FWHM; none: 0 (rad) */
    const char *noise;          /* "netd", "total-power", "dicke" or "none" */
    double netd_k;              /* the given NETD, or the radiometer's at netd_at_k; 0: none */
    double netd_at_k;           /* the Tb netd_k holds for: the channel's reference temperature
                                   (radiometer; NETD varies with each pixel's Tb), K */
    double noise_bandwidth_hz;  /* B_n of the channel, Hz */
    int noise_seed_given;       /* else the noise takes the run's seed */
    uint64_t noise_seed;
} thz_sensor_channel_info;

/* Fill *out; THZ_ERR_INPUT (and *out zeroed) when an index is out of range. */
THZ_API thz_status thz_scene_get_info(const thz_scene *scene, thz_scene_info *out);
THZ_API thz_status thz_scene_channel(const thz_scene *scene, size_t i, thz_channel_info *out);
THZ_API thz_status thz_scene_material(const thz_scene *scene, size_t i, thz_material_info *out);
THZ_API thz_status thz_scene_object(const thz_scene *scene, size_t i, thz_object_info *out);
THZ_API thz_status thz_scene_sensor(const thz_scene *scene, size_t i, thz_sensor_info *out);
THZ_API thz_status thz_scene_sensor_channel(const thz_scene *scene, size_t sensor, size_t channel,
                                            thz_sensor_channel_info *out);

THZ_API size_t thz_scene_channel_count(const thz_scene *scene);
THZ_API size_t thz_scene_object_count(const thz_scene *scene);
THZ_API size_t thz_scene_sensor_count(const thz_scene *scene);

/* The index of the sensor (object) called `name`, or -1 when there is none. */
THZ_API long thz_scene_sensor_index(const thz_scene *scene, const char *name);
THZ_API long thz_scene_object_index(const thz_scene *scene, const char *name);

/* What identifies the scene as loaded (summary.json's scene.fingerprint): 64-bit hashes
 * of its geometry (meshes bit for bit), its optics (materials as evaluated, temperatures,
 * atmosphere), its channels, and `run`: those with the sensors and the photon and render
 * settings but for the photon count and seed. Names and colours do not count. */
typedef struct thz_scene_fingerprint {
    uint64_t geometry, optics, channels, run;
} thz_scene_fingerprint;
THZ_API thz_status thz_scene_get_fingerprint(const thz_scene *scene, thz_scene_fingerprint *out);

/* The scene's validation warnings (emissivity breaking Kirchhoff's law, bands leaving
 * a table, mesh winding): count, and warning i (NULL when out of range). */
THZ_API size_t thz_scene_warning_count(const thz_scene *scene);
THZ_API const char *thz_scene_warning(const thz_scene *scene, size_t i);

/* An object's triangles in world space (transforms applied), in metres: n_vertices
 * vertices of 3 floats (x, y, z) in `positions`, n_triangles triangles of 3 vertex
 * indices in `indices`, counter-clockwise seen from the front, and one unit front normal
 * of 3 floats per triangle in `normals`. The arrays belong to the scene. */
typedef struct thz_object_mesh {
    size_t n_vertices;
    const float *positions;
    size_t n_triangles;
    const uint32_t *indices;
    const float *normals;
} thz_object_mesh;
/* Fills *out for object i; THZ_ERR_INPUT (and *out zeroed) when i is out of range. */
THZ_API thz_status thz_scene_object_mesh(const thz_scene *scene, size_t i, thz_object_mesh *out);

/* A material's optics at one frequency, as the simulation uses them (physics.md
 * "Surfaces"), for a half-space (thickness_m 0) or a slab of thickness_m (a shell). */
typedef struct thz_surface_optics {
    double reflectance_normal; /* R at normal incidence */
    double reflectance_mean;   /* hemispherical mean R-bar */
    double emissivity_normal;  /* eps at normal incidence (explicit, or Kirchhoff's A) */
    double emissivity_mean;    /* eps-bar */
    double transmission_mean;  /* T-bar; 0 for a half-space */
    double attenuation_per_m;  /* inside the material: alpha_M, or 4 pi k nu / c */
    int has_index;             /* n and k below hold the complex index */
    double n, k;
} thz_surface_optics;
/* Fills *out for material i at freq_hz > 0; THZ_ERR_INPUT (and *out zeroed) when i is
 * out of range, freq_hz is not positive and finite or thickness_m is negative or
 * infinite. */
THZ_API thz_status thz_scene_material_optics(const thz_scene *scene, size_t i, double freq_hz,
                                             double thickness_m, thz_surface_optics *out);

/* Planck's law B_nu(T) in W m^-2 sr^-1 Hz^-1 and its inverse, the brightness temperature
 * in K of a radiance at freq_hz (0 for radiance <= 0), as the images use them; NaN when
 * an argument is NaN (thz_brightness_temperature_stderr too). */
THZ_API double thz_planck_radiance(double freq_hz, double temperature_k);
THZ_API double thz_brightness_temperature(double freq_hz, double radiance);
/* The standard error in K of a brightness temperature tb_k from its radiance's standard
 * error stderr_l (W m^-2 sr^-1 Hz^-1) at freq_hz: stderr_l / (dB/dT at tb_k), as the
 * noise figures of summary.json convert it (0 when tb_k <= 0). */
THZ_API double thz_brightness_temperature_stderr(double freq_hz, double tb_k, double stderr_l);

/* Integrators by name ("photon-map", "final-gather", "path"): 1 when `name` is one,
 * else 0; whether it needs a photon map (photon-map, final-gather); whether more
 * render passes lower its noise (final-gather, path). 0 for unknown names. */
THZ_API int thz_integrator_known(const char *name);
THZ_API int thz_integrator_needs_photons(const char *name);
THZ_API int thz_integrator_has_passes(const char *name);

#ifdef __cplusplus
}
#endif
#endif
