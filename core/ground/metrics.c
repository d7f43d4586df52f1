/* Image comparison metrics: MSE, MAE, PSNR, SSIM, correlation and bias of
 * an AO image against a ground truth, defined as shared/tools/aometrics.py
 * defines them.
 *
 * SSIM follows aometrics.py step by step, down to the order in which numpy
 * (1.24) adds the 11 products of each blur tap: pairwise along rows, one by
 * one down columns.  With the same Gaussian weights the SSIM map is then
 * bitwise numpy's; numpy's own exp() on AVX-512 machines differs from
 * libm's by an ulp in some weights, and the final mean is summed in a
 * different order, so the mean agrees to about 1e-13.
 *
 * numpy builds padded full-size planes; here the blur keeps only the last
 * 11 horizontally blurred rows of each of its five fields in a ring, so
 * SSIM needs O(width) memory. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "obscura/metrics.h"

#define SSIM_R 5
#define SSIM_TAPS (2 * SSIM_R + 1)
#define SSIM_SIGMA 1.5
#define SSIM_C1 (0.01 * 0.01)
#define SSIM_C2 (0.03 * 0.03)
#define SSIM_FIELDS 5 /* a, b, a*a, b*b, a*b */

/* np.clip(v, 0, 1) on the float64 value of a float32 pixel; NaN stays NaN. */
static double clamp01(float v)
{
    double d = v;
    return d < 0.0 ? 0.0 : d > 1.0 ? 1.0 : d;
}

/* The truth a and the candidate b: one channel each, the same size, not
 * empty; *n their pixels. */
static obs_status check_pair(const obs_image *a, const obs_image *b, size_t *n,
                             char err[OBS_ERR_LEN])
{
    if (!a || !b)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "metrics: %s image is NULL",
                         !a ? "truth" : "candidate");
    if (a->channels != 1 || b->channels != 1)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "metrics need single-channel images: truth is %dx%d with %d channels, "
                         "candidate %dx%d with %d channels",
                         a->width, a->height, a->channels, b->width, b->height, b->channels);
    if (a->width != b->width || a->height != b->height)
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "image sizes differ: truth %dx%d, candidate %dx%d", a->width,
                         a->height, b->width, b->height);
    if (a->width <= 0 || a->height <= 0 || !a->data || !b->data)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "metrics: empty image (%dx%d%s)",
                         a->width, a->height, !a->data || !b->data ? ", no pixels" : "");
    if (obs__size_mul((size_t)a->width, (size_t)a->height, n) != 0)
        return obs__fail(err, OBS_TOO_LARGE, "metrics: image %dx%d too large", a->width,
                         a->height);
    return OBS_OK;
}

/* Index into [0, n) of padded position i, as np.pad(mode="reflect"): the
 * edge pixel is not repeated, and images narrower than the radius are
 * mirrored again (period 2(n-1)); a single pixel pads with itself. */
static int reflect(long long i, int n)
{
    if (n == 1)
        return 0;
    long long period = 2 * ((long long)n - 1);
    i %= period;
    if (i < 0)
        i += period;
    return (int)(i >= n ? period - i : i);
}

/* Sum of 11 terms as numpy's pairwise_sum adds a contiguous run of 11:
 * eight partial sums combined as a tree, then the rest one by one. */
static double sum_pairwise(const double p[SSIM_TAPS])
{
    double s = ((p[0] + p[1]) + (p[2] + p[3])) + ((p[4] + p[5]) + (p[6] + p[7]));
    for (int k = 8; k < SSIM_TAPS; k++)
        s += p[k];
    return s;
}

static double sum_sequential(const double p[SSIM_TAPS])
{
    double s = p[0];
    for (int k = 1; k < SSIM_TAPS; k++)
        s += p[k];
    return s;
}

/* The normalised Gaussian of aometrics.py:
 * x = arange(-5, 6); g = exp(-x*x / (2*1.5**2)); g /= g.sum(). */
static void gaussian(double g[SSIM_TAPS])
{
    for (int k = 0; k < SSIM_TAPS; k++) {
        int x = k - SSIM_R;
        g[k] = exp((double)(-x * x) / (2.0 * SSIM_SIGMA * SSIM_SIGMA));
    }
    double s = sum_pairwise(g);
    for (int k = 0; k < SSIM_TAPS; k++)
        g[k] /= s;
}

