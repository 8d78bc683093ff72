/* The `lines` model: line-by-line absorption of H2O and O2 from spectral line
 * catalogues, plus the MT_CKD water-vapour continuum and a dry-air collision-
 * induced continuum. docs/atmosphere.md explains the choices; in short:
 *
 *   alpha(nu) = sum_lines n S(T) F(nu) + alpha_MT_CKD(nu) + alpha_dry(nu)
 *
 * - S(T) = S296 Q(296)/Q(T) exp(E''(T-296)/(296 T)) (1-exp(-h nu0/kT))/(1-exp(-h nu0/k 296))
 *   with the TIPS 2021 partition sums Q (the HITRAN convention, as am 14.0 does);
 * - Lorentz half width gamma = (296/T)^n_air (gamma_air (P - p_self) + gamma_self p_self),
 *   pressure shift delta_air (P - p_self), Voigt where the Doppler width is not
 *   negligible against the Lorentz width (low pressure);
 * - shape: Van Vleck-Huber, F = (nu tanh(h nu/2kT)) / (nu0 tanh(h nu0/2kT)) *
 *   (1/pi) [f(nu - nu0) + f(nu + nu0)]. With the continuum on, H2O lines use
 *   f(d) = L(d) - L(750 GHz) for |d| < 750 GHz and 0 beyond, the shape MT_CKD is
 *   defined against (no double counting of the far wings); O2 lines keep full wings;
 * - O2 60 GHz band and 118.75 GHz line: first-order (Rosenkranz) line mixing with
 *   the second-order strength and shift corrections of Makarov et al. (2011):
 *   f = (gamma G + (nu - nu0') Y) / ((nu - nu0')^2 + gamma^2) + mirror term;
 * - MT_CKD 4.2 self and foreign continuum from its 10 cm^-1 table (Catmull-Rom);
 * - dry air (mostly N2-N2) collision-induced absorption: the P.676-13 eq. 8 term.
 *
 * Units inside: frequencies in GHz, pressures in hPa (= mbar), number densities in
 * cm^-3, S in cm^2 GHz (HITRAN cm/molecule times 29.9792458), alpha in 1/cm until
 * the end. Uncoupled O2 lines weaker than LINE_MIN_RELATIVE times the strongest
 * O2 line (at the air's temperature) are dropped (3069 of 9598 lines are kept);
 * this changes alpha by < 1e-7 relative at 1 GHz - 3 THz even in dry air.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "atmosphere/atm_catalog.h"
#include "atmosphere/atm_inputs.h"
#include "atmosphere/atm_internal.h"
#include "atmosphere/atm_lines_data.h"
#include "core/alloc.h"
#include "core/data_dir.h"
#include "core/file.h"
#include "core/path.h"

#define LINE_MIN_RELATIVE 1e-10
#define O2_DRY_AIR_VMR 0.20946          /* O2 fraction of dry air */
#define VOIGT_DOPPLER_RATIO 1e-3        /* Voigt when gamma_D > this times gamma_L */
#define H_OVER_K_K_PER_GHZ 0.0479924307 /* h / k in K/GHz (CODATA 2018) */
#define BOLTZMANN_HPA_CM3 1.380649e-19  /* k in hPa cm^3 / K: n[cm^-3] = p[hPa] / (k T) */
#define AMU_KG 1.66053906660e-27
#define MT_CKD_P_REF_HPA 1013.0
#define MT_CKD_T_REF_K 296.0

/* ---- Lines at the air's state ---------------------------------------------------- */

static double iso_mass_amu(int molecule, int iso)
{
    static const double h2o[] = {18.010565, 20.014811, 19.014780, 19.016740,
                                 21.020985, 20.020956, 20.022915};
    static const double o2[] = {31.989830, 33.994076, 32.994045};
    if (molecule == 1)
        return iso >= 1 && iso <= 7 ? h2o[iso - 1] : h2o[0];
    return iso >= 1 && iso <= 3 ? o2[iso - 1] : o2[0];
}

static int compare_lines(const void *a, const void *b)
{
    double x = ((const lbl_line *)a)->nu_ghz, y = ((const lbl_line *)b)->nu_ghz;
    return (x > y) - (x < y);
}

