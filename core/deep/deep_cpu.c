/* Multi-layer, opacity-based AO from a deep image: the CPU twin of
 * core/shaders/deep.frag.glsl (tests/unit/core/test_deep.c compares them).
 *
 * OITAO (Bauer et al.) Algorithm 1: for each sample, the occlusion
 * against every node of the compressed list at the sample's pixel, the
 * largest counting.  The per-node occlusion ("GetAO") is VAO++'s (section
 * 3): the length of the pipe through the tangent sphere hidden behind the
 * node's depth, with the depth range check of section 4.4 (eq 4) applied
 * per node.  Opacity enters as in OITAO section III: eq 1 weights the
 * occluder by its alpha and the receiver's occlusion by its own (solid
 * volumes); for thin hulls eqs 2-4 mix the exterior AO (sphere on the
 * normal's side) and the interior AO (sphere on the other side) by W(p).
 * With method hemisphere the per-node occlusion is instead that of the
 * normal-oriented hemisphere kernel's point samples (methods/hemisphere.c),
 * each against every node, the largest counting (hemisphere_ao() below).
 * The AO of each node is blended front to back by alpha into one 2D AO
 * (section III, the separated scheme). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "chain/bands_cpu.h"
#include "chain/mask_weight.h"
#include "chain/passes_cpu.h"
#include "deep/deep_internal.h"
#include "methods/gtao.h"
#include "methods/hbao.h"
#include "methods/hemisphere.h"
#include "mask_apply.h"
#include "methods/methods.h"

int obs_deep_result_exr_layers(const obs_deep_result *r, unsigned outputs, obs_exr_layer layers[3])
{
    static const char *const ao[] = {"AO.Y"}, *const front[] = {"AOFront.Y"};
    static const char *const rgba[] = {"R", "G", "B", "A"};
    int n = 0;
    if ((outputs & OBS_OUTPUT_AO) && r->ao_blend.data)
        layers[n++] = (obs_exr_layer){&r->ao_blend, ao};
    if ((outputs & OBS_OUTPUT_AO) && r->ao_front.data)
        layers[n++] = (obs_exr_layer){&r->ao_front, front};
    if ((outputs & OBS_OUTPUT_COMPOSITE) && r->composite.data)
        layers[n++] = (obs_exr_layer){&r->composite, rgba};
    return n;
}

void obs__deep_frame_free(obs__deep_frame *df)
{
    if (!df)
        return;
    free(df->pos);
    free(df->nrm);
    free(df->end);
    free(df->nrm3);
    obs_deep_layers_free(&df->layers);
    memset(df, 0, sizeof *df);
}

typedef struct prep_job {
    obs__deep_frame *df;
    const obs_deep_image *d;
    int k; /* the node plane */
} prep_job;

static void prep_position_rows(void *ctx, int y0, int y1)
{
    const prep_job *j = ctx;
    const obs__deep_frame *df = j->df;
    const size_t npx = (size_t)j->d->width * (size_t)j->d->height;
    const float *node = df->layers.node + (size_t)j->k * npx * OBS_DEEP_CH;
    float *pos = df->pos + (size_t)j->k * npx * 4;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < j->d->width; x++) {
            size_t i = (size_t)y * j->d->width + x;
            /* an empty node is background (raw depth 0) */
            float z = j->k < df->layers.count[i] ? node[i * OBS_DEEP_CH + OBS_DEEP_Z] : 0.0f;
            obs__prep_position(&df->f, z, x, y, pos + 4 * i);
        }
}

static void prep_normal_rows(void *ctx, int y0, int y1)
{
    const prep_job *j = ctx;
    const obs__deep_frame *df = j->df;
    const size_t npx = (size_t)j->d->width * (size_t)j->d->height;
    const float *node = df->layers.node + (size_t)j->k * npx * OBS_DEEP_CH;
    const float *pos = df->pos + (size_t)j->k * npx * 4;
    float *nrm = df->nrm + (size_t)j->k * npx * 4;
    for (int y = y0; y < y1; y++)
        for (int x = 0; x < j->d->width; x++) {
            size_t i = (size_t)y * j->d->width + x;
            const float *nd = node + i * OBS_DEEP_CH;
            float v[3];
            obs__prep_normal(&df->f, pos, nd + OBS_DEEP_NX, x, y, v);
            nrm[4 * i] = v[0];
            nrm[4 * i + 1] = v[1];
            nrm[4 * i + 2] = v[2];
            nrm[4 * i + 3] = pos[4 * i + 3] > 0.0f ? fminf(fmaxf(nd[OBS_DEEP_A], 0.0f), 1.0f) : 0.0f;
        }
}

