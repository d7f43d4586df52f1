/* The ray-traced AO reference (reference.h): Embree 3 for the rays,
 * rows over the worker pool (pool.c), a counter-based random stream per
 * pixel so that the image depends on the seed alone. */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "level/occl.h"
#include "ground/reference_internal.h"
#include "internal.h"
#include "obscura/reference.h"
#include "pool.h"

#define DEFAULT_SPP 256
#define MAX_SPP (1 << 20)
#define PI_F 3.14159265358979f
/* Surfaces one ray may cross in a scene with opacities. */
#define MAX_CROSSINGS 256

/* ---- random numbers: PCG32 (O'Neill 2014, pcg32_random_r) --------------- */

typedef struct pcg32 {
    uint64_t state, inc;
} pcg32;

static uint32_t pcg32_next(pcg32 *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ULL + r->inc;
    uint32_t xs = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xs >> rot) | (xs << ((-rot) & 31u));
}

/* SplitMix64's finaliser: decorrelates the seeds of neighbouring pixels. */
static uint64_t mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ULL;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* One stream per pixel (pcg32_srandom_r with the pixel as sequence). */
static void pcg32_seed(pcg32 *r, uint64_t seed, uint64_t pixel)
{
    r->state = 0;
    r->inc = (pixel << 1u) | 1u;
    pcg32_next(r);
    r->state += mix64(seed);
    pcg32_next(r);
}

static float uniform01(pcg32 *r)
{
    return (float)(pcg32_next(r) >> 8) * (1.0f / 16777216.0f); /* [0, 1) */
}

/* ---- vectors ----------------------------------------------------------- */

