/* The level's BVH and single rays (level.h): points in space rather than
 * on the surface, for the dynamic-object bake's regions and probes and the
 * instanced decorators' volume.  The same scene as the vertex bake's trace
 * builds (occl.c). */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "level/level.h"
#include "level/occl.h"

#define PACKET 8 /* rays per rtcIntersect8 packet */


/* ---- the level's BVH and single rays, for the dynamic-object bake ------
 * (dynamic/: dyn_probes.c, dyn_regions.c, dyn_measure.c: points in space rather than on the
 * surface).  The same scene as obs__bake_trace builds; kept beside it. */
struct obs__bake_bvh {
    obs__bake_occl *occl; /* every triangle opaque, or with decorators */
    RTCScene rtc;
    const obs__bake_world *w;
};

obs_status obs__bake_bvh_new(const obs__bake_world *w, obs__bake_bvh **out,
                             char err[OBS_ERR_LEN])
{
    return obs__bake_bvh_new_decor(w, NULL, 0.0f, out, err);
}

obs_status obs__bake_bvh_new_decor(const obs__bake_world *w, const struct obs__bake_decor *d,
                                   float tree_attenuation, obs__bake_bvh **out,
                                   char err[OBS_ERR_LEN])
{
    *out = NULL;
    obs__bake_bvh *b = calloc(1, sizeof *b);
    if (!b)
        return obs__fail(err, OBS_NO_MEMORY, "BVH");
    b->w = w;
    obs_status st = obs__bake_occl_new(w, d, tree_attenuation, &b->occl, err);
    if (st != OBS_OK) {
        free(b);
        return st;
    }
    b->rtc = b->occl->opaque;
    *out = b;
    return OBS_OK;
}

void obs__bake_bvh_free(obs__bake_bvh *b)
{
    if (!b)
        return;
    obs__bake_occl_free(b->occl);
    free(b);
}

void obs__bake_bvh_cast(const obs__bake_bvh *b, const float o[3], const float *dirs, int n,
                        float tfar, float *t, uint8_t *back, float *trans)
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    const obs__bake_world *w = b->w;
    for (int k0 = 0; k0 < n; k0 += PACKET) {
        RTC_ALIGN(32) struct RTCRayHit8 rh;
        RTC_ALIGN(32) int valid[PACKET];
        for (int l = 0; l < PACKET; l++) {
            int k = k0 + l < n ? k0 + l : n - 1;
            valid[l] = k0 + l < n ? -1 : 0;
            obs__bake_ray8_lane(&rh, l, o, dirs + 3 * k, tfar);
        }
        rtcIntersect8(valid, b->rtc, &ctx, &rh);
        if (trans) { /* section 2.1: the segment up to the opaque hit (tfar on a miss) */
            double tr[PACKET];
            obs__bake_occl_transmittance8(b->occl, valid, &rh, tr);
            for (int l = 0; l < PACKET && k0 + l < n; l++)
                trans[k0 + l] = (float)tr[l];
        }
        for (int l = 0; l < PACKET && k0 + l < n; l++) {
            int k = k0 + l;
            if (rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID) {
                t[k] = INFINITY;
                back[k] = 0;
                continue;
            }
            t[k] = rh.ray.tfar[l];
            /* with decorators the opaque scene lists a subset: its world triangle */
            size_t pr = b->occl->opaque_tri ? b->occl->opaque_tri[rh.hit.primID[l]]
                                            : rh.hit.primID[l];
            const float *hn = w->fn + 3 * pr;
            back[k] = !w->two_sided[pr] && hn[0] * rh.ray.dir_x[l] + hn[1] * rh.ray.dir_y[l] +
                                                   hn[2] * rh.ray.dir_z[l] >
                                               0.0f;
        }
    }
}

int obs__bake_bvh_occluded(const obs__bake_bvh *b, const float a[3], const float c[3])
{
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    float d[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    float len = sqrtf(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (len <= 0.0f)
        return 0;
    struct RTCRay r = {a[0], a[1], a[2], 0.0f, d[0] / len, d[1] / len, d[2] / len, 0.0f,
                       len, 0xffffffffu, 0, 0};
    rtcOccluded1(b->rtc, &ctx, &r);
    return r.tfar < 0.0f; /* Embree sets tfar to -inf on a hit */
}