int obs_deep_intervals_in_effect(const obs_deep_image *d, const obs_params *p)
{
    /* on, or auto with method gtao (whose free arcs measured closer to the
     * ray tracer; the VAO methods' intervals measured farther,
     * bench/QUALITY.md), where the image has facing flags and every node
     * counts (deep_mode multi) */
    return d && p &&
           (p->deep_intervals == OBS_DEEP_INTERVALS_ON ||
            (p->deep_intervals == OBS_DEEP_INTERVALS_AUTO && p->method == OBS_METHOD_GTAO)) &&
           d->has_facing && p->deep_mode != OBS_DEEP_SINGLE;
}

void obs_deep_params_resolve(const obs_deep_image *d, const obs_params *in, obs_params *out)
{
    obs_params_resolve(in, out);
    if (!obs_deep_intervals_in_effect(d, out) || out->method != OBS_METHOD_GTAO)
        return;
    /* gtao with intervals computes the slice integral as written
     * (OBS_DEEP_GTAO_EXACT): its rows fill what the request left unset */
    obs_params q;
    if (in)
        q = *in;
    else
        memset(&q, 0, sizeof q);
#define OBS__EXACT_ROW(name, value) obs__params_fill(&q, #name, value);
    OBS_DEEP_GTAO_EXACT(OBS__EXACT_ROW)
#undef OBS__EXACT_ROW
    obs_params_resolve(&q, out);
}

