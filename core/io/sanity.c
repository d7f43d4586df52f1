/* Sanity warnings on a G-buffer read under a convention: values that look
 * unlike what the convention says (depth normalized or inverted, normals
 * not unit length or in the other space).  Normals are tested against the
 * normals derived from depth: under the right depth mode and normal
 * space the two agree on smooth surfaces.  One line each; --strict makes
 * them errors.  Never changes the G-buffer. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/exr_internal.h"
#include "obscura/deep.h"
#include "internal.h"

/* A G-buffer with fewer valid pixels than this is not judged. */
#define MIN_PIXELS 64
/* Normals whose mean | |n| - 1 | exceeds this are not unit length. */
#define UNIT_TOLERANCE 0.05
/* Mean n . n_depth under which normals disagree with depth, and over
 * which the alternative agrees. */
#define AGREE_BAD 0.5
#define AGREE_GOOD 0.8
/* Neighbours farther apart than this fraction of the depth are an edge. */
#define EDGE_FRACTION 0.05
/* Mean AO over the geometry above which the AO is "above 0.99 almost
 * everywhere": the Arnold frame at 20 units, radius 0.5, is 0.996; the
 * Blender rooms at their radius 0.93..0.97. */
#define AO_HIGH 0.99

__attribute__((format(printf, 3, 4)))
static void warn(obs_exr_info *info, int *added, const char *fmt, ...)
{
    va_list ap;
    if (info->warning_count >= OBS_EXR_WARNINGS)
        return;
    va_start(ap, fmt);
    vsnprintf(info->warnings[info->warning_count++], sizeof info->warnings[0], fmt, ap);
    va_end(ap);
    (*added)++;
}

/* Planar depth of raw value v under a depth mode (planar, inverse, or
 * normalized over near..far); 0 for background.  radial and ndc are left
 * to the chain: the depth-derived normals are not computed for them. */
static double planar(double v, obs_depth_mode mode, double n, double f)
{
    if (!isfinite(v))
        return 0.0;
    if (mode == OBS_DEPTH_INVERSE)
        v = v > 0.0 ? 1.0 / v : 0.0;
    else if (mode == OBS_DEPTH_NORMALIZED)
        v = v >= 0.0 && v < 1.0 ? n + v * (f - n) : 0.0;
    return v > 0.0 && v < OBS_BACKGROUND_DEPTH ? v : 0.0;
}

/* View-space point of pixel (x, y) at planar depth d, for a perspective
 * projection P (display window dw x dh, the planes at ox, oy). */
static void view_point(const float *P, double x, double y, double d, double out[3])
{
    /* x_ndc = (P00 X + P01 Y + P02 Z + P03) / -Z, with Z = -d */
    double nx = x, ny = y;
    double a = P[0], b = P[1], c = P[4], e = P[5];
    double rx = nx * d - (P[2] * -d + P[3]), ry = ny * d - (P[6] * -d + P[7]);
    double det = a * e - b * c;
    out[0] = (e * rx - b * ry) / det;
    out[1] = (a * ry - c * rx) / det;
    out[2] = -d;
}

/* The normal of pixel (x, y) in view space as `space` says. */
static void view_normal(const obs_gbuffer *gb, const float *wtc, obs_normal_space space, int x, int y,
                        float o[3])
{
    const float *n = obs__plane_px(&gb->normal, gb->width, x, y);
    for (int r = 0; r < 3; r++)
        o[r] = space == OBS_NORMALS_CAMERA ? n[r]
                                           : wtc[r * 4] * n[0] + wtc[r * 4 + 1] * n[1] + wtc[r * 4 + 2] * n[2];
}

/* Mean agreement n . n_depth over smooth pixels of the normals (in view
 * space as `space` says, through wtc) with the normals derived from depth
 * under `mode`; -2 when too few pixels were usable.  A mean of cosines
 * (in [-1, 1]) over N pixels is within about 1/sqrt(N) of the frame's, so
 * a grid of about AGREE_SAMPLES pixels (N = 65536: 0.004) tells 0.5 from
 * 0.8 as well as every pixel would, at a fraction of a large frame's cost. */