static float dot3(const float a[3], const float b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static int normalize3(float v[3])
{
    float len = sqrtf(dot3(v, v));
    if (!(len > 1e-20f) || !isfinite(len))
        return -1;
    for (int k = 0; k < 3; k++)
        v[k] /= len;
    return 0;
}

/* An orthonormal basis around unit n: Duff et al. 2017, "Building an
 * Orthonormal Basis, Revisited", Listing 3. */
static void onb(const float n[3], float t[3], float b[3])
{
    float sign = copysignf(1.0f, n[2]);
    float a = -1.0f / (sign + n[2]);
    float c = n[0] * n[1] * a;
    t[0] = 1.0f + sign * n[0] * n[0] * a;
    t[1] = sign * c;
    t[2] = -sign * n[0];
    b[0] = c;
    b[1] = sign + n[1] * n[1] * a;
    b[2] = -n[1];
}

/* A cosine-weighted direction around n (Malley's method: a uniform point
 * on the unit disk lifted to the hemisphere; pdf cos(theta)/pi, Pharr et
 * al., PBRT 3rd ed., 13.6.3). */
static void cosine_dir(const float n[3], const float t[3], const float b[3], float u1, float u2,
                       float d[3])
{
    float r = sqrtf(u1), phi = 2.0f * PI_F * u2;
    float x = r * cosf(phi), y = r * sinf(phi), z = sqrtf(fmaxf(0.0f, 1.0f - u1));
    for (int k = 0; k < 3; k++)
        d[k] = x * t[k] + y * b[k] + z * n[k];
}

/* ---- the job ----------------------------------------------------------- */

typedef struct job {
    const obs_scene *scene;
    RTCScene rtc;
    const obs_reference_view *view;
    obs_reference_desc desc;
    int width, height;
    float clip_to_world[16];
    float eye[4]; /* camera position (w 1) or direction towards it (w 0) */
    float *ao, *depth;
    obs__obscurance ob; /* obscurance mode */
} job;

static void init_ray(struct RTCRay *r, const float o[3], const float d[3], float tfar)
{
    r->org_x = o[0];
    r->org_y = o[1];
    r->org_z = o[2];
    r->dir_x = d[0];
    r->dir_y = d[1];
    r->dir_z = d[2];
    r->tnear = 0.0f;
    r->tfar = tfar;
    r->time = 0.0f;
    r->mask = 0xffffffffu;
    r->id = 0;
    r->flags = 0;
}

/* A ray Embree takes (it asserts so): finite, its origin within the
 * scenes' bound (far within Embree's 1.844e18). */
static int ray_ok(const float o[3], const float d[3])
{
    for (int k = 0; k < 3; k++)
        if (!isfinite(o[k]) || !isfinite(d[k]))
            return 0;
    return !obs_scene_coord_beyond(o) && (d[0] != 0.0f || d[1] != 0.0f || d[2] != 0.0f);
}

/* The world-space ray through the centre of pixel (x, y): the points at
 * NDC z = -1 and z = 1 unprojected (valid for any projection). */
static void camera_ray(const job *j, int x, int y, float o[3], float d[3])
{
    float ndc_x = ((float)x + 0.5f) / (float)j->width * 2.0f - 1.0f;
    float ndc_y = 1.0f - ((float)y + 0.5f) / (float)j->height * 2.0f;
    float a[4] = {ndc_x, ndc_y, -1.0f, 1.0f}, b[4] = {ndc_x, ndc_y, 1.0f, 1.0f}, pa[4], pb[4];
    obs__mat4_apply(j->clip_to_world, a, pa);
    obs__mat4_apply(j->clip_to_world, b, pb);
    for (int k = 0; k < 3; k++) {
        o[k] = pa[k] / pa[3];
        d[k] = pb[k] / pb[3] - o[k];
    }
    normalize3(d);
}

/* The surface point of a hit of the ray o + t d, its shading normal n and
 * geometric normal ng, both facing the ray's origin.  0 for a degenerate
 * triangle. */
static int hit_point(const job *j, const float o[3], const float d[3], const struct RTCRayHit *rh,
                     float p[3], float n[3], float ng[3])
{
    for (int k = 0; k < 3; k++)
        p[k] = o[k] + rh->ray.tfar * d[k];
    ng[0] = rh->hit.Ng_x;
    ng[1] = rh->hit.Ng_y;
    ng[2] = rh->hit.Ng_z;
    if (normalize3(ng) != 0)
        return 0; /* a degenerate triangle */
    /* Seen from the back: both normals flip, as a path tracer's do. */
    float flip = dot3(ng, d) > 0.0f ? -1.0f : 1.0f;
    for (int k = 0; k < 3; k++)
        ng[k] *= flip;
    memcpy(n, ng, 3 * sizeof(float));
    const obs_scene *s = j->scene;
    if (s->normals) {
        const uint32_t *tri = s->indices + 3 * (size_t)rh->hit.primID;
        float w[3] = {1.0f - rh->hit.u - rh->hit.v, rh->hit.u, rh->hit.v}, sn[3] = {0, 0, 0};
        int against = 0;
        for (int c = 0; c < 3; c++) {
            const float *vn = s->normals + 3 * (size_t)tri[c];
            against += dot3(vn, ng) * flip < 0.0f;
            for (int k = 0; k < 3; k++)
                sn[k] += w[c] * vn[k];
        }
        /* A triangle whose three normals all lie on the other side of it
         * than the one seen (normals that disagree with the winding) has
         * them turned to face the viewer, as the --gbuffer points' are:
         * around them every cosine ray would lie below the surface, AO 0. */
        float side = against == 3 ? -flip : flip;
        if (normalize3(sn) == 0)
            for (int k = 0; k < 3; k++)
                n[k] = side * sn[k];
    }
    return 1;
}

/* The closest hit of o + t d with tnear < t < tfar; 0 when none. */
static int intersect(const job *j, struct RTCIntersectContext *ictx, const float o[3],
                     const float d[3], float tnear, float tfar, struct RTCRayHit *rh)
{
    init_ray(&rh->ray, o, d, tfar);
    rh->ray.tnear = tnear;
    rh->hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh->hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(j->rtc, ictx, rh);
    return rh->hit.geomID != RTC_INVALID_GEOMETRY_ID;
}

/* The surface point of pixel (x, y), its shading normal n and geometric
 * normal ng, both facing the viewer.  0 when there is none. */
static int surface_point(const job *j, struct RTCIntersectContext *ictx, int x, int y,
                         float p[3], float n[3], float ng[3])
{
    const obs_reference_view *v = j->view;
    if (v->position) {
        const float *pp = v->position->data + ((size_t)y * j->width + x) * v->position->channels;
        const float *nn = v->normal->data + ((size_t)y * j->width + x) * v->normal->channels;
        float to_eye[3];
        for (int k = 0; k < 3; k++) {
            p[k] = pp[k];
            n[k] = nn[k];
        }
        /* background: a non-finite point, one beyond the scenes' bound
         * (no ray can start there), a zero normal */
        if (!isfinite(p[0]) || !isfinite(p[1]) || !isfinite(p[2]) ||
            obs_scene_coord_beyond(p) || normalize3(n) != 0)
            return 0;
        for (int k = 0; k < 3; k++)
            to_eye[k] = j->eye[3] != 0.0f ? j->eye[k] - p[k] : j->eye[k];
        if (dot3(n, to_eye) < 0.0f)
            for (int k = 0; k < 3; k++)
                n[k] = -n[k];
        memcpy(ng, n, 3 * sizeof(float));
        return 1;
    }

    float o[3], d[3];
    camera_ray(j, x, y, o, d);
    if (!ray_ok(o, d)) /* the corners' were checked: rounding between them */
        return 0;
    struct RTCRayHit rh;
    if (!intersect(j, ictx, o, d, 0.0f, INFINITY, &rh))
        return 0;
    return hit_point(j, o, d, &rh, p, n, ng);
}

/* How far past a hit the next search starts, and an AO ray's origin is
 * lifted off its surface: scales with the coordinates (float spacing). */
static float surface_eps(const float p[3])
{
    return 1e-4f * fmaxf(1.0f, fmaxf(fabsf(p[0]), fmaxf(fabsf(p[1]), fabsf(p[2]))));
}

/* Transmittance of the segment o + t d, 0 < t < tfar (reference.h): 0 or
 * 1 for an opaque scene; with opacities, the product of (1 - alpha) over
 * the surfaces it crosses, found by searching again just past each hit
 * (at most MAX_CROSSINGS; a segment crossing more counts as blocked). */
static float transmittance(const job *j, struct RTCIntersectContext *ictx, const float o[3],
                           const float d[3], float tfar)
{
    const float *opacity = j->scene->opacity;
    if (!opacity) {
        struct RTCRay r;
        init_ray(&r, o, d, tfar);
        rtcOccluded1(j->rtc, ictx, &r);
        return r.tfar >= 0.0f ? 1.0f : 0.0f; /* Embree sets tfar to -inf on a hit */
    }
    float T = 1.0f, tnear = 0.0f;
    for (int k = 0; k < MAX_CROSSINGS; k++) {
        struct RTCRayHit rh;
        if (!intersect(j, ictx, o, d, tnear, tfar, &rh))
            return T;
        float a = opacity[rh.hit.primID];
        if (a >= 1.0f)
            return 0.0f;
        T *= 1.0f - fmaxf(a, 0.0f);
        float p[3] = {o[0] + rh.ray.tfar * d[0], o[1] + rh.ray.tfar * d[1],
                      o[2] + rh.ray.tfar * d[2]};
        tnear = rh.ray.tfar + surface_eps(p);
    }
    return 0.0f;
}

/* The cosine-weighted average of the transmittance of rays from p over
 * the distance (reference.h): the fraction of unblocked rays for an
 * opaque scene. */
static float ao_at(const job *j, struct RTCIntersectContext *ictx, pcg32 *rng, const float p[3],
                   const float n[3], const float ng[3])
{
    float t[3], b[3], o[3], d[3];
    /* Leave the surface along its own normal. */
    float eps = surface_eps(p);
    for (int k = 0; k < 3; k++)
        o[k] = p[k] + ng[k] * eps;
    onb(n, t, b);
    float open = 0.0f;
    for (int i = 0; i < j->desc.spp; i++) {
        float u1 = uniform01(rng), u2 = uniform01(rng);
        cosine_dir(n, t, b, u1, u2, d);
        if (dot3(d, ng) <= 0.0f)
            continue; /* below the surface: no light comes from there */
        open += transmittance(j, ictx, o, d, j->desc.distance);
    }
    return open / (float)j->desc.spp;
}

static float planar_depth(const job *j, const float p[3])
{
    const float *w = j->view->camera->world_to_camera;
    return -(w[8] * p[0] + w[9] * p[1] + w[10] * p[2] + w[11]);
}

/* A pixel of a scene with opacities (reference.h): every surface the
 * camera ray crosses (at most MAX_CROSSINGS) is a layer; its AO is
 * 1 - alpha (1 - V), V its ray-traced visibility with attenuated rays
 * (OITAO eq 1, the receiver's alpha_p), and the layers are blended front
 * to back by alpha onto AO 1 (OITAO III, the separated scheme), as
 * core/deep/deep_cpu.c blends its nodes.  Layers of alpha 0 are skipped.
 * *depth: the front layer's planar depth, OBS_SKY_DEPTH when none. */
static float layered_ao(const job *j, struct RTCIntersectContext *ictx, pcg32 *rng, int x, int y,
                        float *depth)
{
    float o[3], d[3], T = 1.0f, acc = 0.0f, tnear = 0.0f;
    camera_ray(j, x, y, o, d);
    *depth = OBS_SKY_DEPTH;
    if (!ray_ok(o, d))
        return 1.0f;
    for (int k = 0; k < MAX_CROSSINGS && T > 0.0f; k++) {
        struct RTCRayHit rh;
        float p[3], n[3], ng[3];
        if (!intersect(j, ictx, o, d, tnear, INFINITY, &rh))
            break;
        int ok = hit_point(j, o, d, &rh, p, n, ng);
        float a = fminf(fmaxf(j->scene->opacity[rh.hit.primID], 0.0f), 1.0f);
        tnear = rh.ray.tfar + surface_eps(p);
        if (!ok || !(a > 0.0f))
            continue;
        if (*depth == OBS_SKY_DEPTH)
            *depth = planar_depth(j, p);
        float v = ao_at(j, ictx, rng, p, n, ng);
        acc += T * a * (1.0f - a * (1.0f - v));
        T *= 1.0f - a;
    }
    return acc + T;
}

/* One row on one thread (pool.h hands the rows out in order). */
static int render_row(void *ctx, void *local, size_t row, size_t row_end)
{
    (void)local;
    (void)row_end; /* ranges of one row */
    job *j = ctx;
    struct RTCIntersectContext ictx;
    rtcInitIntersectContext(&ictx);
    const int y = (int)row;
    for (int x = 0; x < j->width; x++) {
        size_t i = (size_t)y * j->width + x;
        float p[3], n[3], ng[3];
        pcg32 rng;
        pcg32_seed(&rng, j->desc.seed, i);
        if (j->desc.obscurance) {
            /* eq 1 around the normal facing the viewer; opaque */
            const int near = j->desc.obscurance_near > 0.0f;
            float *o = j->ao + (near ? 5 : 3) * i, v[2] = {1.0f, 1.0f}, a = 1.0f;
            int hit = surface_point(j, &ictx, x, y, p, n, ng);
            if (hit)
                obs__obscurance_at(j->rtc, &ictx, &j->ob, i, p, ng, v);
            if (hit && near)
                a = ao_at(j, &ictx, &rng, p, n, ng); /* desc.distance is the near one */
            o[0] = j->desc.blend * v[0] + (1.0f - j->desc.blend) * v[1];
            o[1] = v[0];
            o[2] = v[1];
            if (near) {
                o[3] = a;
                o[4] = a * v[1];
            }
            if (j->depth)
                j->depth[i] = hit ? planar_depth(j, p) : OBS_SKY_DEPTH;
            continue;
        }
        if (j->scene->opacity && !j->view->position) {
            float z;
            j->ao[i] = layered_ao(j, &ictx, &rng, x, y, &z);
            if (j->depth)
                j->depth[i] = z;
            continue;
        }
        if (!surface_point(j, &ictx, x, y, p, n, ng)) {
            j->ao[i] = 1.0f;
            if (j->depth)
                j->depth[i] = OBS_SKY_DEPTH;
            continue;
        }
        j->ao[i] = ao_at(j, &ictx, &rng, p, n, ng);
        if (j->depth)
            j->depth[i] = planar_depth(j, p);
    }
    return 0;
}

static int report(void *user, size_t done, size_t total)
{
    const job *j = user;
    j->desc.progress(j->desc.progress_user, (int)done, (int)total);
    return 0;
}

/* ---- Embree scene -------------------------------------------------------- */

static void device_error(void *user, enum RTCError code, const char *msg)
{
    char *buf = user;
    if (!buf[0])
        snprintf(buf, OBS_ERR_LEN, "Embree error %d: %s", (int)code, msg ? msg : "");
}

static obs_status build(RTCDevice dev, const obs_scene *s, RTCScene *out, const char *dev_err,
                        char err[OBS_ERR_LEN])
{
    RTCScene rs = rtcNewScene(dev);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    float *v = NULL;
    unsigned *ix = NULL;
    if (rs && g) {
        /* Copies, not shared buffers: Embree reads vertex buffers in
         * 16-byte loads and wants them padded. */
        v = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                    3 * sizeof(float), s->vertex_count);
        ix = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                     3 * sizeof(unsigned), s->triangle_count);
    }
    if (!v || !ix) {
        if (g)
            rtcReleaseGeometry(g);
        if (rs)
            rtcReleaseScene(rs);
        return obs__fail(err, OBS_NO_MEMORY, "building the ray-tracing scene (%zu triangles): %s",
                         s->triangle_count, dev_err[0] ? dev_err : "out of memory");
    }
    memcpy(v, s->positions, s->vertex_count * 3 * sizeof(float));
    memcpy(ix, s->indices, s->triangle_count * 3 * sizeof(unsigned));
    rtcCommitGeometry(g);
    rtcAttachGeometry(rs, g);
    rtcReleaseGeometry(g);
    rtcSetSceneBuildQuality(rs, RTC_BUILD_QUALITY_HIGH);
    rtcCommitScene(rs);
    if (dev_err[0]) {
        rtcReleaseScene(rs);
        return obs__fail(err, OBS_NO_MEMORY, "building the ray-tracing scene: %s", dev_err);
    }
    *out = rs;
    return OBS_OK;
}