obs_status obs__deep_frame_setup(const obs_deep_image *d, const obs_params *params,
                                 obs__deep_frame *df, char err[OBS_ERR_LEN])
{
    obs_params p;
    obs_gbuffer gb;
    float *depth = NULL, *in_n = NULL;
    obs_status s;

    memset(df, 0, sizeof *df);
    if (!d || !d->offset || d->width <= 0 || d->height <= 0)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "no deep image");
    obs_params_resolve(params, &p);
    const obs__method *method = obs__method_get(p.method);
    if (!method || !method->deep) {
        /* the message lists the rows of the method table that run here */
        char name[32], list[128] = "";
        size_t len = 0;
        int k = 0, n = 0;
        for (int i = 0; i < obs__method_count(); i++)
            n += obs__method_at(i)->deep;
        for (int i = 0; i < obs__method_count(); i++) {
            const obs__method *r = obs__method_at(i);
            if (!r->deep)
                continue;
            k++;
            len += (size_t)snprintf(list + len, sizeof list - len, "%s%s",
                                    k == 1 ? "" : k == n ? " and " : ", ", r->name);
            if (len >= sizeof list)
                break;
        }
        obs_param_format(&p, obs_param_find("method"), name, sizeof name);
        return obs__fail(err, OBS_INVALID_ARGUMENT,
                         "method %s does not run on deep input: the multi-layer chain takes "
                         "methods %s",
                         name, list);
    }
    /* the parameters as the chain runs them on this image (intervals:
     * gtao's exact rows) */
    obs_deep_params_resolve(d, params, &p);
    df->multi = p.deep_mode != OBS_DEEP_SINGLE;
    df->thin = p.deep_hull == OBS_DEEP_THIN;
    df->intervals = obs_deep_intervals_in_effect(d, &p);
    /* Without intervals every node is the visible surface of a solid
     * behind it (eq 4's range check, ao_definition rays' conversion).  A
     * node the facing flags put inside a nearer node's interval (a back
     * face closing it, a face within it) is not: it lies inside the solid
     * the nearer front face already stands for, and taken as the front of
     * one more solid behind it, nearer the samples' pipes than that front
     * face, it thickened the occluder the range check thins (a halo behind
     * every back face).  The methods whose occluder is solid behind a
     * node leave such nodes out: VAO's line samples, hemisphere's point
     * samples.  The horizon methods keep them: a node raises a horizon by
     * its own position, and a back face is a point of the occluder, the
     * one nearest a receiver behind it (hbao; gtao: with its intervals,
     * on by default, or every node as it is). */
    df->inside = !df->intervals && d->has_facing && df->multi &&
                 (p.method == OBS_METHOD_VAOPP || p.method == OBS_METHOD_VAO ||
                  p.method == OBS_METHOD_HEMISPHERE);
    size_t npx = (size_t)d->width * (size_t)d->height;
    depth = calloc(npx, sizeof *depth);
    in_n = d->has_normal ? calloc(npx * 3, sizeof *in_n) : NULL;
    if (!depth || (d->has_normal && !in_n)) {
        s = obs__fail(err, OBS_NO_MEMORY, "deep frame of %dx%d", d->width, d->height);
        goto fail;
    }
    /* The frame (camera, R, samples) as for a flat G-buffer of the front
     * nodes; normals given when the file has them. */
    memset(&gb, 0, sizeof gb);
    gb.width = d->width;
    gb.height = d->height;
    gb.display_x = d->display_x;
    gb.display_y = d->display_y;
    gb.display_width = d->display_width;
    gb.display_height = d->display_height;
    gb.depth = (obs_plane){depth, 1, 0};
    gb.normal = (obs_plane){in_n, in_n ? 3 : 0, 0};
    gb.camera = d->camera;
    if ((s = obs__frame_setup(NULL, &gb, &p, &df->f, err)) != OBS_OK)
        goto fail;
    if (df->f.half) {
        s = obs__fail(err, OBS_INVALID_ARGUMENT,
                      "ao_resolution half is for flat G-buffers; deep input runs at full "
                      "resolution (use ao_resolution full or a quality other than preview)");
        goto fail;
    }
    /* eq 5 over the clip range of the camera the frame resolved (the
     * image's, or the parameters' field of view and near, far); with
     * intervals it never splits one (deep_compress.c) */
    obs_deep_image dc = *d;
    memcpy(dc.camera.projection, df->f.proj, sizeof dc.camera.projection);
    dc.camera.has_projection = 1;
    if ((s = obs__deep_compress(&dc, p.deep_layers, p.deep_front_half == OBS_ON, df->intervals,
                                &df->layers, err)) != OBS_OK)
        goto fail;
    int m = df->layers.m;
    /* object masks (obs_deep_read_masks): the weight and the object of
     * every node, read at each method's sample site by
     * obs__occluder_weight_node, one plane per node */
    df->f.mask_occl = df->layers.occluders;
    df->f.mask_id = df->layers.object_id;
    df->f.mask_on = df->f.mask_occl || df->f.mask_id;
    df->f.mask_plane = npx;
    df->pos = malloc(npx * (size_t)m * 4 * sizeof *df->pos);
    df->nrm = malloc(npx * (size_t)m * 4 * sizeof *df->nrm);
    df->end = calloc(npx * (size_t)m, sizeof *df->end);
    if (!df->pos || !df->nrm || !df->end) {
        s = obs__fail(err, OBS_NO_MEMORY, "deep frame of %dx%dx%d", d->width, d->height, m);
        goto fail;
    }
    df->m = m;

    /* The prep pass of every node plane, in row bands on the worker pool:
     * positions, then normals (which read the neighbours' positions). */
    for (int k = 0; k < m; k++) {
        prep_job j = {df, d, k};
        obs__cpu_rows(d->height, 0, prep_position_rows, &j);
        obs__cpu_rows(d->height, 0, prep_normal_rows, &j);
    }
    /* The border steps of method gtao and the samples off the planes of
     * VAO's line samples read the front nodes' normals. */
    if (df->f.method != OBS_METHOD_HEMISPHERE && df->f.method != OBS_METHOD_HBAO) {
        if (!(df->nrm3 = malloc(npx * 3 * sizeof *df->nrm3))) {
            s = obs__fail(err, OBS_NO_MEMORY, "deep frame of %dx%d", d->width, d->height);
            goto fail;
        }
        for (size_t i = 0; i < npx; i++)
            memcpy(df->nrm3 + 3 * i, df->nrm + 4 * i, 3 * sizeof *df->nrm3);
    }
    /* The nodes' extents from their facing flags (deep_intervals; without
     * them only whether a node lies inside an interval, df->inside). */
    if (df->intervals || df->inside)
        for (size_t i = 0; i < npx; i++) {
            float z[OBS_DEEP_MAX_LAYERS], fc[OBS_DEEP_MAX_LAYERS], e[OBS_DEEP_MAX_LAYERS];
            int c = df->layers.count[i];
            for (int k = 0; k < c; k++) {
                z[k] = df->pos[((size_t)k * npx + i) * 4 + 3];
                fc[k] = df->layers.node[((size_t)k * npx + i) * OBS_DEEP_CH + OBS_DEEP_FACING];
            }
            obs__deep_intervals(z, fc, c, e);
            /* a list eq 5 cut behind its last kept node, that one a back
             * face: OBS__DEEP_END_CUT (what lies behind it is not known) */
            if (c > 0 && e[c - 1] < 0.0f) {
                const float zl = df->layers.node[((size_t)(c - 1) * npx + i) * OBS_DEEP_CH + OBS_DEEP_Z];
                for (uint64_t k = d->offset[i]; k < d->offset[i + 1]; k++)
                    if (d->samples[k * OBS_DEEP_CH + OBS_DEEP_Z] > zl) {
                        e[c - 1] = OBS__DEEP_END_CUT;
                        break;
                    }
            }
            if (df->f.method == OBS_METHOD_GTAO)
                obs__deep_sheets(z, fc, c, e);
            for (int k = 0; k < c; k++)
                df->end[(size_t)k * npx + i] = df->inside && e[k] > 0.0f ? 0.0f : e[k];
        }
    free(depth);
    free(in_n);
    return OBS_OK;
