/* Method hbao: horizon-based ambient occlusion (Bavoil, Sainz, Dimitrov,
 * "Image-space horizon-based ambient occlusion", SIGGRAPH 2008 talk; the
 * baseline of shared/papers/oitao-abuffer-ssao.txt).  The CPU twin of
 * hbao.glsl.
 *
 * HBAO integrates, over the directions theta around the view axis, the
 * occlusion between the tangent plane and the horizon:
 *   AO = 1 - 1/(2 pi) Int (sin h(theta) - sin t(theta)) W(theta) dtheta,
 * t(theta) the elevation of the tangent in direction theta (plus an angle
 * bias against the self-occlusion of tessellated surfaces), h(theta) the
 * horizon elevation found by ray marching the depth buffer in screen
 * space.  With per-sample attenuation each step that raises the horizon
 * adds W(r_i) (sin h_i - sin h_(i-1)), W(r) = 1 - r^2 / R^2, r the
 * distance of the sample; samples at r >= R are left out.  Nd directions
 * (the 3x3 tile's rotation as the jitter), Ns steps of R_px / (Ns + 1)
 * pixels each, R_px the radius projected at p (at most R_px steps). */
#include <math.h>

#include "methods/bent.h"
#include "chain/mask_weight.h"
#include "methods/hbao.h"

/* One sample point q (view xyz, planar depth w; w 0: background) of a
 * direction from p: where it rises above the horizon sin_h, W(r) times
 * the rise into *ao and the horizon raised (GLSL: hbao_sample()); with
 * bent, the occluded span taken from the bent normal (direction dx, dy);
 * all times om, the object masks' weight of its pixel (0: no horizon
 * raised). */
static void hbao_sample(const float q[4], const float p[3], float R2, float om, float *sin_h,
                        float *ao, float dx, float dy, float *bent)
{
    if (!(q[3] > 0.0f))
        return;
    float v[3] = {q[0] - p[0], q[1] - p[1], q[2] - p[2]};
    float r2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if (!(r2 < R2) || !(r2 > 0.0f))
        return;
    float sin_s = v[2] / sqrtf(r2); /* elevation of the sample: view +z faces the camera */
    if (sin_s > *sin_h && om > 0.0f) { /* om 0 (object masks): it raises no horizon */
        *ao += om * (1.0f - r2 / R2) * (sin_s - *sin_h); /* W(r_i) (sin h_i - sin h_(i-1)) */
        if (bent) /* OBS_OUTPUT_BENT: less the step's occluded span */
            obs__hbao_bent_span(dx, dy, *sin_h, sin_s, -om * (1.0f - r2 / R2), bent);
        *sin_h = sin_s;
    }
}

static float hbao_estimate(const obs__frame *f, const float *pos, int layers, int self, int x,
                           int y, const float p[3], const float n[3], int *count, float bent[3]);

/* GLSL: hbao_ao() in hbao.glsl */
float obs__hbao_pixel(const obs__frame *f, const float *pos, int x, int y, const float p[3],
                      const float n[3], int *count)
{
    return obs__hbao_pixel_nodes(f, pos, 1, 0, x, y, p, n, count);
}

float obs__hbao_pixel_bent(const obs__frame *f, const float *pos, int x, int y, const float p[3],
                           const float n[3], int *count, float bent[3])
{
    return hbao_estimate(f, pos, 1, 0, x, y, p, n, count, bent);
}

float obs__hbao_pixel_nodes(const obs__frame *f, const float *pos, int layers, int self, int x,
                            int y, const float p[3], const float n[3], int *count)
{
    return hbao_estimate(f, pos, layers, self, x, y, p, n, count, NULL);
}

/* obs__hbao_pixel_nodes that also sums the bent normal into bent[3]
 * (NULL: not wanted; obs__hbao_bent_span, bent.c). */
static float hbao_estimate(const obs__frame *f, const float *pos, int layers, int self, int x,
                           int y, const float p[3], const float n[3], int *count, float bent[3])
{
    const size_t plane = (size_t)f->width * (size_t)f->height * 4;
    const obs__hbao_state *hb = obs__hbao_of(f);
    const float R = f->radius, R2 = R * R;
    const float *rot = f->rot[obs__tile_index(f, x, y)];
    float rpx = obs__radius_px(f, p, R);
    if (count)
        *count = 0;
    if (!(rpx >= 1.0f))
        return 1.0f; /* the kernel reaches no other pixel */
    int ns = hb->steps < (int)rpx ? hb->steps : (int)rpx;
    float step = rpx / (float)(ns + 1); /* the farthest sample is not fully attenuated */
    float ao = 0.0f;
    int taken = 0;
    for (int d = 0; d < hb->dirs; d++) {
        const float *e = hb->dir[d];
        float dx = rot[0] * e[0] - rot[1] * e[1], dy = rot[1] * e[0] + rot[0] * e[1];
        /* t(theta): the tangent (n . T = 0, T.xy = (dx, dy)) rises by
         * -(n.x dx + n.y dy) / n.z per unit; its sine and cosine, then
         * t + bias by the angle sum (sin 1 from t + bias >= pi/2 on). */
        float nd = n[0] * dx + n[1] * dy, nz = fmaxf(n[2], 0.0f);
        float l = sqrtf(nd * nd + nz * nz);
        float st = l > 0.0f ? -nd / l : 0.0f, ct = l > 0.0f ? nz / l : 1.0f;
        float sin_h = st * hb->bias_cs[0] + ct * hb->bias_cs[1];
        if (ct * hb->bias_cs[0] - st * hb->bias_cs[1] < 0.0f)
            sin_h = 1.0f;
        if (bent) /* OBS_OUTPUT_BENT: open from the tangent up to the view axis */
            obs__hbao_bent_span(dx, dy, sin_h, 1.0f, 1.0f, bent);
        for (int j = 1; j <= ns; j++) {
            /* screen y runs down, view y up */
            int qx = x + (int)floorf(dx * step * (float)j + 0.5f);
            int qy = y + (int)floorf(-dy * step * (float)j + 0.5f);
            if (qx < 0 || qy < 0 || qx >= f->width || qy >= f->height)
                break;
            taken++;
            const float *q = pos + 4 * ((size_t)qy * (size_t)f->width + (size_t)qx);
            /* deep input: every node, front to back, each times the
             * object masks' weight of its surface */
            for (int k = 0; k < layers; k++)
                hbao_sample(q + (size_t)k * plane, p, R2,
                            obs__occluder_weight_node(f, x, y, self, qx, qy, k), &sin_h, &ao, dx,
                            dy, bent);
        }
    }
    if (count)
        *count = taken;
    return fmaxf(0.0f, 1.0f - ao / (float)hb->dirs);
}

void obs__hbao_setup(const obs_params *p, obs__frame *f)
{
    obs__hbao_state *s = (obs__hbao_state *)(void *)f->ms.bytes;
    s->dirs = p->hbao_directions;
    s->steps = p->hbao_steps;
    for (int d = 0; d < s->dirs; d++) { /* HBAO: Nd directions over 2 pi */
        double a = 2.0 * M_PI * d / s->dirs;
        s->dir[d][0] = (float)cos(a);
        s->dir[d][1] = (float)sin(a);
    }
    s->bias_cs[0] = (float)cos(p->hbao_angle_bias * M_PI / 180.0);
    s->bias_cs[1] = (float)sin(p->hbao_angle_bias * M_PI / 180.0);
}