static obs_status check_args(const obs_scene *scene, const obs_reference_view *v,
                             obs_reference_desc *d, int *w, int *h, char err[OBS_ERR_LEN])
{
    if (!scene || !scene->positions || !scene->indices || scene->triangle_count == 0)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "empty scene: no triangles");
    if (!v || !v->camera || !v->camera->has_projection)
        return obs__fail(err, OBS_NO_CAMERA, "the reference needs a camera with a projection");
    if (d->obscurance) {
        for (int c = 0; c < 2; c++)
            if (!(d->obscurance_distance[c] > 0.0f) || !isfinite(d->obscurance_distance[c]))
                return obs__fail(err, OBS_INVALID_ARGUMENT,
                                 "obscurance %s distance %g: expected a positive length",
                                 c ? "long" : "short", (double)d->obscurance_distance[c]);
        if (!(d->blend >= 0.0f && d->blend <= 1.0f))
            return obs__fail(err, OBS_INVALID_ARGUMENT, "blend %g: expected 0 to 1",
                             (double)d->blend);
        if (!(d->obscurance_near >= 0.0f) || !isfinite(d->obscurance_near))
            return obs__fail(err, OBS_INVALID_ARGUMENT,
                             "near distance %g: expected a positive length (0: none)",
                             (double)d->obscurance_near);
        d->distance = d->obscurance_near; /* ao_at's */
    } else if (!(d->distance > 0.0f) || !isfinite(d->distance))
        return obs__fail(err, OBS_INVALID_ARGUMENT, "distance %g: expected a positive length",
                         (double)d->distance);
    if (d->spp == 0)
        d->spp = DEFAULT_SPP;
    if (d->spp < 1 || d->spp > MAX_SPP)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "spp %d: expected 1 to %d", d->spp, MAX_SPP);
    if (d->threads < 0 || d->threads > OBS__POOL_MAX_THREADS)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "threads %d: expected 1 to %d", d->threads,
                         OBS__POOL_MAX_THREADS);
    if (!v->position != !v->normal)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "G-buffer points need both position and normal");
    if (v->position) {
        const obs_image *p = v->position, *n = v->normal;
        if (!p->data || !n->data || p->channels < 3 || n->channels < 3 || p->width != n->width ||
            p->height != n->height)
            return obs__fail(err, OBS_INVALID_ARGUMENT,
                             "G-buffer points: position and normal must be 3-channel images of "
                             "one size");
        *w = p->width;
        *h = p->height;
    } else {
        *w = v->width;
        *h = v->height;
    }
    if (*w < 1 || *h < 1)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "image size %dx%d", *w, *h);
    return obs_check_size(NULL, *w, *h, err);
}

