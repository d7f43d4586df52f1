/* The closed form of eq 1 of the bake's paper at a 90-degree crease, for
 * the tests of the bake (tests/unit/bake/) and of the reference's
 * obscurance mode (tests/unit/core/test_reference_obscurance.c). */
#ifndef OBS_TEST_OBSCURANCE_CREASE_H
#define OBS_TEST_OBSCURANCE_CREASE_H

#include <math.h>

/* Eq 1 with rho(x) = 1 - exp(a x), a = ln(0.5) / d, at a point of a floor
 * at distance h from an infinite wall standing on it (a 90-degree crease;
 * the same at height h on the wall, by symmetry).  Cosine-weighted
 * directions are uniform points (x, y) of the unit disk lifted to the
 * hemisphere (Malley's method), so eq 1 is the disk average of rho; with x
 * the component towards the wall, a direction with x > 0 meets the wall at
 * t = h / x, one with x <= 0 nothing (rho = 1).  So
 *   AO(h) = 1 - 1/pi  integral over the half disk x > 0 of exp(a h / x)
 *         = 1 - 2/pi  integral_0^1 sqrt(1 - x^2) exp(-k / x) dx,  k = h ln 2 / d,
 * and AO(0) = 1 - 2/pi * pi/4 = 1/2 for every d.  The one-dimensional
 * integral is evaluated by Simpson's rule (smooth: exp(-k/x) -> 0 at 0). */
static inline double crease_ao(double h, double d)
{
    double k = h * log(2.0) / d;
    const int n = 4000;
    double acc = 0.0;
    for (int i = 0; i <= n; i++) {
        double x = (double)i / n;
        double fx = x > 0.0 ? sqrt(fmax(0.0, 1.0 - x * x)) * exp(-k / x) : (k > 0.0 ? 0.0 : 1.0);
        acc += fx * (i == 0 || i == n ? 1.0 : i % 2 ? 4.0 : 2.0);
    }
    return 1.0 - 2.0 / 3.14159265358979323846 * acc / (3.0 * n);
}

#endif