#define AGREE_SAMPLES 65536.0
static double agreement(const obs_gbuffer *gb, const float *P, const float *wtc, obs_normal_space space,
                        obs_depth_mode mode, double n, double f)
{
    int w = gb->width, h = gb->height;
    int dw = gb->display_width > 0 ? gb->display_width : w;
    int dh = gb->display_height > 0 ? gb->display_height : h;
    double sum = 0.0;
    long count = 0;
    int step = (double)w * h > AGREE_SAMPLES ? (int)sqrt((double)w * h / AGREE_SAMPLES) : 1;
    step = step < 1 ? 1 : step;
    for (int y = 1; y + 1 < h; y += step)
        for (int x = 1; x + 1 < w; x += step) {
            double d[3], p[3][3];
            const int px[3][2] = {{x, y}, {x + 1, y}, {x, y + 1}};
            int ok = 1;
            for (int k = 0; k < 3 && ok; k++) {
                d[k] = planar(*obs__plane_px(&gb->depth, w, px[k][0], px[k][1]), mode, n, f);
                ok = d[k] > 0.0;
                double ndx = (px[k][0] + 0.5 + gb->display_x) / dw * 2.0 - 1.0;
                double ndy = 1.0 - (px[k][1] + 0.5 + gb->display_y) / dh * 2.0;
                view_point(P, ndx, ndy, d[k], p[k]);
            }
            if (!ok || fabs(d[1] - d[0]) > EDGE_FRACTION * d[0] ||
                fabs(d[2] - d[0]) > EDGE_FRACTION * d[0])
                continue;
            double u[3] = {p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]};
            double v[3] = {p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]};
            /* rows grow downwards: u x v points away from the camera */
            double c[3] = {v[1] * u[2] - v[2] * u[1], v[2] * u[0] - v[0] * u[2],
                           v[0] * u[1] - v[1] * u[0]};
            double len = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
            float m[3];
            view_normal(gb, wtc, space, x, y, m);
            double ml = sqrt((double)m[0] * m[0] + (double)m[1] * m[1] + (double)m[2] * m[2]);
            if (len <= 0.0 || !(ml > 0.0) || !isfinite(ml))
                continue;
            sum += (c[0] * m[0] + c[1] * m[1] + c[2] * m[2]) / (len * ml);
            count++;
        }
    return count >= MIN_PIXELS ? sum / (double)count : -2.0;
}

static const char *space_name(obs_normal_space s)
{
    return s == OBS_NORMALS_CAMERA ? "camera" : "world";
}

static const char *mode_name(obs_depth_mode m)
{
    switch (m) {
    case OBS_DEPTH_INVERSE: return "inverse";
    case OBS_DEPTH_NORMALIZED: return "normalized";
    case OBS_DEPTH_NDC: return "ndc";
    case OBS_DEPTH_RADIAL: return "radial";
    default: return "planar";
    }
}

/* The k-th smallest of d[0..n-1] (Hoare's selection: O(n) on average,
 * where a sort of a 4K frame's depths would cost every frame ~0.5 s);
 * reorders d. */
static double select_kth(double *d, long n, long k)
{
    long lo = 0, hi = n - 1;
    while (lo < hi) {
        double pivot = d[lo + (hi - lo) / 2];
        long i = lo, j = hi;
        while (i <= j) {
            while (d[i] < pivot)
                i++;
            while (d[j] > pivot)
                j--;
            if (i <= j) {
                double t = d[i];
                d[i++] = d[j];
                d[j--] = t;
            }
        }
        if (k <= j)
            hi = j;
        else if (k >= i)
            lo = i;
        else
            break;
    }
    return d[k];
}


/* Distance along the view axis of raw value v under p's depth mode (0:
 * background), as the chain's linear_depth (core/chain/prep_cpu.c) reads
 * it; radial is taken as it is (the range is for orders of magnitude). */
static double metric(double v, const obs_params *p, const float *P)
{
    if (p->depth_mode == OBS_DEPTH_NDC) {
        if (!(v >= 0.0) || v >= 1.0 || !P)
            return !(v >= 0.0) || v >= 1.0 ? 0.0 : v;
        double zn = 2.0 * v - 1.0, z = (P[11] - zn * P[15]) / (zn * P[14] - P[10]);
        return -z > 0.0 && -z < OBS_BACKGROUND_DEPTH ? -z : 0.0;
    }
    if (p->depth_mode == OBS_DEPTH_NORMALIZED && P) {
        double n = (P[15] + P[11]) / (P[10] + P[14]), f = (P[11] - P[15]) / (P[10] - P[14]);
        return planar(v, OBS_DEPTH_NORMALIZED, n, f);
    }
    return planar(v, p->depth_mode == OBS_DEPTH_RADIAL ? OBS_DEPTH_PLANAR : p->depth_mode,
                  0.0, 1.0);
}

