/* The scene model: channels, materials, atmosphere, objects (triangle meshes in world
 * space), sensors and run settings, as loaded from a thzmap-scene/1 file
 * (scene-format.md). Every later stage reads the scene; none changes it after loading.
 */
#ifndef THZ_SCENE_SCENE_H
#define THZ_SCENE_SCENE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "atmosphere/atmosphere.h"
#include "core/error.h"
#include "physics/brdf.h"
#include "physics/channel.h"
#include "physics/material_index.h"
#include "physics/optics.h"
#include "physics/spectrum.h"

typedef enum thz_transmission { TRANSMISSION_DIFFUSE = 0, TRANSMISSION_STRAIGHT } thz_transmission;

/* The `reflection` key: Lambertian (default), mirror, or Ward's anisotropic lobe. */
typedef enum thz_reflection {
    REFLECTION_DIFFUSE = 0,
    REFLECTION_SPECULAR,
    REFLECTION_WARD
} thz_reflection;

typedef struct thz_material {
    char *name;
    thz_spectrum reflectivity;      /* R(nu), required */
    thz_spectrum attenuation_per_m; /* alpha_M(nu), default constant 0 */
    thz_spectrum emissivity;        /* explicit eps(nu); n == 0 means Kirchhoff */
    thz_transmission transmission;  /* shells: diffuse (default) or straight */
    material_index *index;          /* n + ik (refractive_index, permittivity_model or library);
                                       NULL: the R, alpha_M, eps tables alone */
    thz_reflection reflection;
    double ward_alpha[2];        /* Ward's alpha_x, alpha_y (REFLECTION_WARD) */
    brdf_ward_table *ward_table; /* Ward's albedo table (REFLECTION_WARD), owned */
    double color[3];             /* rgb 0..1 for the visual truth image */
} thz_material;

typedef enum thz_object_type { OBJECT_SOLID = 0, OBJECT_SHELL } thz_object_type;

/* A triangle mesh in world space. Triangle i has vertices indices[3i..3i+2], counter-
 * clockwise seen from its front side; normal[3i..3i+2] is the unit front normal
 * (outward for closed solids, inward for `box` with inward: true). */
typedef struct thz_mesh {
    size_t n_vertices;
    float *positions; /* 3 floats per vertex, plus 4 floats of padding (Embree reads 16 B) */
    size_t n_triangles;
    uint32_t *indices; /* 3 per triangle */
    float *normals;    /* 3 per triangle, unit */
    double *areas_m2;  /* 1 per triangle */
    double total_area_m2;
    double bbox_min_m[3], bbox_max_m[3];
} thz_mesh;

typedef struct thz_object {
    char *name;
    thz_object_type type;
    size_t material;      /* index into scene->materials */
    double temperature_k; /* >= 0 */
    double thickness_m;   /* shells: > 0; solids: 0 */
    bool two_sided;       /* the `two_sided` key; scene_object_two_sided is the rule */
    thz_mesh mesh;
} thz_object;

/* The sensor's optics and noise (scene-format.md "Sensors: optics and noise";
 * sensor/psf.h, sensor/noise.h). */
typedef enum thz_psf_kind { PSF_NONE = 0, PSF_AIRY, PSF_GAUSSIAN } thz_psf_kind;

typedef enum thz_noise_kind {
    NOISE_NONE = 0,
    NOISE_NETD,       /* netd_k given per channel */
    NOISE_RADIOMETER, /* the radiometer equation */
} thz_noise_kind;

typedef enum thz_radiometer { RADIOMETER_TOTAL_POWER = 0, RADIOMETER_DICKE } thz_radiometer;

typedef struct thz_sensor_noise {
    thz_noise_kind kind;
    double *netd_k;                /* NOISE_NETD: one per channel, K (owned) */
    double receiver_temperature_k; /* NOISE_RADIOMETER: T_rec >= 0, K */
    double integration_time_s;     /* NOISE_RADIOMETER: tau > 0, s */
    thz_radiometer radiometer;
} thz_sensor_noise;