obs_status obs_reference_render(const obs_scene *scene, const obs_reference_view *view,
                                const obs_reference_desc *desc, obs_image *ao, obs_image *depth,
                                char err[OBS_ERR_LEN])
{
    obs_reference_desc d = {0};
    int w = 0, h = 0;
    obs_status s;
    char dev_err[OBS_ERR_LEN] = "";
    RTCDevice dev = NULL;
    RTCScene rs = NULL;

    memset(ao, 0, sizeof *ao);
    if (depth)
        memset(depth, 0, sizeof *depth);
    if (desc)
        d = *desc;
    if ((s = check_args(scene, view, &d, &w, &h, err)) != OBS_OK)
        return s;

    job *j = calloc(1, sizeof *j);
    size_t px = (size_t)w * (size_t)h;
    const int ao_channels = !d.obscurance ? 1 : d.obscurance_near > 0.0f ? 5 : 3;
    if (!j || !(ao->data = malloc(px * ao_channels * sizeof(float))) ||
        (depth && !(depth->data = malloc(px * sizeof(float))))) {
        s = obs__fail(err, OBS_NO_MEMORY, "reference image of %dx%d", w, h);
        goto fail;
    }
    ao->width = w;
    ao->height = h;
    ao->channels = ao_channels;
    if (depth) {
        depth->width = w;
        depth->height = h;
        depth->channels = 1;
    }

    const obs_camera *cam = view->camera;
    float clip[16], inv_w[16];
    obs__mat4_mul(cam->projection, cam->world_to_camera, clip);
    if (obs__mat4_invert(clip, j->clip_to_world) != 0 ||
        obs__mat4_invert(cam->world_to_camera, inv_w) != 0) {
        s = obs__fail(err, OBS_NO_CAMERA, "the camera's matrices are singular");
        goto fail;
    }
    const int persp = cam->projection[14] != 0.0f;
    const float origin[4] = {0, 0, 0, 1}, back[4] = {0, 0, 1, 0};
    obs__mat4_apply(inv_w, persp ? origin : back, j->eye);
    if (persp)
        for (int k = 0; k < 4; k++)
            j->eye[k] /= j->eye[3];
    /* The camera rays start there (Embree aborts on an origin past
     * 1.844e18 or a non-finite one): the scenes' bound, and every corner
     * ray finite. */
    if (persp && (!isfinite(j->eye[0]) || !isfinite(j->eye[1]) || !isfinite(j->eye[2]) ||
                  obs_scene_coord_beyond(j->eye))) {
        s = obs__fail(err, OBS_NO_CAMERA, "the camera at (%g, %g, %g): " OBS_SCENE_COORD_RULE,
                      (double)j->eye[0], (double)j->eye[1], (double)j->eye[2]);
        goto fail;
    }
    j->width = w;
    j->height = h;
    for (int c = 0; c < 4; c++) {
        float o[3], dir[3];
        camera_ray(j, c & 1 ? w - 1 : 0, c & 2 ? h - 1 : 0, o, dir);
        if (!ray_ok(o, dir)) {
            s = obs__fail(err, OBS_NO_CAMERA,
                          "the camera's ray through pixel (%d, %d) starts at (%g, %g, %g) "
                          "towards (%g, %g, %g): its matrices overflow float, or " OBS_SCENE_COORD_RULE,
                          c & 1 ? w - 1 : 0, c & 2 ? h - 1 : 0, (double)o[0], (double)o[1],
                          (double)o[2], (double)dir[0], (double)dir[1], (double)dir[2]);
            goto fail;
        }
    }

    char embree_cfg[32];
    if (!(dev = rtcNewDevice(obs__pool_embree_config(embree_cfg)))) {
        s = obs__fail(err, OBS_UNSUPPORTED, "Embree: no device (error %d)",
                      (int)rtcGetDeviceError(NULL));
        goto fail;
    }
    rtcSetDeviceErrorFunction(dev, device_error, dev_err);
    if ((s = build(dev, scene, &rs, dev_err, err)) != OBS_OK)
        goto fail;

    j->scene = scene;
    j->rtc = rs;
    j->view = view;
    j->desc = d;
    if (d.obscurance)
        obs__obscurance_init(&j->ob, d.obscurance_distance, d.spp, d.seed,
                             obs__bake_occluders_occl(d.occluders));
    j->width = w;
    j->height = h;
    j->ao = ao->data;
    j->depth = depth ? depth->data : NULL;
    obs__pool_for f = {.end = (size_t)h, .chunk = 1, .threads = d.threads, .range = render_row,
                       .ctx = j, .progress = d.progress ? report : NULL, .progress_user = j};
    obs__pool_run(&f, NULL);

fail:
    if (rs)
        rtcReleaseScene(rs);
    if (dev)
        rtcReleaseDevice(dev);
    free(j);
    if (s != OBS_OK) {
        obs_image_free(ao);
        if (depth)
            obs_image_free(depth);
    }
    return s;
}