/* min, median, max of the r->geometry values at d (reordered). */
static void fill_range(double *d, obs_depth_range *r)
{
    if (r->geometry <= 0)
        return;
    r->min = r->max = d[0];
    for (long i = 1; i < r->geometry; i++) {
        r->min = fmin(r->min, d[i]);
        r->max = fmax(r->max, d[i]);
    }
    r->median = select_kth(d, r->geometry, r->geometry / 2);
}

/* The range over every pixel; the median over every `stride`-th
 * foreground value (1: all of them).  m > 0 holds no NaN, so plain
 * comparisons give fmin's and fmax's min and max. */
static int depth_range(const obs_gbuffer *gb, const obs_params *params, size_t stride, obs_depth_range *r)
{
    obs_params p;
    obs_camera cam;
    char err[OBS_ERR_LEN];
    obs__params_for_gbuffer(params, gb, &p);
    const float *P = obs__camera_resolve(gb, &p, &cam, err) == OBS_OK ? cam.projection : NULL;
    int unit = p.depth_mode == OBS_DEPTH_NDC || p.depth_mode == OBS_DEPTH_NORMALIZED;
    size_t n = (size_t)gb->width * gb->height, kept = 0;
    double *d = malloc((n / stride + 1) * sizeof *d);
    memset(r, 0, sizeof *r);
    if (!d)
        return -1;
    for (int y = 0; y < gb->height; y++)
        for (int x = 0; x < gb->width; x++) {
            double v = *obs__plane_px(&gb->depth, gb->width, x, y);
            double m = metric(v, &p, P);
            if (m > 0.0) {
                r->min = r->geometry == 0 || m < r->min ? m : r->min;
                r->max = r->geometry == 0 || m > r->max ? m : r->max;
                if ((size_t)r->geometry++ % stride == 0)
                    d[kept++] = m;
            }
            /* over 1 and under the background marker: not a 0..1 depth */
            else if (unit && v > 1.0 && v < OBS_BACKGROUND_DEPTH)
                r->impossible++, r->impossible_max = fmax(r->impossible_max, v);
        }
    if (kept > 0)
        r->median = select_kth(d, (long)kept, (long)kept / 2);
    free(d);
    return 0;
}

int obs_gbuffer_depth_range(const obs_gbuffer *gb, const obs_params *params, obs_depth_range *r)
{
    return depth_range(gb, params, 1, r);
}

double obs_radius_suggest(const obs_depth_range *r)
{
    return r->geometry > 0 ? r->median / OBS_RADIUS_FRACTION : 0.0;
}

/* The guards' median is over about this many foreground values, a
 * stride through the frame's (a rank within about 1 / sqrt(N) = 0.4 % of
 * the middle, against a test of three orders of magnitude), so a large
 * frame's check does not select among its every pixel (obscura inspect,
 * obs_gbuffer_depth_range, gives the exact one). */
#define RANGE_SAMPLES 65536

/* Depth that gives no AO at all, and a radius out of scale with it. */
static void depth_guards(const obs_gbuffer *gb, const obs_params *p, obs_exr_info *info,
                         int *added)
{
    obs_depth_range r;
    size_t n = (size_t)gb->width * gb->height;
    if (depth_range(gb, p, n > RANGE_SAMPLES ? n / RANGE_SAMPLES : 1, &r) != 0)
        return;
    if (r.impossible > 0 && r.impossible >= r.geometry)
        warn(info, added, "depth values up to %.4g are impossible under --depth-mode %s (0..1): "
             "%ld of %ld pixels read as background and get AO 1; the depth looks planar: give "
             "--depth-mode planar (or inverse)", r.impossible_max, mode_name(p->depth_mode),
             r.impossible, r.impossible + r.geometry);
    else if (r.geometry == 0)
        warn(info, added, "no geometry: every depth value is background (0, negative, not "
             "finite or over %.0g) under --depth-mode %s, so the AO is 1 everywhere; check the "
             "depth channel (--depth) and --depth-mode", (double)OBS_BACKGROUND_DEPTH,
             mode_name(p->depth_mode));
    if (r.geometry < MIN_PIXELS)
        return;
    if (p->radius < r.median / 1000.0 || p->radius > r.median)
        warn(info, added, "radius %.4g is %s the median depth %.4g (depth %.4g..%.4g): the AO "
             "will be %s; start from --radius %.3g (a tenth of the median depth)", p->radius,
             p->radius > r.median ? "above" : "under 1/1000 of", r.median, r.min, r.max,
             p->radius > r.median ? "dark everywhere" : "near 1 everywhere",
             obs_radius_suggest(&r));
}