fail:
    free(depth);
    free(in_n);
    obs__deep_frame_free(df);
    return s;
}

void obs__deep_intervals(const float *z, const float *facing, int count, float *end)
{
    int k0 = 0;
    for (int k = 0; k < count; k++)
        end[k] = 0.0f;
    while (k0 < count) {
        int open = -1, depth = 0; /* the node that opened the interval, the facing count */
        for (int k = k0; k < count; k++) {
            if (!(z[k] > 0.0f))
                continue;
            if (depth == 0) {
                if (facing[k] > 0.0f) { /* a front face: the solid starts */
                    open = k;
                    depth = 1;
                }
                continue; /* else a surface seen from one side: solid behind */
            }
            end[k] = -1.0f; /* inside the interval node `open` opened */
            depth += facing[k] > 0.0f ? 1 : facing[k] < 0.0f ? -1 : 0;
            if (depth == 0)
                end[open] = fmaxf(z[k], z[open]); /* its matching back face */
        }
        if (depth == 0)
            return;
        /* node `open` has no back face in the list: a surface seen from one
         * side, solid behind it as without intervals; the nodes behind it
         * are scanned again on their own */
        for (int k = open; k < count; k++)
            end[k] = 0.0f;
        k0 = open + 1;
    }
}

void obs__deep_sheets(const float *z, const float *facing, int count, float *end)
{
    for (int k = 0; k + 1 < count; k++) /* not the last: a node behind it */
        if (end[k] == 0.0f && facing[k] != 0.0f && z[k] > 0.0f)
            end[k] = z[k];
}

/* GLSL: interval_occlusion() in deep.frag.glsl.  The length of the pipe
 * [front, front + 2h] inside the solid interval [zs, e] of a node whose
 * back face the list holds: their overlap, no range check (the buffer
 * shows where the solid ends). */
static float interval_occlusion(float zs, float e, float front, float h)
{
    return fmaxf(0.0f, fminf(e, front + 2.0f * h) - fmaxf(zs, front));
}

/* GLSL: node_occlusion() in deep.frag.glsl.  The length of the pipe
 * [front, front + 2h] (depths) hidden by a node at planar depth zs with
 * view normal z nz: the cases A, B, C of VAO++ section 3 with the node as
 * the depth buffer, and the depth range check (section 4.4, eq 4,
 * obs__range_falloff) when the node lies in front of the pipe.  With `interior` (the sphere on the back side of a thin hull,
 * OITAO eqs 2-4) a node in front of the pipe is on the hull's exterior
 * side and hides nothing of the interior. */
static float node_occlusion(const obs__frame *f, float zs, float nz, float front, float h,
                            int interior)
{
    if (!(zs > 0.0f))
        return 0.0f; /* empty node */
    float dz = fminf(fmaxf(zs - front, 0.0f), 2.0f * h);
    if (zs < front) {
        if (interior)
            return 0.0f;
        if (f->range_check) {
            float sd = obs__range_falloff(f, front - zs, nz);
            dz = 2.0f * h * (1.0f - sd);
        }
    }
    return 2.0f * h - dz;
}