/* A sensor's name begins the names of its output files (S.radiance.hdr, ...), where a
 * '/' becomes '_' (sensor_file_char). The loader refuses names longer than this, which
 * leaves room for the longest suffix within a file system's 255-byte file names, and two
 * sensors whose files would have the same names ("a/b" and "a_b"). */
#define SENSOR_NAME_MAX 200

static inline char sensor_file_char(char c)
{
    return c == '/' ? '_' : c;
}

typedef struct thz_sensor {
    char *name;
    double position_m[3];
    double direction[3]; /* unit viewing direction */
    double up[3];        /* unit, not parallel to direction (as given, not orthogonalised) */
    double fov_deg;      /* horizontal, 0 < fov < 180 */
    uint32_t columns, rows;
    double aperture_m2;
    uint32_t oversampling;      /* n: n x n samples per pixel */
    double normalize_to_k;      /* T_ref > 0 */
    double aperture_diameter_m; /* D of the circular aperture, m; 0: none given */
    thz_psf_kind psf;
    double psf_fwhm_deg; /* PSF_GAUSSIAN: FWHM of the Gaussian PSF, degrees */
    thz_sensor_noise noise;
    bool noise_seed_given; /* else the noise takes the run's seed */
    uint64_t noise_seed;
    bool misplaced; /* scene_checks found it inside a closed solid or outside the
                       enclosure (and warned): back faces it sees are not the
                       normals' fault */
} thz_sensor;

typedef struct thz_photon_settings {
    uint64_t per_channel;   /* K > 0 */
    bool per_channel_given; /* by the scene or the command line (else the default noise
                               target applies, run.h) */
    uint64_t seed;
    double min_relative_power;   /* 0 <= x < 1; 0: no power cut-off */
    uint32_t gather_min_photons; /* k >= 2 */
} thz_photon_settings;

typedef enum thz_integrator {
    INTEGRATOR_PHOTON_MAP = 0,
    INTEGRATOR_FINAL_GATHER,
    INTEGRATOR_PATH
} thz_integrator;

/* The integrators' names as in the scene file ("photon-map", "final-gather", "path"),
 * indexed by thz_integrator and ended by NULL: the one list of them. */
extern const char *const scene_integrator_names[];

typedef struct thz_render_settings {
    thz_integrator integrator;
    uint32_t gather_rays;      /* final-gather, default 32 */
    uint32_t paths_per_sample; /* path, default 16 */
    bool paths_per_sample_given;
    double target_noise_k; /* render.target_noise_k: p95 of the per-pixel standard error
                              of Tb_c to reach (K); 0: none given */
    double max_seconds;    /* render.max_seconds: time limit of the passes (s); 0: none */
} thz_render_settings;

struct thz_scene {
    char *path; /* the scene file as given */
    char *dir;  /* its directory: relative paths in the scene are relative to it */
    char *name;

    size_t n_channels;
    thz_channel *channels;
    size_t n_materials;
    thz_material *materials;
    thz_atmosphere atmosphere;
    size_t n_objects;
    thz_object *objects;
    size_t n_sensors;
    thz_sensor *sensors;
    thz_photon_settings photons;
    thz_render_settings render;

    size_t n_warnings;
    char **warnings; /* messages for validate and summary.json, one line each */

    /* What scene_hash.c keeps of the meshes' hash (owned; shallow copies share it, as
     * they share the meshes); NULL for a scene not made by scene_create: nothing kept. */
    struct scene_hash_memo *hash_memo;
};
typedef struct thz_scene thz_scene;

/* Loads a scene file (thzmap-scene/1) and checks it completely; = thz_scene_load. */
thz_status scene_load(const char *path, thz_scene **out, thz_error *err);

/* The same from JSON text: `base_dir` resolves relative file paths and `label` names
 * the text in messages (as a file name would). For tests and for the future GUI. */
thz_status scene_load_string(const char *json_text, const char *base_dir, const char *label,
                             thz_scene **out, thz_error *err);

