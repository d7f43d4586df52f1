/* Developer tool of make quality (bench/quality.sh): EXR channels laid out
 * side by side in one small PNG, a grid of tiles reduced by an integer
 * factor (box filter).
 *
 *   quality_strip OUT.png --scale N --cols C TILE...
 *   TILE: --grey FILE CH            one channel, clamped to [0,1]
 *         --rgb FILE R G B          colour channels, sRGB-encoded
 *         --diff FILE_A CH_A FILE_B CH_B
 *                                   error map of B against A, as
 *                                   obscura compare --diff draws it
 *         --empty                   a white tile
 *   --sky FILE CH: where that depth channel is 1e9 or more (no geometry),
 *   grey and diff tiles are white.
 * Tiles fill the grid row by row; all must have one size. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "obscura/io.h"
#include "obscura/metrics.h"

#define MAX_TILES 64
#define GUTTER 4

static void die(const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "quality_strip: ");
    fprintf(stderr, fmt, a, b);
    fputc('\n', stderr);
    exit(1);
}

static void read_ch(const char *path, const char *ch, obs_image *img)
{
    char err[OBS_ERR_LEN] = "";
    if (obs_exr_read_channel(path, ch, NULL, img, err) != OBS_OK)
        die("%s: %s", path, err);
}

static float srgb(float v)
{
    v = fminf(fmaxf(v, 0.0f), 1.0f);
    return v <= 0.0031308f ? 12.92f * v : 1.055f * powf(v, 1.0f / 2.4f) - 0.055f;
}

static obs_image sky;

static void paint_sky(obs_image *t)
{
    if (!sky.data || sky.width != t->width || sky.height != t->height)
        return;
    for (size_t p = 0; p < (size_t)t->width * t->height; p++)
        if (!(sky.data[p] < 1e9f))
            t->data[3 * p] = t->data[3 * p + 1] = t->data[3 * p + 2] = 1.0f;
}

/* One tile as RGB at full resolution; NULL data for an empty tile. */
static int make_tile(int argc, char **argv, int i, obs_image *t)
{
    const char *k = argv[i];
    memset(t, 0, sizeof *t);
    if (!strcmp(k, "--empty"))
        return i + 1;
    if (!strcmp(k, "--grey") && i + 2 < argc) {
        obs_image g;
        read_ch(argv[i + 1], argv[i + 2], &g);
        size_t n = (size_t)g.width * g.height;
        *t = (obs_image){g.width, g.height, 3, malloc(n * 3 * sizeof(float))};
        for (size_t p = 0; p < n; p++)
            t->data[3 * p] = t->data[3 * p + 1] = t->data[3 * p + 2] = fminf(fmaxf(g.data[p], 0.0f), 1.0f);
        obs_image_free(&g);
        paint_sky(t);
        return i + 3;
    }
    if (!strcmp(k, "--rgb") && i + 4 < argc) {
        obs_image c[3];
        for (int j = 0; j < 3; j++)
            read_ch(argv[i + 1], argv[i + 2 + j], &c[j]);
        size_t n = (size_t)c[0].width * c[0].height;
        *t = (obs_image){c[0].width, c[0].height, 3, malloc(n * 3 * sizeof(float))};
        for (size_t p = 0; p < n; p++)
            for (int j = 0; j < 3; j++)
                t->data[3 * p + j] = srgb(c[j].data[p]);
        for (int j = 0; j < 3; j++)
            obs_image_free(&c[j]);
        return i + 5;
    }
    if (!strcmp(k, "--diff") && i + 4 < argc) {
        obs_image a, b;
        char err[OBS_ERR_LEN] = "";
        read_ch(argv[i + 1], argv[i + 2], &a);
        read_ch(argv[i + 3], argv[i + 4], &b);
        if (obs_metrics_diff_image(&a, &b, t, err) != OBS_OK)
            die("%s: %s", argv[i + 3], err);
        obs_image_free(&a);
        obs_image_free(&b);
        paint_sky(t);
        return i + 5;
    }
    die("bad tile '%s'%s", k, "");
    return argc;
}

int main(int argc, char **argv)
{
    if (argc < 6)
        die("usage: quality_strip OUT.png --scale N --cols C TILE...%s%s", "", "");
    const char *out = argv[1];
    int scale = 0, cols = 0, n = 0, w = 0, h = 0;
    obs_image tiles[MAX_TILES];
    for (int i = 2; i < argc;) {
        if (!strcmp(argv[i], "--scale") && i + 1 < argc) {
            scale = atoi(argv[i + 1]);
            i += 2;
        } else if (!strcmp(argv[i], "--sky") && i + 2 < argc) {
            read_ch(argv[i + 1], argv[i + 2], &sky);
            i += 3;
        } else if (!strcmp(argv[i], "--cols") && i + 1 < argc) {
            cols = atoi(argv[i + 1]);
            i += 2;
        } else {
            if (n == MAX_TILES)
                die("more than %s tiles%s", "64", "");
            i = make_tile(argc, argv, i, &tiles[n]);
            if (tiles[n].data) {
                if (w && (tiles[n].width != w || tiles[n].height != h))
                    die("tiles differ in size (%s)%s", argv[i - 1], "");
                w = tiles[n].width;
                h = tiles[n].height;
            }
            n++;
        }
    }
    if (scale < 1 || cols < 1 || !w)
        die("needs --scale >= 1, --cols >= 1 and a tile%s%s", "", "");
    const int tw = w / scale, th = h / scale, rows = (n + cols - 1) / cols;
    const int cw = cols * tw + (cols - 1) * GUTTER, ch = rows * th + (rows - 1) * GUTTER;
    obs_image canvas = {cw, ch, 3, malloc((size_t)cw * ch * 3 * sizeof(float))};
    for (size_t p = 0; p < (size_t)cw * ch * 3; p++)
        canvas.data[p] = 1.0f;
    for (int t = 0; t < n; t++) {
        if (!tiles[t].data)
            continue;
        int ox = (t % cols) * (tw + GUTTER), oy = (t / cols) * (th + GUTTER);
        for (int y = 0; y < th; y++)
            for (int x = 0; x < tw; x++)
                for (int c = 0; c < 3; c++) {
                    float s = 0;
                    for (int dy = 0; dy < scale; dy++)
                        for (int dx = 0; dx < scale; dx++)
                            s += tiles[t].data[((size_t)(y * scale + dy) * w + (x * scale + dx)) * 3 + c];
                    canvas.data[((size_t)(oy + y) * cw + ox + x) * 3 + c] = s / (scale * scale);
                }
        obs_image_free(&tiles[t]);
    }
    char err[OBS_ERR_LEN] = "";
    if (obs_png_write(out, &canvas, 8, 0, err) != OBS_OK)
        die("%s: %s", out, err);
    obs_image_free(&canvas);
    obs_image_free(&sky);
    return 0;
}