/* GLSL: sphere_ao() in deep.frag.glsl.  VAO (eq 1, 2 of VAO++ section 3)
 * of the tangent sphere of radius R/2 at p along n, each line sample's
 * occlusion the largest over the nodes at its pixel (OITAO Algorithm 1,
 * line 9), each node's weighted by its alpha (OITAO eq 1's alpha_omega).
 * self: the receiver's node at (x, y), which a sample on that pixel reads
 * as its tangent plane (obs__own_plane_depth). */
static float sphere_ao(const obs__deep_frame *df, int x, int y, const float p[3], const float n[3],
                       int interior, int self)
{
    const obs__frame *f = &df->f;
    const float R = f->radius, r = 0.5f * R;
    const float c[3] = {p[0] + n[0] * r, p[1] + n[1] * r, p[2] + n[2] * r};
    const float *rot = f->rot[obs__tile_index(f, x, y)];
    const int layers = df->multi ? df->m : 1;
    const size_t npx = (size_t)f->width * (size_t)f->height;
    float open = 0.0f, F = 0.0f;
    obs__disk disk; /* the samples' pixels */
    obs__disk_map(f, c, r, rot, &disk);

    for (int i = 0; i < f->samples; i++) {
        float sx = f->sample_xy[2 * i], sy = f->sample_xy[2 * i + 1];
        float l = sqrtf(fmaxf(0.0f, 1.0f - sx * sx - sy * sy));
        float h = r * l;
        int qx, qy;
        float front = -c[2] - h, occ = 0.0f, solid = 0.0f;
        if (!obs__disk_px(f, &disk, sx, sy, &qx, &qy)) {
            /* off the planes: the front nodes' surface continued past the
             * border, as the flat chain reads its planes there
             * (border_cpu.c), with the alpha and masks' weight of the
             * front node it continues; left out of eq 1's sum and F where
             * there is no estimate */
            float zs = 0.0f, nz = 1.0f; /* 0: an empty node, where b is background */
            size_t b = 0;
            if (!obs__disk_border(f, df->pos, df->nrm3, &disk, x, y, sx, sy, &zs, &nz, &b))
                continue;
            const float a = df->nrm[4 * b + 3] *
                            obs__occluder_weight_node(f, x, y, self, (int)(b % (size_t)f->width),
                                                      (int)(b / (size_t)f->width), 0);
            open += 2.0f * h - a * node_occlusion(f, zs, nz, front, h, interior);
            F += R * l;
            continue;
        }
        size_t q = (size_t)qy * (size_t)f->width + (size_t)qx;
        for (int k = 0; k < layers; k++) {
            const float *pk = df->pos + ((size_t)k * npx + q) * 4;
            const float *nk = df->nrm + ((size_t)k * npx + q) * 4; /* normal, alpha */
            const float e = df->end[(size_t)k * npx + q];
            float zs = pk[3];
            if (e < 0.0f)
                continue; /* inside a nearer node's interval */
            if (k == self && qx == x && qy == y)
                zs = obs__own_plane_depth(p, n, c, r, rot, sx, sy, zs);
            /* the node's alpha times the object masks' weight of its
             * surface (1 without masks) */
            const float a = nk[3] * obs__occluder_weight_node(f, x, y, self, qx, qy, k);
            if (e > 0.0f && zs > 0.0f && !interior) /* a closed interval */
                solid += a * interval_occlusion(zs, e, front, h);
            else
                occ = fmaxf(occ, a * node_occlusion(f, zs, nk[2], front, h, interior));
        }
        /* the intervals are disjoint: their lengths add; the nodes solid
         * behind them count as Algorithm 1's largest */
        occ = fminf(2.0f * h, occ + solid);
        open += 2.0f * h - occ;
        F += R * l; /* VAO++ eq 2 */
    }
    return F > 0.0f ? open / F : 1.0f; /* VAO++ eq 1 */
}