/* Both with every file the scene names (and the scene file) confined to the directory
 * root (NULL: not confined); = thz_scene_load_within, thz_scene_load_string_within. */
thz_status scene_load_within(const char *path, const char *root, thz_scene **out, thz_error *err);
thz_status scene_load_string_within(const char *json_text, const char *base_dir, const char *label,
                                    const char *root, thz_scene **out, thz_error *err);

/* An empty scene with the spec's defaults; NULL on allocation failure. */
thz_scene *scene_create(void);
void scene_destroy(thz_scene *scene);

/* Appends a warning (printf format). Returns false only on allocation failure. */
bool scene_add_warning(thz_scene *scene, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* The optics of object `obj` at freq_hz: its material's R, alpha_M and explicit eps
 * evaluated there, and its thickness (0 for solids). */
optics_point scene_object_optics(const thz_scene *scene, const thz_object *obj, double freq_hz);

/* Whether scene_object_optics gives obj the same point at every frequency (its freq_hz
 * aside, which only an index reads): no index, and R, alpha_M and eps constants. Such an
 * object's optics can be evaluated once per phase or render. */
bool scene_object_optics_constant(const thz_scene *scene, const thz_object *obj);

/* The BRDF frame of triangle `tri` of `obj` seen from `side` (brdf.h): the normal on that
 * side, the tangent along the triangle's first edge v0 -> v1 (Ward's x axis), b = n x t. */
brdf_frame scene_triangle_frame(const thz_object *obj, uint32_t tri, int side);

/* The lobe of `obj`'s material at optics point o (borrowed; must outlive the lobe). */
void scene_object_lobe(const thz_scene *scene, const thz_object *obj, const optics_point *o,
                       brdf_lobe *lobe);

/* Whether both sides of `obj` are front sides (and emit): shells, and solids with
 * `two_sided`. */
bool scene_object_two_sided(const thz_object *obj);

/* Whether the side of `obj` a ray arrives on is a front side (physics.md): shells and
 * two-sided solids always; one-sided solids when cos(normal, -ray) > 0. */
bool scene_object_side_is_front(const thz_object *obj, int side);

/* Emitted spectral power P_A(freq_hz) = sum over emitting sides of pi eps-bar A B_nu(T)
 * in W/Hz (physics.md "Photon phase"). */
double scene_emitted_power_w_per_hz(const thz_scene *scene, double freq_hz);

/* Band mean of P_A over channel c, in W/Hz. */
double scene_band_emitted_power_w_per_hz(const thz_scene *scene, size_t channel);

/* The reference temperature T0 of channel c, K: the temperature of the object with the
 * largest area x sides x hemispherical emissivity at the channel centre (the walls of a
 * room); 0 without objects. The control variate B_nu(T0) of the `path` integrator, and
 * the T0 of final-gather's deviation photon map (photon_map.h). */
double scene_reference_temperature_k(const thz_scene *scene, size_t channel);

/* The frequencies in (lo_hz, hi_hz) where a spectrum that the renderers tabulate per
 * quadrature node may have a kink: the points of the spectral tables (R, alpha_M, eps,
 * a tabled complex index) of the materials the objects use and of a tabled atmosphere,
 * ascending and distinct, in *knots (malloc'd; NULL when there are none). */
thz_status scene_spectral_knots(const thz_scene *scene, double lo_hz, double hi_hz, double **knots,
                                size_t *n, thz_error *err);

/* An upper bound on scene_spectral_knots' count, without allocating. */
size_t scene_spectral_knots_bound(const thz_scene *scene, double lo_hz, double hi_hz);

/* Computes the mesh-derived data from positions and indices: allocates (replacing any
 * earlier) normals and areas_m2, and sets total_area_m2 and the bounding box.
 * Degenerate triangles keep area 0 and a zero normal. False on allocation failure. */
bool mesh_finalize(thz_mesh *mesh);
void mesh_fini(thz_mesh *mesh);

#endif