/* Converts the raw catalogue into lines at the state: strengths, widths, shifts and
 * mixing; drops the weak ones. p_self: the species' partial pressure, n: its number
 * density (cm^-3). Lines whose isotopologue has no partition sum are an error. */
static thz_status species_build(lbl_species *sp, const raw_catalog *cat, const partition_sums *q,
                                int molecule, lbl_shape shape, const atm_air_state *air,
                                double p_self, double n_cm3, const char *what,
                                const char *lines_path, const char *q_path, thz_error *err)
{
    double t = air->temperature_k, p = air->pressure_hpa;
    double tr = 296.0 / t;
    double kt_ghz = t / H_OVER_K_K_PER_GHZ;
    memset(sp, 0, sizeof *sp);
    sp->shape = shape;
    if (cat->n == 0)
        return THZ_OK;
    double *s_t = thz_malloc_array(cat->n, sizeof *s_t);
    sp->lines = thz_calloc(cat->n, sizeof *sp->lines);
    if (!s_t || !sp->lines) {
        free(s_t);
        free(sp->lines);
        sp->lines = NULL;
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory preparing the %s lines", what);
    }
    double s_max = 0.0;
    for (size_t i = 0; i < cat->n; i++) {
        const raw_line *l = &cat->lines[i];
        if (l->elower_k < 0.0) { /* am's flag: strength independent of T */
            s_t[i] = l->s296_cm2_ghz;
        } else {
            double q296 = atm_partition_sum(q, l->iso, 296.0), qt = atm_partition_sum(q, l->iso, t);
            if (!isfinite(q296) || !isfinite(qt)) {
                free(s_t);
                free(sp->lines);
                sp->lines = NULL;
                return thz_error_set(err, THZ_ERR_INPUT,
                                     "%s: %s lines: no partition sum for isotopologue %d at %g "
                                     "K in %s (it has %zu isotopologues); give a table that has "
                                     "it or remove those lines",
                                     lines_path, what, l->iso, t, q_path, q->n_iso);
            }
            double stim_t = -expm1(-l->nu0_ghz / kt_ghz);
            double stim_296 = -expm1(-l->nu0_ghz * H_OVER_K_K_PER_GHZ / 296.0);
            s_t[i] = l->s296_cm2_ghz * q296 / qt * exp(l->elower_k * (t - 296.0) / (296.0 * t)) *
                     stim_t / stim_296;
        }
        if (s_t[i] > s_max)
            s_max = s_t[i];
    }
    size_t n = 0;
    for (size_t i = 0; i < cat->n; i++) {
        const raw_line *l = &cat->lines[i];
        /* Only uncoupled O2 lines are thinned: every H2O line is kept (weak
         * low-frequency HDO lines carry ~1 % of alpha below 10 GHz, and the 750 GHz
         * cut-off bounds the cost anyway); coupled lines are few and include the
         * Debye pseudo-line, tiny in S. */
        if (shape == SHAPE_GROSS && (s_t[i] < LINE_MIN_RELATIVE * s_max || s_t[i] <= 0.0))
            continue;
        lbl_line *o = &sp->lines[n++];
        o->amp = n_cm3 * s_t[i] / M_PI;
        o->inv_vvh0 = 1.0 / (l->nu0_ghz * tanh(l->nu0_ghz / (2.0 * kt_ghz)));
        o->gamma_ghz = pow(tr, l->n_air) * (l->gamma_air * (p - p_self) + l->gamma_self * p_self);
        double m_kg = iso_mass_amu(molecule, l->iso) * AMU_KG;
        o->gamma_d_ghz = l->nu0_ghz / 299792458.0 * sqrt(2.0 * M_LN2 * 1.380649e-23 * t / m_kg);
        o->voigt = o->gamma_d_ghz > VOIGT_DOPPLER_RATIO * o->gamma_ghz;
        o->g = 1.0;
        if (shape == SHAPE_COUPLED) {
            /* Makarov et al. (2011) coefficients are per dry-air pressure */
            double pd = p - air->h2o_pressure_hpa;
            double r = l->tref_k / t;
            o->y = pd * (l->y0 + l->y1 * (r - 1.0)) * pow(r, l->yx);
            o->g = 1.0 + pd * pd * (l->g0 + l->g1 * (r - 1.0)) * pow(r, l->gx);
            o->nu_ghz = l->nu0_ghz + pd * pd * (l->d0 + l->d1 * (r - 1.0)) * pow(r, l->dx);
        } else {
            o->nu_ghz = l->nu0_ghz + l->delta_air * (p - p_self);
        }
        if (shape == SHAPE_VVH_CUTOFF)
            o->pedestal = lorentz(H2O_CUTOFF_GHZ, o->gamma_ghz);
    }
    free(s_t);
    sp->n = n;
    qsort(sp->lines, n, sizeof *sp->lines, compare_lines);
    return THZ_OK;
}

