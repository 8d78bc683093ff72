/* Fresnel optics of a complex refractive index N = n + ik seen from air (scene-format.md
 * "Materials: optics from a complex index"; docs/physics.md "Fresnel reflectance and
 * slabs"): the reflectance of the interface, exact for an absorbing medium, and of a
 * slab of thickness t with incoherent multiple reflections.
 *
 * mu = cos(theta_i) in (0, 1] is the cosine of the angle of incidence in air. With
 * s = sin(theta_i) and q = sqrt(N^2 - s^2) (the branch with Im q >= 0, the wave decays
 * into the medium), r_s = (mu - q)/(mu + q) and r_p = (N^2 mu - q)/(N^2 mu + q); the
 * unpolarised reflectance is (|r_s|^2 + |r_p|^2) / 2.
 */
#ifndef THZ_PHYSICS_FRESNEL_H
#define THZ_PHYSICS_FRESNEL_H

/* Reflectances |r_s|^2 and |r_p|^2 of air -> n + ik at mu, and the cosine of the real
 * refraction angle: the angle of the planes of constant phase in the medium,
 * cos(theta_t) = Re q / sqrt(s^2 + (Re q)^2) (= sqrt(1 - s^2/n^2) when k = 0). Any of
 * the outputs may be NULL. */
void fresnel_interface(double n, double k, double mu, double *r_s, double *r_p, double *cos_t);

/* Unpolarised reflectance of air -> n + ik at mu: the mean of |r_s|^2 and |r_p|^2. */
double fresnel_reflectance(double n, double k, double mu);

/* A slab of thickness_m of index n + ik in air, seen at mu, whose inside attenuates the
 * power by exp(-alpha_per_m thickness_m / cos(theta_t)) per crossing (alpha = 4 pi k nu / c
 * for the index's own absorption), theta_t the real refraction angle. Incoherent multiple
 * reflections, per polarisation with the interface reflectance r and internal
 * transmittance tau (the inner face reflects as the outer one, by reciprocity):
 *     R = r + (1 - r)^2 r tau^2 / (1 - r^2 tau^2),  T = (1 - r)^2 tau / (1 - r^2 tau^2),
 * then the mean of s and p. A lossless slab at normal incidence gives R = 2r/(1 + r). */
void fresnel_slab(double n, double k, double mu, double alpha_per_m, double thickness_m,
                  double *reflectance, double *transmittance);

#endif
