/* Image comparison metrics of libobscura: how far an AO image is from a
 * ground truth.  The definitions are those of the project's referee script
 * tools/aometrics.py (shared/tools), so a number computed here and one
 * printed there mean the same thing.  No GL here; safe to call from any
 * thread. */
#ifndef OBSCURA_METRICS_H
#define OBSCURA_METRICS_H

#include "obscura/obscura.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Metrics of a candidate image b against a truth image a, over the pixels a
 * mask selects.  Values are clamped to [0,1] before anything is measured. */
typedef struct obs_metrics {
    double mse;       /* mean of (b - a)^2 */
    double mae;       /* mean of |b - a| */
    double psnr;      /* 10 log10(1 / max(mse, 1e-12)), in dB */
    double ssim;      /* mean SSIM over the selected pixels, see below */
    double corr;      /* Pearson correlation of a and b; 0 if either is constant */
    double bias;      /* mean of (b - a): candidate minus truth */
    long long count;  /* pixels compared (mask non-zero) */
} obs_metrics;

/* Compares single-channel images a (truth) and b (candidate) of the same
 * size over the pixels where mask (width*height bytes, row-major like the
 * images) is non-zero; mask may be NULL to select every pixel.
 *
 * SSIM is Wang et al. 2004 with a Gaussian window (sigma 1.5, 11 taps,
 * separable, mirror padding without repeating the edge pixel, as numpy's
 * np.pad(mode="reflect")), C1 = 0.01^2, C2 = 0.03^2.  It is computed on the
 * whole image with unselected pixels set to 1.0 in both images, then
 * averaged over the selected pixels: exactly aometrics.py's procedure.
 * NaN pixels propagate into the results, as they do there.
 *
 * Fails with OBS_INVALID_ARGUMENT when the images differ in size, are not
 * single-channel, or the mask selects no pixel; *out is zeroed then. */
obs_status obs_metrics_compute(const obs_image *a, const obs_image *b,
                               const unsigned char *mask, obs_metrics *out,
                               char err[OBS_ERR_LEN]);

/* The difference image of aometrics.py --diff: e = min(4 |b - a|, 1) on the
 * clamped values of every pixel, stored as RGB (e, 1 - e, 1 - e): white
 * where the images agree, red where they differ by 0.25 or more.  Same
 * argument checks as obs_metrics_compute().  Caller frees *out with
 * obs_image_free(). */
obs_status obs_metrics_diff_image(const obs_image *a, const obs_image *b,
                                  obs_image *out, char err[OBS_ERR_LEN]);

#ifdef __cplusplus
}
#endif

#endif
