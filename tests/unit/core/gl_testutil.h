/* Helpers of the GL tests: the small Blender scenes with their cameras,
 * a context of a given backend, and the difference of two images. */
#ifndef OBS_GL_TESTUTIL_H
#define OBS_GL_TESTUTIL_H

#include <math.h>

#include "testutil.h"

#include "obscura/io.h"

static const char *const scenes[] = {TESTDATA "/room_small", TESTDATA "/yard_small"};

static inline void load(const char *stem, obs_gbuffer_file *gf)
{
    char path[512], err[OBS_ERR_LEN] = "";
    snprintf(path, sizeof path, "%s.exr", stem);
    if (obs_gbuffer_read_exr(path, NULL, NULL, gf, err) != OBS_OK)
        fail_msg("%s: %s", path, err);
    snprintf(path, sizeof path, "%s.camera.json", stem);
    if (obs_camera_read_json(path, &gf->gb.camera, NULL, NULL, err) != OBS_OK)
        fail_msg("%s: %s", path, err);
}

static inline obs_ctx *make_ctx(obs_backend b)
{
    obs_ctx *ctx = NULL;
    char err[OBS_ERR_LEN] = "";
    obs_ctx_desc d = {.backend = b};
    if (obs_ctx_create(&d, &ctx, err) != OBS_OK)
        fail_msg("%s: %s", obs_backend_name(b), err);
    return ctx;
}

/* A context of the default backend, or the test skipped (said why) when
 * none can be made. */
#define CTX_OR_SKIP(ctx)                                                       \
    do {                                                                       \
        obs_ctx_desc desc_ = {0};                                              \
        char err_[OBS_ERR_LEN] = "";                                           \
        if (obs_ctx_create(&desc_, &(ctx), err_) != OBS_OK) {                  \
            print_message("no GL context (%s): skipped\n", err_);              \
            skip();                                                            \
        }                                                                      \
    } while (0)

/* Mean |a - b| and the fraction of pixels differing by more than 1e-3. */
static inline void diff(const obs_image *a, const obs_image *b, double *mean, double *frac)
{
    size_t n = (size_t)a->width * a->height * a->channels, big = 0;
    double sum = 0;
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    for (size_t i = 0; i < n; i++) {
        double d = fabs((double)a->data[i] - b->data[i]);
        sum += d;
        big += d > 1e-3;
    }
    *mean = sum / n;
    *frac = (double)big / n;
}

#endif
