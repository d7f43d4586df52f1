/* Quadratic spherical harmonics of the dynamic-object bake (section 2.3:
 * "We sample spherical obscurance functions at each of the valid points,
 * convolving with a clamped cosine function so that we can generate AO for
 * any input normal"; section 2.3, the 18 channels of quadratic SH at two
 * distances).
 *
 * With f(w) the spherical obscurance rho(d(p, w)) of the point p, eq 1 for
 * the normal n is (1/pi) integral f(w) max(0, n . w) dw; the clamped
 * cosine is zonal, so by the Funk-Hecke theorem the integral is
 * sum_lm A_l f_lm Y_lm(n) with A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4
 * (Ramamoorthi and Hanrahan, "An efficient representation for irradiance
 * environment maps", 2001).  Bands 0..2 keep all but a few percent of a
 * smooth f; the paper's engine evaluates bands 0..1 only. */
#include <math.h>
#include <string.h>

#include "level/level.h"
#include "level/rng.h"

#define PI_D 3.14159265358979323846

const double obs__sh_cosine[3] = {PI_D, 2.0 * PI_D / 3.0, PI_D / 4.0};

void obs__sh_basis(const float d[3], double y[OBS_DYN_SH])
{
    double x = d[0], yy = d[1], z = d[2];
    y[0] = 0.28209479177387814;            /* 1 / (2 sqrt(pi)) */
    y[1] = 0.4886025119029199 * yy;        /* sqrt(3 / 4 pi) y */
    y[2] = 0.4886025119029199 * z;
    y[3] = 0.4886025119029199 * x;
    y[4] = 1.0925484305920792 * x * yy;    /* sqrt(15 / 4 pi) */
    y[5] = 1.0925484305920792 * yy * z;
    y[6] = 0.31539156525252005 * (3.0 * z * z - 1.0); /* sqrt(5 / 16 pi) */
    y[7] = 1.0925484305920792 * x * z;
    y[8] = 0.5462742152960396 * (x * x - yy * yy);  /* sqrt(15 / 16 pi) */
}

void obs__sh_project(const float *dirs, const double *w, const double *f, size_t n,
                         double out[OBS_DYN_SH])
{
    memset(out, 0, OBS_DYN_SH * sizeof *out);
    for (size_t i = 0; i < n; i++) {
        double y[OBS_DYN_SH];
        obs__sh_basis(dirs + 3 * i, y);
        for (int k = 0; k < OBS_DYN_SH; k++)
            out[k] += w[i] * f[i] * y[k];
    }
}

static int band(int k) { return k == 0 ? 0 : k < 4 ? 1 : 2; }

void obs__sh_convolve(double c[OBS_DYN_SH])
{
    for (int k = 0; k < OBS_DYN_SH; k++)
        c[k] *= obs__sh_cosine[band(k)] / PI_D; /* the 1/pi of eq 1 */
}

double obs__sh_eval(const double c[OBS_DYN_SH], const float n[3], int order)
{
    double y[OBS_DYN_SH], s = 0.0;
    obs__sh_basis(n, y);
    int kmax = order >= 2 ? 9 : order == 1 ? 4 : 1;
    for (int k = 0; k < kmax; k++)
        s += c[k] * y[k];
    return s;
}

void obs__sphere_dirs(int n, uint64_t seed, uint64_t stream, float *dirs)
{
    /* A uniform random rotation (a unit quaternion from four normal
     * deviates, Box-Muller), so that neighbouring points do not share
     * their directions' pattern. */
    obs__bake_rng r = obs__bake_rng_stream(seed, stream, 7);
    double q[4];
    for (int i = 0; i < 4; i += 2) {
        double u1 = fmax(obs__bake_rng_unit(&r), 1e-300), u2 = obs__bake_rng_unit(&r);
        double rad = sqrt(-2.0 * log(u1));
        q[i] = rad * cos(2.0 * PI_D * u2);
        q[i + 1] = rad * sin(2.0 * PI_D * u2);
    }
    double qn = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    double a = q[0] / qn, b = q[1] / qn, c = q[2] / qn, d = q[3] / qn;
    double m[9] = {a * a + b * b - c * c - d * d, 2 * (b * c - a * d), 2 * (b * d + a * c),
                   2 * (b * c + a * d), a * a - b * b + c * c - d * d, 2 * (c * d - a * b),
                   2 * (b * d - a * c), 2 * (c * d + a * b), a * a - b * b - c * c + d * d};
    const double golden = PI_D * (3.0 - sqrt(5.0));
    for (int k = 0; k < n; k++) {
        double z = 1.0 - (2.0 * k + 1.0) / n, s = sqrt(fmax(0.0, 1.0 - z * z));
        double phi = golden * k, v[3] = {s * cos(phi), s * sin(phi), z};
        for (int i = 0; i < 3; i++)
            dirs[3 * k + i] = (float)(m[3 * i] * v[0] + m[3 * i + 1] * v[1] + m[3 * i + 2] * v[2]);
    }
}