/* GLSL: hemisphere_estimate() in hemisphere.glsl with deep.frag.glsl's
 * nodes (HS_NODE).  Method hemisphere on the
 * nodes: the normal-oriented hemisphere kernel of methods/hemisphere.c (radius
 * R, the frame's tile rotation), each point sample s occluded by a node at
 * its pixel as obs__hemisphere_pixel is by the flat depth buffer, with the
 * node as that buffer: occluded when s lies more than the bias behind the
 * node's depth, the node being taken to fill everything behind it, and
 * weighted by the method's range check (smoothstep of R / |z_p - z_node|)
 * so that a node far in front of the receiver fades out, as eq 4 does for
 * node_occlusion's pipes.  Each sample's occlusion is the largest over the
 * nodes at its pixel (OITAO Algorithm 1, line 9: ao = max(ao, GetAO(p,
 * f)) over the fragment list), each node's weighted by its alpha (OITAO
 * eq 1's alpha_omega); the samples' occlusions are averaged (lines 10-12).
 * With `interior` (n is then the back side's direction, OITAO eqs 2-4) a
 * node on the exterior side of the receiver's tangent plane (not more than
 * the bias along n from p) hides nothing, as node_occlusion's node in
 * front of the pipe. */
static float hemisphere_ao(const obs__deep_frame *df, int x, int y, const float p[3],
                           const float n[3], int interior, int self)
{
    const obs__frame *f = &df->f;
    const obs__hemisphere_nodes nodes = {df->pos,
                                         df->nrm,
                                         df->end,
                                         df->multi ? df->m : 1,
                                         (size_t)f->width * (size_t)f->height,
                                         interior,
                                         self};
    return obs__hemisphere_estimate(f, &nodes, x, y, p, n);
}

/* The per-sample estimator of the frame's method: VAO++'s line samples,
 * method hemisphere's point samples or methods gtao's and hbao's horizon
 * steps, each against every node (Algorithm 1; for the horizon methods
 * every node at a step's pixel, OITAO's multi-layer HBAO, Fig. 9). */
static float method_ao(const obs__deep_frame *df, int x, int y, const float p[3], const float n[3],
                       int interior, int self)
{
    if (df->f.method == OBS_METHOD_HEMISPHERE)
        return hemisphere_ao(df, x, y, p, n, interior, self);
    if (df->f.method == OBS_METHOD_GTAO) /* the horizon over every node */
        return obs__gtao_pixel_nodes(&df->f, df->pos, df->nrm3, df->multi ? df->m : 1, self,
                                     df->intervals ? df->end : NULL, x, y, p, n, NULL, NULL);
    if (df->f.method == OBS_METHOD_HBAO)
        return obs__hbao_pixel_nodes(&df->f, df->pos, df->multi ? df->m : 1, self, x, y, p, n,
                                     NULL);
    float v = sphere_ao(df, x, y, p, n, interior, self);
    return df->f.rays ? obs__rays_from_volume(v) : v; /* ao_definition rays */
}

float obs__deep_node_ao(const obs__deep_frame *df, int x, int y, int k)
{
    const size_t npx = (size_t)df->f.width * (size_t)df->f.height;
    const size_t i = (size_t)k * npx + (size_t)y * (size_t)df->f.width + (size_t)x;
    const float *p = df->pos + 4 * i, *n = df->nrm + 4 * i;
    float alpha = n[3];
    if (!(p[3] > 0.0f))
        return 1.0f;
    float ve = method_ao(df, x, y, p, n, 0, k);
    if (!df->thin)
        return 1.0f - alpha * (1.0f - ve); /* OITAO eq 1: the receiver's alpha_p */
    /* OITAO eqs 2-4: the interior AO from the sphere on -n; W(p) = alpha
     * on a front face (normal towards the camera), 1 - alpha on a back
     * face. */
    const float nn[3] = {-n[0], -n[1], -n[2]};
    float vi = method_ao(df, x, y, p, nn, 1, k);
    float facing = -(p[0] * n[0] + p[1] * n[1] + p[2] * n[2]);
    float W = facing >= 0.0f ? alpha : 1.0f - alpha; /* eq 3 */
    return W * ve + (1.0f - W) * vi;                 /* eq 4 */
}

float obs__deep_pixel(const obs__deep_frame *df, int x, int y, float *front)
{
    const size_t npx = (size_t)df->f.width * (size_t)df->f.height;
    const size_t i = (size_t)y * (size_t)df->f.width + (size_t)x;
    float T = 1.0f, acc = 0.0f;
    *front = 1.0f;
    for (int k = 0; k < df->m; k++) {
        if (!(df->pos[((size_t)k * npx + i) * 4 + 3] > 0.0f))
            break; /* nodes are packed front to back */
        float a = df->nrm[((size_t)k * npx + i) * 4 + 3];
        float ao = obs__deep_node_ao(df, x, y, k);
        if (k == 0)
            *front = ao;
        acc += T * a * ao; /* "over", front to back */
        T *= 1.0f - a;
        if (T == 0.0f)
            break; /* an opaque node: every node behind it adds T a ao = 0 */
    }
    return acc + T; /* what shows through is open (AO 1) */
}

