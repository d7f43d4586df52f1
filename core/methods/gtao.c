/* Method gtao: ground-truth-based ambient occlusion (Jimenez, Wu,
 * Pesce, Jarabo, "Practical real-time strategies for accurate indirect
 * occlusion", SIGGRAPH 2016 course; Algorithm 1), as XeGTAO implements it
 * (GameTechDev/XeGTAO, XeGTAO.hlsli, XeGTAO_MainPass).  The CPU twin of
 * gtao.glsl.
 *
 * GTAO writes the cosine-weighted visibility of the hemisphere around n
 * in slices around the view vector v: a slice of screen direction phi
 * holds the directions at angle theta from v (theta in the slice plane),
 * and with dw = |sin theta| dtheta dphi
 *   A = 1/pi Int_0^pi |n_p| Int_h0^h1 cos(theta - gamma) |sin theta| dtheta dphi,
 * n_p the normal projected onto the slice plane, gamma its angle to v,
 * h0 <= gamma <= h1 the horizon angles on the slice's two sides (found by
 * sampling the depth buffer along the slice within the search radius).
 * The inner integral has the closed form (Algorithm 1's inner
 * integral, XeGTAO's "line ~27")
 *   a(h) = (cos gamma + 2 h sin gamma - cos(2 h - gamma)) / 4,
 *   A_slice = |n_p| (a(h0) + a(h1)),
 * and A is the mean of A_slice over the slices.  Unoccluded, h = gamma
 * -+ pi/2 and A_slice = |n_p| (cos gamma + gamma sin gamma), whose mean
 * over phi is 1.
 *
 * What XeGTAO adds, kept here: the horizon of each side starts at the
 * tangent plane (cos(gamma +- pi/2)) and a sample at distance r moves it
 * only by its falloff weight, saturate(r * falloffMul + falloffAdd); the
 * thin-occluder compensation stretches r's depth component by
 * 1 + gtao_thin before the weight; the steps along a side are
 * s = ((step + noise) / steps)^2 of the screen radius plus 1.3 pixels
 * (XeGTAO's sample distribution power 2 and pixelTooCloseThreshold),
 * rounded to a pixel; the centre is moved towards the camera by 1e-5 of
 * its depth (XeGTAO's value for 32-bit depth); the result is raised to
 * gtao_power.  gtao_heuristics on adds its three empirical corrections:
 * |n_p| moved 5 % towards 1, saturate((10 - r_px) / 100) / 2 added to the
 * slices' sum before the mean (a fade towards open for small screen
 * radii), and the result at least 0.03.
 *
 * Where it differs: the slice and step noise is XeGTAO's R2 sequence on
 * the index of the chain's 3x3 tile (obs__gtao_noise) instead of its
 * Hilbert-curve index, so the chain's blur averages 9 slice offsets; the
 * arc cosines are exact (XeGTAO: a polynomial approximation); depth is
 * read at full resolution (XeGTAO reads a MIP level that grows with the
 * sample's distance); a sample on the background leaves the horizon as it
 * is; a sample outside the image reads the surface continued past the
 * border (chain/border_cpu.c: the tangent plane of the last pixel on the
 * segment from the shaded pixel, exact for an open plane and for a crease
 * through the shaded point; XeGTAO's clamp sampler repeats the border
 * pixel instead, and counting it open lightened creases at the border);
 * the view vector of an orthographic camera is +z. */
#include <math.h>

#include "chain/lanes.h"
#include "methods/bent.h"
#include "chain/mask_weight.h"
#include "methods/gtao.h"
#include "methods/gtao_deep.h"

/* XeGTAO_MainPass's constants (XeGTAO.hlsli, XeGTAO.h) */
#define GTAO_MIN_VISIBILITY 0.03f /* visibility = max(0.03, visibility) */