/* ---- MT_CKD -------------------------------------------------------------------- */

/* Catmull-Rom spline through the table at wavenumber nu (am interpolates the product
 * with the radiation term instead: docs/atmosphere.md gives the difference); NaN
 * at a NaN nu (which no comparison below would stop before the index). */
static double catmull_rom(const double *v, size_t n, double step, double nu)
{
    double x = nu / step;
    if (isnan(x))
        return NAN;
    if (x <= 0.0)
        return v[0];
    if (x >= (double)(n - 1))
        return v[n - 1];
    size_t i = (size_t)x;
    double u = x - (double)i;
    double p0 = v[i > 0 ? i - 1 : 0], p1 = v[i], p2 = v[i + 1], p3 = v[i + 2 < n ? i + 2 : n - 1];
    return 0.5 * (2.0 * p1 + (-p0 + p2) * u + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u * u +
                  (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * u * u * u);
}

/* MT_CKD: alpha [1/cm] = n_w nu tanh(hc nu / 2kT) [ (n_w/n_0) (296/T)^texp C_s
 * + (n_f/n_0) C_f ], nu in cm^-1, n_0 the number density at 1013 hPa and 296 K. */
static double continuum_per_cm(const atm_lines_data *d, double f_ghz)
{
    if (!d->continuum || d->n_h2o <= 0.0)
        return 0.0;
    double nu = f_ghz / ATM_GHZ_PER_CM1;
    double t = d->air.temperature_k;
    double rad = nu * tanh(ATM_HC_OVER_K_CM_K * nu / (2.0 * t));
    const atm_inputs *in = d->inputs;
    double cs = catmull_rom(in->c_self, in->n_cont, in->cont_step_cm1, nu);
    double cf = catmull_rom(in->c_foreign, in->n_cont, in->cont_step_cm1, nu);
    double tx = catmull_rom(in->self_texp, in->n_cont, in->cont_step_cm1, nu);
    return d->n_h2o * rad *
           (d->n_h2o / d->n_ref * pow(MT_CKD_T_REF_K / t, tx) * cs + d->n_foreign / d->n_ref * cf);
}

/* P.676-13 eq. 8, second term: pressure-induced absorption of dry air (mostly
 * N2-N2), alpha in 1/cm. p: dry-air pressure in hPa. */
static double dry_continuum_per_cm(const atm_lines_data *d, double f_ghz)
{
    double theta = 300.0 / d->air.temperature_k, p = d->dry_hpa;
    double n2 = f_ghz * p * theta * theta * 1.4e-12 * p * pow(theta, 1.5) /
                (1.0 + 1.9e-5 * pow(f_ghz, 1.5));
    return 0.1820 * f_ghz * n2 / ATM_NEPER_TO_DB * 1e-5; /* dB/km -> 1/cm */
}

double atm_lines_continua_per_cm(const atm_lines_data *d, double f_ghz)
{
    return continuum_per_cm(d, f_ghz) + dry_continuum_per_cm(d, f_ghz);
}

/* ---- Line sums ---------------------------------------------------------------- */

/* First index with nu_ghz >= f. */
static size_t lower_bound(const lbl_species *sp, double f)
{
    size_t lo = 0, hi = sp->n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (sp->lines[mid].nu_ghz < f)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* alpha of the species in 1/cm at f GHz; vvh = f tanh(h f / 2kT). */
static double species_sum(const lbl_species *sp, double f, double vvh)
{
    double sum = 0.0;
    size_t i0 = 0, i1 = sp->n;
    if (sp->shape == SHAPE_VVH_CUTOFF) {
        i0 = lower_bound(sp, f - H2O_CUTOFF_GHZ);
        i1 = lower_bound(sp, f + H2O_CUTOFF_GHZ);
    }
    for (size_t i = i0; i < i1; i++)
        sum += lbl_line_alpha(sp->shape, &sp->lines[i], f, vvh);
    return sum;
}

void atm_lines_parts(const atm_lines_data *d, double freq_hz, atm_alpha_parts *parts)
{
    double f = freq_hz * 1e-9;
    double vvh = lbl_vvh(d, f);
    memset(parts, 0, sizeof *parts);
    parts->h2o_lines_per_m = 100.0 * species_sum(&d->h2o, f, vvh);
    parts->o2_per_m = 100.0 * (species_sum(&d->o2, f, vvh) + species_sum(&d->o2_coupled, f, vvh));
    parts->h2o_continuum_per_m = 100.0 * continuum_per_cm(d, f);
    parts->dry_continuum_per_m = 100.0 * dry_continuum_per_cm(d, f);
}

void atm_lines_table_key(const atm_lines_data *d, atm_table_key *key)
{
    /* what atm_lines_create builds d from; the rest of d follows from these */
    unsigned char continuum = d->continuum;
    atm_table_key_add(key, &d->inputs->read_id, sizeof d->inputs->read_id);
    atm_table_key_add(key, &continuum, 1);
    atm_table_key_add(key, &d->air.temperature_k, sizeof(double));
    atm_table_key_add(key, &d->air.pressure_hpa, sizeof(double));
    atm_table_key_add(key, &d->air.h2o_pressure_hpa, sizeof(double));
}

double atm_lines_grid_step_hz(const atm_lines_data *d, double lo_hz, double hi_hz)
{
    const lbl_species *all[] = {&d->h2o, &d->o2, &d->o2_coupled};
    double lo = lo_hz * 1e-9, hi = hi_hz * 1e-9, step = INFINITY;
    for (size_t s = 0; s < 3; s++) {
        for (size_t i = 0; i < all[s]->n; i++) {
            const lbl_line *l = &all[s]->lines[i];
            /* Voigt HWHM (Olivero & Longbothum 1977) */
            double w = 0.5346 * l->gamma_ghz +
                       sqrt(0.2166 * l->gamma_ghz * l->gamma_ghz + l->gamma_d_ghz * l->gamma_d_ghz);
            if (!(l->nu_ghz > lo - 20.0 * w && l->nu_ghz < hi + 20.0 * w) || w / 4.0 >= step)
                continue;
            /* Cubic interpolation of a Lorentzian of half width w with step h errs by
             * about 0.56 (h/w)^4 of its peak; the line's share of alpha at its centre
             * scales that, so h = w (1e-5 / share)^(1/4) keeps it near 6e-6 of alpha. */
            atm_alpha_parts p;
            atm_lines_parts(d, l->nu_ghz * 1e9, &p);
            double total_per_cm = 1e-2 * atmosphere_alpha_parts_sum(&p);
            double share = fabs(l->amp * core(l, 0.0)) / total_per_cm;
            if (!(share > 0.0))
                continue;
            double h = w * fmin(0.25, pow(1e-5 / fmin(share, 1.0), 0.25));
            if (h < step)
                step = h;
        }
    }
    return step * 1e9;
}

/* ---- Set-up -------------------------------------------------------------------- */

/* A catalogue's path: the file given, else the data directory's (checked there: a
 * missing one is thzmap's installation's fault, thz_data_file). */
static thz_status resolve(char *buf, size_t n, const char *given, const char *data_dir,
                          const char *name, thz_error *err)
{
    if (given) {
        if (strlen(given) >= n)
            return thz_error_set(err, THZ_ERR_INPUT, "path too long: %s", given);
        strcpy(buf, given);
        return THZ_OK;
    }
    return thz_data_file(data_dir, name, buf, n, err);
}

thz_status atm_lines_create(atm_lines_data **out, const atm_air_state *air,
                            const atm_lines_options *opt, thz_error *err)
{
    enum { PATH = 4096 };
    char p_h2o[PATH], p_o2[PATH], p_o2c[PATH], p_qh2o[PATH], p_qo2[PATH], p_cont[PATH] = "";
    atm_lines_data *d = thz_calloc(1, sizeof *d);
    if (!d)
        return thz_error_set(err, THZ_ERR_NOMEM, "out of memory");
    d->air = *air;
    d->continuum = opt->continuum;
    const char *data = opt->data_dir;
    thz_status st =
        resolve(p_h2o, PATH, opt->h2o_lines_file, data, "atmosphere/am14_h2o_lines.csv", err);
    if (st == THZ_OK)
        st = resolve(p_o2, PATH, opt->o2_lines_file, data, "atmosphere/am14_o2_lines_uncoupled.csv",
                     err);
    if (st == THZ_OK)
        st = resolve(p_o2c, PATH, opt->o2_coupled_lines_file, data,
                     "atmosphere/am14_o2_lines_coupled.csv", err);
    if (st == THZ_OK)
        st = resolve(p_qh2o, PATH, opt->h2o_partition_sums_file, data,
                     "atmosphere/am14_h2o_partition_sums_tips2021.csv", err);
    if (st == THZ_OK)
        st = resolve(p_qo2, PATH, opt->o2_partition_sums_file, data,
                     "atmosphere/am14_o2_partition_sums_tips2021.csv", err);
    if (st == THZ_OK && d->continuum)
        st = resolve(p_cont, PATH, opt->continuum_file, data,
                     "atmosphere/mt_ckd_4.2_h2o_continuum_0-520cm-1.csv", err);
    /* Regular files of bounded size only: the readers grow their buffers line by line, and
     * /dev/zero or a FIFO would grow them, or block, without end. */
    const char *const inputs[ATM_IN_FILES] = {p_h2o, p_o2, p_o2c, p_qh2o, p_qo2, p_cont};
    for (size_t i = 0; st == THZ_OK && i < ATM_IN_FILES; i++)
        if (inputs[i][0] != '\0')
            st = file_check_regular(inputs[i], NULL, ATM_CATALOG_MAX_FILE_BYTES, NULL, err);
    if (st == THZ_OK)
        st = atm_inputs_acquire(inputs, &d->inputs, err);
    if (st != THZ_OK)
        goto cleanup;

    double t = air->temperature_k, p = air->pressure_hpa, e = air->h2o_pressure_hpa;
    d->dry_hpa = p - e;
    d->half_h_over_kt = H_OVER_K_K_PER_GHZ / (2.0 * t);
    d->n_h2o = e / (BOLTZMANN_HPA_CM3 * t);
    d->n_foreign = (p - e) / (BOLTZMANN_HPA_CM3 * t);
    d->n_ref = MT_CKD_P_REF_HPA / (BOLTZMANN_HPA_CM3 * MT_CKD_T_REF_K);
    double po2_hpa = O2_DRY_AIR_VMR * (p - e);
    double n_o2 = po2_hpa / (BOLTZMANN_HPA_CM3 * t);
    const atm_inputs *in = d->inputs;
    st =
        species_build(&d->h2o, &in->h2o, &in->q_h2o, 1, d->continuum ? SHAPE_VVH_CUTOFF : SHAPE_VVH,
                      air, e, d->n_h2o, "H2O", p_h2o, p_qh2o, err);
    if (st == THZ_OK)
        st = species_build(&d->o2, &in->o2, &in->q_o2, 7, SHAPE_GROSS, air, po2_hpa, n_o2, "O2",
                           p_o2, p_qo2, err);
    if (st == THZ_OK)
        st = species_build(&d->o2_coupled, &in->o2_coupled, &in->q_o2, 7, SHAPE_COUPLED, air,
                           po2_hpa, n_o2, "O2 coupled", p_o2c, p_qo2, err);
cleanup:
    if (st != THZ_OK) {
        atm_lines_destroy(d);
        return st;
    }
    *out = d;
    return THZ_OK;
}

void atm_lines_destroy(atm_lines_data *d)
{
    if (!d)
        return;
    free(d->h2o.lines);
    free(d->o2.lines);
    free(d->o2_coupled.lines);
    atm_inputs_release(d->inputs);
    free(d);
}