void obs__deep_composite(const obs_deep_image *d, obs_deep_result *out)
{
    size_t npx = (size_t)d->width * (size_t)d->height;
    for (size_t i = 0; i < npx; i++) {
        float T = 1.0f, rgb[3] = {0.0f, 0.0f, 0.0f};
        for (uint64_t s = d->offset[i]; s < d->offset[i + 1]; s++) {
            const float *v = d->samples + s * OBS_DEEP_CH;
            float a = fminf(fmaxf(v[OBS_DEEP_A], 0.0f), 1.0f);
            for (int c = 0; c < 3; c++) /* premultiplied; grey without colour */
                rgb[c] += T * (d->has_color ? v[OBS_DEEP_R + c] : a);
            T *= 1.0f - a;
        }
        float ao = out->ao_blend.data[i], *o = out->composite.data + 4 * i;
        for (int c = 0; c < 3; c++)
            o[c] = rgb[c] * ao;
        o[3] = 1.0f - T;
    }
}

typedef struct deep_job {
    const obs__deep_frame *df;
    obs_deep_result *out;
    obs__cpu_run *stop; /* its deadline, cancel and stopped fields only */
} deep_job;

static void deep_rows(void *ctx, int y0, int y1)
{
    const deep_job *j = ctx;
    const int w = j->df->f.width;
    for (int y = y0; y < y1; y++) {
        if (obs__cpu_stop_now(j->stop)) /* read between rows: at most a row past it */
            return;
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            j->out->ao_blend.data[i] = obs__deep_pixel(j->df, x, y, &j->out->ao_front.data[i]);
        }
    }
}

obs_status obs_deep_run_cpu(const obs_deep_image *d, const obs_params *params,
                            obs_deep_result *out, char err[OBS_ERR_LEN])
{
    return obs_deep_run_cpu_opts(d, params, NULL, out, err);
}

obs_status obs_deep_run_cpu_opts(const obs_deep_image *d, const obs_params *params,
                                 const obs_cpu_options *opt, obs_deep_result *out,
                                 char err[OBS_ERR_LEN])
{
    obs__deep_frame df;
    obs__cpu_run stop = {0};
    obs_status s;
    if (out)
        memset(out, 0, sizeof *out);
    if (!out)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "obs_deep_run_cpu: no output");
    obs__cpu_arm(&stop, opt);
    if ((s = obs__deep_frame_setup(d, params, &df, err)) != OBS_OK)
        return s;
    if ((s = obs__deep_result_alloc(out, d->width, d->height, err)) != OBS_OK) {
        obs__deep_frame_free(&df);
        return s;
    }
    /* every pixel on its own (obs__deep_pixel reads the frame, writes its
     * pixel): in row bands on the worker pool, the same bytes for any
     * thread count */
    deep_job j = {&df, out, &stop};
    obs__cpu_rows(d->height, 0, deep_rows, &j);
    if (atomic_load(&stop.stopped)) { /* some rows not run: no result */
        s = obs__cpu_stopped_fail(&stop, "in", OBS_PASS_AO, err);
        obs__deep_frame_free(&df);
        obs_deep_result_free(out);
        return s;
    }
    /* the low-pass filter (VAO++ 4.6) of both, the flat chain's twin with
     * the front node's plane as its positions (GLSL: deep_gl.c) */
    if (df.f.blur_radius > 0) {
        float *tmp = malloc((size_t)d->width * (size_t)d->height * sizeof *tmp);
        if (!tmp) {
            obs__deep_frame_free(&df);
            obs_deep_result_free(out);
            return obs__fail(err, OBS_NO_MEMORY, "deep blur of %dx%d", d->width, d->height);
        }
        obs__blur(&df.f, df.pos, out->ao_front.data, tmp);
        obs__blur(&df.f, df.pos, out->ao_blend.data, tmp);
        free(tmp);
    }
    obs__receivers_apply_deep(d, out); /* object masks: receivers */
    obs__deep_composite(d, out);
    obs__deep_frame_free(&df);
    return OBS_OK;
}