static float clampf(float v, float lo, float hi) { return fminf(fmaxf(v, lo), hi); }
static float saturate(float v) { return clampf(v, 0.0f, 1.0f); }
static float signf(float v) { return (float)((v > 0.0f) - (v < 0.0f)); }
static float dot3(const float a[3], const float b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* GLSL: gtao_noise() in gtao.glsl; tile: the pixel's obs__tile_index */
void obs__gtao_noise(int tile, float out[2])
{
    float k = (float)tile;
    float a = 0.5f + k * 0.75487766624669276f, b = 0.5f + k * 0.56984029099805327f;
    out[0] = a - floorf(a);
    out[1] = b - floorf(b);
}

/* GLSL: the branch of gtao_side_horizon() for a step at pixel (qx, qy)
 * off the planes: the surface continued past the border
 * (chain/border_cpu.c), in ext; NULL (the horizon stays) where that is
 * background or there is no estimate.  *taken counts the steps that read
 * the surface or background. */
static const float *border_step(const obs__frame *f, const float *pos, const float *nrm, int x,
                                int y, int qx, int qy, float ext[4], int *taken)
{
    float nz;
    int got = obs__border_point(f, pos, nrm, x, y, (float)qx, (float)qy, ext, &nz, NULL);
    if (got >= 0)
        (*taken)++;
    return got > 0 ? ext : NULL;
}

/* The horizon cosine of one sample point q (view xyz, planar depth w; w
 * 0: background) for the centre c: its cosine to v moved from the
 * tangent's `low` by its falloff weight times om, the object masks'
 * weight of its pixel (obs__occluder_weight); low where it adds nothing. */
static float sample_cos(const obs__gtao_state *g, const float q[4], const float c[3],
                        const float v[3], float low, float om)
{
    if (!(q[3] > 0.0f))
        return low;
    float d[3] = {q[0] - c[0], q[1] - c[1], q[2] - c[2]};
    float dist = sqrtf(dot3(d, d));
    if (!(dist > 0.0f))
        return low;
    float shc = dot3(d, v) / dist;
    float dz = d[2] * (1.0f + g->thin_power[0]); /* thin-occluder compensation */
    float fb = sqrtf(d[0] * d[0] + d[1] * d[1] + dz * dz);
    float w = saturate(fb * g->falloff[0] + g->falloff[1]) * om; /* om: object masks */
    return low + (shc - low) * w; /* lerp(lowHorizonCos, shc, weight) */
}

const float *obs__gtao_border_step(const obs__frame *f, const float *pos, const float *nrm,
                                   int self, int x, int y, int qx, int qy, const float c[3],
                                   const float v[3], float low, float *hc, int *taken,
                                   float ext[4])
{
    const float *q = border_step(f, pos, nrm, x, y, qx, qy, ext, taken);
    if (q)
        *hc = fmaxf(*hc, sample_cos(obs__gtao_of(f), q, c, v, low,
                                    obs__occluder_weight_node(f, x, y, self, qx, qy, 0)));
    return q;
}

/* Deep input with intervals: a step's column reads its pixel's node in
 * each of the `layers` planes, megabytes apart, and waited on memory for
 * them (on dining a third of obs__gtao_column's time on its first read);
 * the steps' pixels are known before, so their nodes and interval ends
 * are fetched GTAO_PREFETCH steps ahead. */
#define GTAO_PREFETCH 4

#if defined(__GNUC__)
/* always inline: gcc takes a function of prefetches alone for one
 * without effects and drops its calls */
static inline __attribute__((always_inline)) void prefetch_column(const obs__frame *f,
                                                                  const float *pos,
                                                                  const float *end, int layers,
                                                                  const int q[2])
{
    if (q[0] < 0 || q[1] < 0 || q[0] >= f->width || q[1] >= f->height)
        return;
    const size_t npx = (size_t)f->width * (size_t)f->height;
    const size_t i = (size_t)q[1] * (size_t)f->width + (size_t)q[0];
    for (int k = 0; k < layers; k++) {
        __builtin_prefetch(pos + 4 * ((size_t)k * npx + i));
        __builtin_prefetch(end + (size_t)k * npx + i);
    }
}
#else
static void prefetch_column(const obs__frame *f, const float *pos, const float *end, int layers,
                            const int q[2])
{
    (void)f, (void)pos, (void)end, (void)layers, (void)q;
}
#endif

/* The horizon cosine of side `dir` (+1 or -1) of a slice after its
 * steps: the largest of the tangent's cosine `low` and the samples',
 * each moved from low by its falloff weight.  A step inside the image
 * reads every one of the `layers` planes of pos (deep input's nodes,
 * OITAO Algorithm 1: the largest counts); past the border, the front
 * plane's surface continued.  end (NULL: none): deep input's interval
 * ends (obs__deep_intervals); each step is then a column of the side's
 * free arcs (obs__gtao_column, gtao_deep.c), the nodes solid behind them
 * giving the horizon as here. */
static float side_horizon(const obs__frame *f, const float *pos, const float *nrm, int layers,
                          int self, int x, int y, const float c[3], const float v[3], const float omega[2],
                          int slice, float noise_step, float min_s, int dir, float low,
                          int *taken, const float *end, obs__gtao_side *side)
{
    const obs__gtao_state *g = obs__gtao_of(f);
    const size_t plane = (size_t)f->width * (size_t)f->height * 4;
    const float fw[3] = {g->falloff[0], g->falloff[1], g->thin_power[0]}; /* intervals */
    float hc = low;
    int sq[32][2]; /* the steps' pixels (gtao_steps <= 32, the parameter table) */
    for (int st = 0; st < g->steps; st++) {
        float base = (float)(slice + st * g->steps) * GTAO_R1;
        float sn = noise_step + base;
        sn -= floor_lane(sn); /* floorf's value, inline (lanes.h) */
        float s = ((float)st + sn) / (float)g->steps;
        s = s * s + min_s; /* sample distribution power 2, then off the centre pixel */
        sq[st][0] = x + dir * (int)floor_lane(s * omega[0] + 0.5f);
        sq[st][1] = y + dir * (int)floor_lane(s * omega[1] + 0.5f);
    }
    for (int st = 0; end && st < GTAO_PREFETCH && st < g->steps; st++)
        prefetch_column(f, pos, end, layers, sq[st]);
    for (int st = 0; st < g->steps; st++) {
        const int qx = sq[st][0], qy = sq[st][1];
        float ext[4];
        const float *q;
        if (end && st + GTAO_PREFETCH < g->steps)
            prefetch_column(f, pos, end, layers, sq[st + GTAO_PREFETCH]);
        /* object masks: the weight of the surface at the step's pixel
         * (of each node there; past the border, of the front one) */
        if (qx < 0 || qy < 0 || qx >= f->width || qy >= f->height) {
            q = obs__gtao_border_step(f, pos, nrm, self, x, y, qx, qy, c, v, low, &hc, taken,
                                      ext);
            if (end) /* intervals: the surface continued, solid behind it */
                obs__gtao_column(f, fw, side, q, NULL, 0, q ? 1 : 0, x, y, self, qx, qy, c, v,
                                 low);
            continue;
        }
        (*taken)++;
        q = pos + 4 * ((size_t)qy * (size_t)f->width + (size_t)qx);
        if (end) { /* intervals: the step's column (gtao_deep.c) */
            hc = fmaxf(hc, obs__gtao_column(f, fw, side, q, end + (size_t)qy * f->width + qx,
                                            plane, layers, x, y, self, qx, qy, c, v, low));
            continue;
        }
        for (int k = 0; k < layers; k++)
            hc = fmaxf(hc, sample_cos(g, q + (size_t)k * plane, c, v, low,
                                      obs__occluder_weight_node(f, x, y, self, qx, qy, k)));
    }
    return hc;
}

/* GLSL: method_ao() in gtao.glsl */
float obs__gtao_pixel(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                      const float p[3], const float n[3], int *count)
{
    return obs__gtao_pixel_bent(f, pos, nrm, x, y, p, n, count, NULL);
}

float obs__gtao_pixel_bent(const obs__frame *f, const float *pos, const float *nrm, int x, int y,
                           const float p[3], const float n[3], int *count, float bent[3])
{
    return obs__gtao_pixel_nodes(f, pos, nrm, 1, 0, NULL, x, y, p, n, count, bent);
}

float obs__gtao_pixel_nodes(const obs__frame *f, const float *pos, const float *nrm, int layers,
                            int self, const float *end, int x, int y, const float p[3],
                            const float n[3], int *count, float bent[3])
{
    const obs__gtao_state *g = obs__gtao_of(f);
    const float half_pi = (float)M_PI_2;
    int taken = 0;
    if (count)
        *count = 0;
    float rpx = obs__radius_px(f, p, g->radius);
    if (!(rpx > 0.0f))
        return 1.0f; /* behind the camera */
    float c[3] = {p[0] * GTAO_CENTRE_SCALE, p[1] * GTAO_CENTRE_SCALE, p[2] * GTAO_CENTRE_SCALE};
    float v[3] = {0.0f, 0.0f, 1.0f}; /* towards the camera; orthographic: +z */
    if (f->proj[14] != 0.0f) {
        float l = sqrtf(dot3(c, c));
        if (!(l > 0.0f))
            return 1.0f;
        v[0] = -c[0] / l;
        v[1] = -c[1] / l;
        v[2] = -c[2] / l;
    }
    float noise[2];
    obs__gtao_noise(obs__tile_index(f, x, y), noise);
    const float min_s = GTAO_TOO_CLOSE / rpx;
    float vis = obs__gtao_vis0(g, rpx);
    for (int sl = 0; sl < g->slices; sl++) {
        float cs[2];
        obs__gtao_slice_dir(g, sl, noise[0], cs);
        const float cp = cs[0], sp = cs[1];
        float omega[2] = {cp * rpx, -sp * rpx}; /* screen pixels: y runs down, view y up */
        float d[3] = {cp, sp, 0.0f};
        float dv = dot3(d, v);
        float od[3] = {d[0] - dv * v[0], d[1] - dv * v[1], d[2] - dv * v[2]};
        /* the slice plane's normal: normalize(cross(od, v)) */
        float ax[3] = {od[1] * v[2] - od[2] * v[1], od[2] * v[0] - od[0] * v[2],
                       od[0] * v[1] - od[1] * v[0]};
        float al = sqrtf(dot3(ax, ax));
        ax[0] /= al;
        ax[1] /= al;
        ax[2] /= al;
        float na = dot3(n, ax);
        float np[3] = {n[0] - ax[0] * na, n[1] - ax[1] * na, n[2] - ax[2] * na};
        float np_len = sqrtf(dot3(np, np));
        float cos_g = np_len > 0.0f ? saturate(dot3(np, v) / np_len) : 1.0f;
        float gamma = signf(dot3(od, np)) * acosf(cos_g);
        float low0 = cosf(gamma + half_pi), low1 = cosf(gamma - half_pi);
        obs__gtao_side sides[2]; /* deep input's intervals: the sides' occupied arcs */
        if (end) { /* the receiver's column: free from the surface in front of it */
            const size_t px = (size_t)y * (size_t)f->width + (size_t)x;
            const float z0 = obs__gtao_centre_start(pos + 4 * px, end + px,
                                                    (size_t)f->width * (size_t)f->height * 4, self);
            obs__gtao_side_start(&sides[0], c, z0);
            obs__gtao_side_start(&sides[1], c, z0);
        }
        float hc0 = side_horizon(f, pos, nrm, layers, self, x, y, c, v, omega, sl, noise[1], min_s, 1,
                                 low0, &taken, end, &sides[0]);
        float hc1 = side_horizon(f, pos, nrm, layers, self, x, y, c, v, omega, sl, noise[1], min_s, -1,
                                 low1, &taken, end, &sides[1]);
        if (g->heuristics)
            np_len += (1.0f - np_len) * GTAO_SLOPE_FUDGE;
        /* the horizons as angles from v, clamped to the hemisphere of n
         * (Algorithm 1's h1 = n + max(h1 - n, -pi/2), h2 = n + min(h2 - n, pi/2)) */
        float h0 = -acosf(clampf(hc1, -1.0f, 1.0f));
        float h1 = acosf(clampf(hc0, -1.0f, 1.0f));
        h0 = gamma + fmaxf(h0 - gamma, -half_pi);
        h1 = gamma + fminf(h1 - gamma, half_pi);
        if (end) /* the free arcs between the horizons (gtao_deep.c) */
            vis += np_len * obs__gtao_slice_free(&sides[0], &sides[1], h0, h1, gamma, cos_g);
        else
            vis += np_len * (obs__gtao_arc(h0, gamma, cos_g) + obs__gtao_arc(h1, gamma, cos_g));
        if (bent)
            obs__gtao_bent_slice(h0, h1, gamma, np_len, od, v, bent);
    }
    if (count)
        *count = taken;
    return obs__gtao_finish(g, vis);
}

void obs__gtao_slice_dir(const obs__gtao_state *g, int sl, float noise0, float cs[2])
{
    float phi = ((float)sl + noise0) / (float)g->slices * (float)M_PI;
    cs[0] = cosf(phi);
    cs[1] = sinf(phi);
}

float obs__gtao_vis0(const obs__gtao_state *g, float rpx)
{
    return g->heuristics ? saturate((10.0f - rpx) / 100.0f) * 0.5f : 0.0f;
}

float obs__gtao_finish(const obs__gtao_state *g, float vis)
{
    vis /= (float)g->slices;
    vis = powf(fmaxf(vis, 0.0f), g->thin_power[1]);
    if (g->heuristics)
        vis = fmaxf(vis, GTAO_MIN_VISIBILITY);
    return saturate(vis);
}

void obs__gtao_setup(const obs_params *p, obs__frame *f)
{
    obs__gtao_state *s = (obs__gtao_state *)(void *)f->ms.bytes;
    s->slices = p->gtao_slices;
    s->steps = p->gtao_steps;
    s->heuristics = p->gtao_heuristics == OBS_ON;
    /* XeGTAO: effectRadius = EffectRadius * RadiusMultiplier; the falloff
     * range is EffectFalloffRange * effectRadius, and a sample at
     * distance r weighs saturate(r * falloffMul + falloffAdd), 1 up to
     * falloffFrom = effectRadius (1 - EffectFalloffRange), 0 at the
     * radius */
    float R = f->radius * p->gtao_radius_multiplier, range = p->gtao_falloff * R;
    s->radius = R;
    s->falloff[0] = -1.0f / range;
    s->falloff[1] = R * (1.0f - p->gtao_falloff) / range + 1.0f;
    s->thin_power[0] = p->gtao_thin;
    s->thin_power[1] = p->gtao_power;
}