int obs_deep_depth_range(const obs_deep_image *d, obs_depth_range *r)
{
    size_t n = (size_t)d->width * d->height;
    double *z = malloc((n ? n : 1) * sizeof *z);
    memset(r, 0, sizeof *r);
    if (!z)
        return -1;
    for (size_t i = 0; i < n; i++)
        if (d->offset[i + 1] > d->offset[i]) { /* sorted: the first is the front */
            double v = planar(d->samples[d->offset[i] * OBS_DEEP_CH + OBS_DEEP_Z],
                              OBS_DEPTH_PLANAR, 0.0, 1.0);
            if (v > 0.0)
                z[r->geometry++] = v;
        }
    fill_range(z, r);
    free(z);
    return 0;
}

int obs_result_sanity(const obs_image *ao, const obs_gbuffer *gb, const obs_deep_image *deep,
                      const obs_params *params, obs_exr_info *info)
{
    obs_params p;
    obs_depth_range range, *r = NULL;
    int added = 0;
    obs__params_for_gbuffer(params, gb, &p);
    if (p.multibounce == OBS_ON && (deep || (gb && !gb->color.data)))
        warn(info, &added, "multibounce on needs a colour plane (the albedo: --color albedo)%s; "
             "the AO is single-bounce", deep ? " of flat input" : " and the input has none");
    if (!ao || !ao->data || ao->channels < 1)
        return added;
    if (gb && gb->width == ao->width && gb->height == ao->height &&
        obs_gbuffer_depth_range(gb, params, &range) == 0)
        r = &range;
    else if (deep && deep->width == ao->width && deep->height == ao->height &&
             obs_deep_depth_range(deep, &range) == 0)
        r = &range;
    long px = (long)ao->width * ao->height, occluded = 0;
    double lost = 0.0;
    for (long i = 0; i < px; i++) {
        double a = ao->data[(size_t)i * ao->channels];
        lost += isfinite(a) ? 1.0 - a : 0.0;
        occluded += a < 1.0 - 1e-4;
    }
    /* The background gets AO 1: the mean is over the geometry. */
    long geometry = r && r->geometry > 0 && r->geometry <= px ? r->geometry : px;
    /* receivers (object masks): the pixels left at 1 by request count by
     * their weight, so the mean is over what was asked for */
    const float *w = gb && gb->width == ao->width && gb->height == ao->height
                         ? gb->receivers.data
                         : deep && deep->width == ao->width && deep->height == ao->height
                               ? deep->receivers
                               : NULL;
    if (w) {
        double sw = 0.0;
        for (long i = 0; i < px; i++)
            sw += w[i];
        geometry = (long)(sw + 0.5);
    }
    double mean = 1.0 - lost / (double)geometry;
    if (geometry < MIN_PIXELS || (occluded > 0 && mean <= AO_HIGH))
        return added;
    char text[120] = "";
    if (r && r->geometry > 0)
        snprintf(text, sizeof text, "; depth %.4g..%.4g, median %.4g", r->min, r->max, r->median);
    char hint[64] = "";
    if (r && r->geometry > 0)
        snprintf(hint, sizeof hint, " (start from --radius %.3g: median depth / %g)",
                 obs_radius_suggest(r), OBS_RADIUS_FRACTION);
    warn(info, &added, "%s (mean %.4f at radius %.4g%s): the radius is small for the scene's "
         "units%s, or --depth-mode is wrong",
         occluded == 0 ? "no pixel is occluded" : "AO is above 0.99 almost everywhere", mean,
         p.radius, text, hint);
    return added;
}