typedef struct ssim_work {
    const obs_image *a, *b;
    const unsigned char *mask;
    int w, h;
    double g[SSIM_TAPS];
    int *xidx;                /* padded column (w + 2R) -> source column */
    double *in[SSIM_FIELDS];  /* one unblurred row of each field */
    double *ring[SSIM_FIELDS]; /* SSIM_TAPS blurred rows each, row y in slot y % SSIM_TAPS */
} ssim_work;

/* Horizontal pass for source row y: the row with unselected pixels set to
 * 1.0 (np.where(m, t, 1.0)), its products, each blurred along the row. */
static void blur_row(ssim_work *s, int y)
{
    size_t off = (size_t)y * (size_t)s->w;
    const float *ra = s->a->data + off, *rb = s->b->data + off;
    const unsigned char *rm = s->mask ? s->mask + off : NULL;
    for (int x = 0; x < s->w; x++) {
        int sel = !rm || rm[x];
        double va = sel ? clamp01(ra[x]) : 1.0;
        double vb = sel ? clamp01(rb[x]) : 1.0;
        s->in[0][x] = va;
        s->in[1][x] = vb;
        s->in[2][x] = va * va;
        s->in[3][x] = vb * vb;
        s->in[4][x] = va * vb;
    }
    size_t slot = (size_t)(y % SSIM_TAPS) * (size_t)s->w;
    for (int f = 0; f < SSIM_FIELDS; f++) {
        const double *in = s->in[f];
        double *outrow = s->ring[f] + slot;
        for (int x = 0; x < s->w; x++) {
            double p[SSIM_TAPS];
            for (int k = 0; k < SSIM_TAPS; k++)
                p[k] = in[s->xidx[x + k]] * s->g[k];
            outrow[x] = sum_pairwise(p);
        }
    }
}

/* Mean of the SSIM map over the selected pixels (count of them). */
static obs_status ssim_mean(const obs_image *a, const obs_image *b, const unsigned char *mask,
                            long long count, double *out, char err[OBS_ERR_LEN])
{
    obs_status st = OBS_OK;
    ssim_work s;
    memset(&s, 0, sizeof s);
    s.a = a;
    s.b = b;
    s.mask = mask;
    s.w = a->width;
    s.h = a->height;
    gaussian(s.g);

    size_t rows = SSIM_FIELDS + SSIM_FIELDS * SSIM_TAPS, nd, ni;
    double *buf = NULL;
    if (obs__size_mul3(rows, (size_t)s.w, sizeof(double), &nd) != 0 ||
        obs__size_mul((size_t)s.w + 2 * SSIM_R, sizeof(int), &ni) != 0) {
        st = obs__fail(err, OBS_TOO_LARGE, "metrics: image width %d too large for SSIM", s.w);
        goto fail;
    }
    buf = malloc(nd);
    s.xidx = malloc(ni);
    if (!buf || !s.xidx) {
        st = obs__fail(err, OBS_NO_MEMORY, "metrics: no memory for SSIM rows (%zu bytes)",
                       nd + ni);
        goto fail;
    }
    for (int f = 0; f < SSIM_FIELDS; f++) {
        s.in[f] = buf + (size_t)f * (size_t)s.w;
        s.ring[f] = buf + (size_t)(SSIM_FIELDS + f * SSIM_TAPS) * (size_t)s.w;
    }
    for (size_t i = 0; i < (size_t)s.w + 2 * SSIM_R; i++)
        s.xidx[i] = reflect((long long)i - SSIM_R, s.w);

    /* numpy sums a column window one term at a time, except for one-pixel-
     * wide images, where the window is contiguous and it sums pairwise. */
    double (*vsum)(const double *) = s.w == 1 ? sum_pairwise : sum_sequential;
    double total = 0.0;
    int next = 0; /* next source row to blur horizontally */
    for (int y = 0; y < s.h; y++) {
        int last = y < s.h - SSIM_R ? y + SSIM_R : s.h - 1;
        while (next <= last)
            blur_row(&s, next++);
        /* Rows needed lie in [y-R, y+R], so the ring of 11 holds them all. */
        size_t slot[SSIM_TAPS];
        for (int k = 0; k < SSIM_TAPS; k++)
            slot[k] = (size_t)(reflect((long long)y - SSIM_R + k, s.h) % SSIM_TAPS) *
                      (size_t)s.w;
        const unsigned char *rm = mask ? mask + (size_t)y * (size_t)s.w : NULL;
        for (int x = 0; x < s.w; x++) {
            if (rm && !rm[x])
                continue;
            double m[SSIM_FIELDS];
            for (int f = 0; f < SSIM_FIELDS; f++) {
                double p[SSIM_TAPS];
                for (int k = 0; k < SSIM_TAPS; k++)
                    p[k] = s.ring[f][slot[k] + (size_t)x] * s.g[k];
                m[f] = vsum(p);
            }
            double ma = m[0], mb = m[1];
            double va = m[2] - ma * ma, vb = m[3] - mb * mb, cov = m[4] - ma * mb;
            /* Same expression, same evaluation order as aometrics.py. */
            total += ((2 * ma * mb + SSIM_C1) * (2 * cov + SSIM_C2)) /
                     ((ma * ma + mb * mb + SSIM_C1) * (va + vb + SSIM_C2));
        }
    }
    *out = total / (double)count;

fail:
    free(s.xidx);
    free(buf);
    return st;
}

