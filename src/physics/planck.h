/* Planck's law and its inverse, with CODATA 2018 constants (physics.md "Units"). */
#ifndef THZ_PHYSICS_PLANCK_H
#define THZ_PHYSICS_PLANCK_H

#define THZ_PLANCK_H 6.62607015e-34    /* J s   */
#define THZ_BOLTZMANN_K 1.380649e-23   /* J/K   */
#define THZ_SPEED_OF_LIGHT 299792458.0 /* m/s */

/* Spectral radiance of a black body, B_nu(T) in W m^-2 sr^-1 Hz^-1. T = 0 gives 0.
 * Accurate to 1e-12 relative in double precision for all freq_hz > 0, T >= 0
 * (uses expm1 where h nu / k T is small). */
double planck_radiance(double freq_hz, double temp_k);

/* Brightness temperature in K: the T with planck_radiance(freq_hz, T) = radiance.
 * Returns 0 for radiance <= 0. Round trip to 1e-9 K. */
double planck_brightness_temperature(double freq_hz, double radiance);

/* dB_nu/dT = B_nu(T) x e^x / ((e^x - 1) T), x = h nu / k T, in W m^-2 sr^-1 Hz^-1 K^-1;
 * 0 for T <= 0 (what a radiance error in K and a NETD in radiance convert through). */
double planck_dbdt(double freq_hz, double temp_k);

#endif