int obs_gbuffer_sanity(const obs_gbuffer *gb, const obs_params *params, obs_exr_info *info)
{
    obs_params p;
    obs_camera cam;
    char err[OBS_ERR_LEN];
    int added = 0;
    obs__params_for_gbuffer(params, gb, &p);
    int w = gb->width, h = gb->height;

    /* depth: every foreground value inside 0..1 (1 included: the far
     * plane of a normalized depth) under a metric mode */
    long valid = 0, unit = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            float v = *obs__plane_px(&gb->depth, w, x, y);
            if (!(v > 0.0f) || v >= OBS_BACKGROUND_DEPTH || !isfinite(v))
                continue;
            valid++;
            unit += v <= 1.0f; /* 1: a normalized depth's far plane */
        }
    depth_guards(gb, &p, info, &added);
    if ((p.depth_mode == OBS_DEPTH_PLANAR || p.depth_mode == OBS_DEPTH_RADIAL) &&
        valid >= MIN_PIXELS && unit == valid)
        warn(info, &added, "depth looks normalized or inverted: all %ld foreground values "
             "lie in 0..1 (depth_mode %s); give --depth-mode inverse, normalized or ndc if it is",
             valid, p.depth_mode == OBS_DEPTH_RADIAL ? "radial" : "planar");
    /* the camera against the position pass */
    char msg[OBS_ERR_LEN];
    if (obs__camera_check_position(gb, &p, msg, sizeof msg))
        warn(info, &added, "%s", msg);
    if (!gb->normal.data)
        return added;

    /* normals: unit length */
    double dev = 0.0;
    long nn = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            const float *n = obs__plane_px(&gb->normal, w, x, y);
            double l = sqrt((double)n[0] * n[0] + (double)n[1] * n[1] + (double)n[2] * n[2]);
            if (!(l > 0.0) || !isfinite(l))
                continue; /* background */
            dev += fabs(l - 1.0);
            nn++;
        }
    if (nn >= MIN_PIXELS && dev / nn > UNIT_TOLERANCE)
        warn(info, &added, "normals are not unit length: mean | |n| - 1 | is %.3g over %.0f pixels "
             "(encoded as 0..1 colours, or not normals?)", dev / nn, (double)nn);

    /* normals against the normals derived from depth.  World-space
     * normals without a world_to_camera cannot be compared (the chain
     * reconstructs them from depth): that cause is said, and the
     * comparison it would make meaningless is not made. */
    if (obs__camera_resolve(gb, &p, &cam, err) != OBS_OK)
        return added;
    if (p.normal_space == OBS_NORMALS_WORLD && !cam.has_world_to_camera) {
        warn(info, &added, "normals are world-space but the camera has no world_to_camera: "
             "they are replaced by normals derived from depth; give --camera FILE or "
             "--world-to-camera M (or --normal-space camera if they are camera-space)");
        return added;
    }
    if (cam.projection[14] != -1.0f ||
        (p.depth_mode != OBS_DEPTH_PLANAR && p.depth_mode != OBS_DEPTH_INVERSE &&
         p.depth_mode != OBS_DEPTH_NORMALIZED))
        return added;
    const float *P = cam.projection;
    double cn = (P[15] + P[11]) / (P[10] + P[14]), cf = (P[11] - P[15]) / (P[10] - P[14]);
    obs_normal_space other = p.normal_space == OBS_NORMALS_CAMERA ? OBS_NORMALS_WORLD
                                                                  : OBS_NORMALS_CAMERA;
    const float *wtc = cam.world_to_camera;
    double here = agreement(gb, P, wtc, p.normal_space, p.depth_mode, cn, cf);
    double there = cam.has_world_to_camera ? agreement(gb, P, wtc, other, p.depth_mode, cn, cf) : -2.0;
    obs_depth_mode alt = p.depth_mode == OBS_DEPTH_INVERSE ? OBS_DEPTH_PLANAR : OBS_DEPTH_INVERSE;
    double inverted = agreement(gb, P, wtc, p.normal_space, alt, cn, cf);
    if (here > -2.0 && here < AGREE_BAD) {
        if (there >= AGREE_GOOD)
            warn(info, &added, "normals look %s-space, not %s-space as the convention says: "
                 "they agree with the normals derived from depth at %.2f (%.2f as given); "
                 "give --normal-space %s if so", space_name(other), space_name(p.normal_space),
                 there, here, space_name(other));
        else if (inverted >= AGREE_GOOD)
            warn(info, &added, "depth looks %s: the normals agree with the normals derived from "
                 "it at %.2f read that way (%.2f as given); give --depth-mode %s if so",
                 alt == OBS_DEPTH_INVERSE ? "inverse (1/Z)" : "planar", inverted, here,
                 alt == OBS_DEPTH_INVERSE ? "inverse" : "planar");
        else
            warn(info, &added, "normals disagree with the normals derived from depth (mean "
                 "cosine %.2f): check the camera, the depth mode and the normal space", here);
    }
    return added;
}
