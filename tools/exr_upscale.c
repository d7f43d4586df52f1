/* Developer tool: a G-buffer EXR upscaled (nearest neighbour) to W x H, so
 * that tests and benchmarks can make large frames without large files in
 * git.  The output uses the generic channel names (Z; N.X, N.Y, N.Z;
 * R, G, B, A) as float32, and keeps the input's header camera if any;
 * with CAMERA.json that camera is written to the header instead (so the
 * output needs no camera flags).
 *
 *   exr_upscale IN.exr WxH OUT.exr [CAMERA.json]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "obscura/io.h"
#include "obscura/obscura.h"

/* Nearest-neighbour upscale of one plane into a tightly packed image. */
static int upscale(const obs_plane *p, int sw, int sh, int w, int h, obs_image *out)
{
    out->width = w;
    out->height = h;
    out->channels = p->channels;
    if (!(out->data = malloc(sizeof(float) * (size_t)w * h * p->channels)))
        return -1;
    size_t stride = p->row_stride ? p->row_stride : sizeof(float) * (size_t)sw * p->channels;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *src = (const float *)((const char *)p->data + (size_t)((long long)y * sh / h) * stride) +
                               (size_t)((long long)x * sw / w) * p->channels;
            memcpy(out->data + ((size_t)y * w + x) * p->channels, src, sizeof(float) * p->channels);
        }
    return 0;
}

int main(int argc, char **argv)
{
    int w = 0, h = 0;
    char extra;
    if (argc < 4 || argc > 5 || sscanf(argv[2], "%dx%d%c", &w, &h, &extra) != 2 || w < 1 || h < 1 || w > 16384 ||
        h > 16384) {
        fprintf(stderr, "usage: exr_upscale IN.exr WxH OUT.exr [CAMERA.json]\n");
        return 2;
    }
    char err[OBS_ERR_LEN];
    obs_gbuffer_file gf = {0};
    if (obs_gbuffer_read_exr(argv[1], NULL, NULL, &gf, err) != OBS_OK) {
        fprintf(stderr, "exr_upscale: %s\n", err);
        return 1;
    }
    static const char *const zn[] = {"Z"}, *const nn[] = {"N.X", "N.Y", "N.Z"},
                             *const cn[] = {"R", "G", "B", "A"};
    obs_image img[3] = {{0}};
    obs_exr_layer layers[3];
    int n = 0, rc = 1;
    const obs_plane *planes[3] = {&gf.gb.depth, &gf.gb.normal, &gf.gb.color};
    const char *const *names[3] = {zn, nn, cn};
    for (int i = 0; i < 3; i++) {
        if (!planes[i]->data)
            continue;
        if ((i == 2 && planes[i]->channels < 3) ||
            upscale(planes[i], gf.gb.width, gf.gb.height, w, h, &img[n]) != 0) {
            fprintf(stderr, "exr_upscale: cannot upscale plane %d\n", i);
            goto done;
        }
        layers[n] = (obs_exr_layer){&img[n], names[i]};
        n++;
    }
    if (argc == 5 && obs_camera_read_json(argv[4], &gf.gb.camera, NULL, NULL, err) != OBS_OK) {
        fprintf(stderr, "exr_upscale: %s\n", err);
        goto done;
    }
    const obs_camera *cam = gf.gb.camera.source != OBS_CAMERA_NONE ? &gf.gb.camera : NULL;
    if (obs_exr_write(argv[3], layers, n, OBS_EXR_FLOAT, cam, err) != OBS_OK) {
        fprintf(stderr, "exr_upscale: %s\n", err);
        goto done;
    }
    rc = 0;
done:
    for (int i = 0; i < 3; i++)
        obs_image_free(&img[i]);
    obs_gbuffer_free(&gf);
    return rc;
}