obs_status obs_metrics_compute(const obs_image *a, const obs_image *b, const unsigned char *mask,
                               obs_metrics *out, char err[OBS_ERR_LEN])
{
    if (!out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "metrics: no output");
    memset(out, 0, sizeof *out);
    size_t n;
    obs_status st = check_pair(a, b, &n, err);
    if (st != OBS_OK)
        return st;

    /* First pass: the differences and the means. */
    long long count = 0;
    double sum_d = 0.0, sum_ad = 0.0, sum_dd = 0.0, sum_a = 0.0, sum_b = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (mask && !mask[i])
            continue;
        double ta = clamp01(a->data[i]), cb = clamp01(b->data[i]);
        double d = cb - ta;
        count++;
        sum_d += d;
        sum_ad += fabs(d);
        sum_dd += d * d;
        sum_a += ta;
        sum_b += cb;
    }
    if (count == 0)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "mask selects no pixels (image %dx%d)",
                         a->width, a->height);

    /* Second pass: centred moments for the correlation (np.corrcoef). */
    double mean_a = sum_a / (double)count, mean_b = sum_b / (double)count;
    double sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (mask && !mask[i])
            continue;
        double da = clamp01(a->data[i]) - mean_a, db = clamp01(b->data[i]) - mean_b;
        sxx += da * da;
        syy += db * db;
        sxy += da * db;
    }

    double ssim;
    st = ssim_mean(a, b, mask, count, &ssim, err);
    if (st != OBS_OK)
        return st;

    out->count = count;
    out->mse = sum_dd / (double)count;
    out->mae = sum_ad / (double)count;
    out->bias = sum_d / (double)count;
    /* max(mse, 1e-12) written so that a NaN mse stays NaN, as in Python. */
    out->psnr = 10.0 * log10(1.0 / (out->mse < 1e-12 ? 1e-12 : out->mse));
    out->ssim = ssim;
    if (sxx == 0.0 || syy == 0.0) {
        out->corr = 0.0; /* undefined for a constant image; numpy gives NaN */
    } else {
        double c = sxy / sqrt(sxx * syy);
        out->corr = c > 1.0 ? 1.0 : c < -1.0 ? -1.0 : c;
    }
    return OBS_OK;
}

obs_status obs_metrics_diff_image(const obs_image *a, const obs_image *b, obs_image *out,
                                  char err[OBS_ERR_LEN])
{
    if (!out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "metrics: no output image");
    memset(out, 0, sizeof *out);
    size_t n, bytes;
    obs_status st = check_pair(a, b, &n, err);
    if (st != OBS_OK)
        return st;
    if (obs__size_mul3(n, 3, sizeof(float), &bytes) != 0)
        return obs__fail(err, OBS_TOO_LARGE, "metrics: image %dx%d too large", a->width,
                         a->height);
    float *px = malloc(bytes);
    if (!px)
        return obs__fail(err, OBS_NO_MEMORY, "metrics: no memory for a %dx%d difference image",
                         a->width, a->height);
    for (size_t i = 0; i < n; i++) {
        double e = fabs(clamp01(b->data[i]) - clamp01(a->data[i])) * 4.0;
        e = e > 1.0 ? 1.0 : e; /* never below 0; NaN stays NaN */
        px[3 * i + 0] = (float)e;
        px[3 * i + 1] = (float)(1.0 - e);
        px[3 * i + 2] = (float)(1.0 - e);
    }
    out->width = a->width;
    out->height = a->height;
    out->channels = 3;
    out->data = px;
    return OBS_OK;
}
