/* Probe paths through a level (obs_dyn_measure_paths): the model of
 * section 2.3 against ray-traced eq 1 along straight paths, and the jumps
 * where a path crosses from one region into another, before and after the
 * regularisation and with the temporal blender.
 *
 * A path joins two points drawn uniformly in the regions' bounding box,
 * each in a region with a model and outside geometry (the back-face test
 * of probes.c), at least a tenth of the box's diagonal apart and in sight
 * of each other (no geometry on the segment), so that an object could
 * move along it, whatever the regions (the same paths for any
 * subdivision of the same box); `steps` points along it, each
 * with two normals: up (+y, the levels' up axis) and one random unit
 * vector per path (the same along the path, so its steps compare like
 * with like).
 *
 * The reference traces the bake's occluders (dynamic.c,
 * obs__dyn_occluders): eq 1's rho times each ray's transmittance through
 * the shrubs' fog and the trees, the quantity the model was fitted to; the
 * endpoints' tests (outside geometry, in sight of each other) see the
 * opaque triangles alone, as the valid points' flags do. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "level/decor.h"
#include "dynamic/dyn_internal.h"
#include "level/rng.h"
#include "internal.h"

#define PI_D 3.14159265358979323846
#define TRIES 2000

static int pick_point(const obs_dyn_model *m, const obs_dyn_box *all, const obs__bake_bvh *bvh,
                      float limit, obs__bake_rng *r, float q[3])
{
    for (int t = 0; t < TRIES; t++) {
        for (int a = 0; a < 3; a++)
            q[a] = all->lo[a] + (all->hi[a] - all->lo[a]) * (float)obs__bake_rng_unit(r);
        float c[3];
        int g = obs_dyn_model_region_at(m, q, c);
        if (g < 0 || c[0] != q[0] || c[1] != q[1] || c[2] != q[2])
            continue; /* in no region with a model */
        if (!obs__dyn_inside(bvh, q, 32, limit))
            return 1;
    }
    return 0;
}

obs_status obs_dyn_measure_paths(const obs_bake_scene *scene, const obs_dyn_result *res,
                                 const obs_dyn_params *pin, const char *decorators_json,
                                 int paths, int steps, int rays,
                                 float tau, obs_dyn_path_stats *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    obs_dyn_params p;
    obs_dyn_params_resolve(pin, &p);
    obs__bake_world w = {0};
    obs__bake_bvh *bvh = NULL;
    obs__bake_decor dc = {0};
    char warning[OBS_ERR_LEN];
    obs_status st;
    double *val = NULL;
    int *reg = NULL;
    if (steps < 2 || rays < 1 || paths < 1)
        return obs__fail(err, OBS_INVALID_ARGUMENT, "paths: %d paths of %d steps, %d rays",
                         paths, steps, rays);
    if ((st = obs__bake_flatten(scene, &w, err)) != OBS_OK)
        return st;
    if ((st = obs__dyn_occluders(scene, &w, &p, decorators_json, &dc, &bvh, warning, err)) !=
        OBS_OK)
        goto done;
    val = malloc((size_t)steps * 4 * sizeof *val);
    reg = malloc((size_t)steps * 2 * sizeof *reg);
    if (!val || !reg) {
        st = obs__fail(err, OBS_NO_MEMORY, "paths");
        goto done;
    }
    obs__bake_rng r = obs__bake_rng_stream((uint64_t)p.seed, 0, 17);
    /* The regions' bounding box: paths do not depend on how it is cut. */
    obs_dyn_box all = {{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    for (size_t i = 0; i < res->model.region_count; i++)
        for (int c = 0; c < 3; c++) {
            all.lo[c] = fminf(all.lo[c], res->model.regions[i].box.lo[c]);
            all.hi[c] = fmaxf(all.hi[c], res->model.regions[i].box.hi[c]);
        }
    double diag = 0.0;
    for (int c = 0; c < 3; c++)
        diag += ((double)all.hi[c] - all.lo[c]) * ((double)all.hi[c] - all.lo[c]);
    diag = sqrt(diag);
    const obs_dyn_model *mods[2] = {&res->original, &res->model};
    float dist[2] = {p.distance_short, p.distance_long};
    double se[4] = {0, 0, 0, 0}, sb[2] = {0, 0}, cs[3] = {0, 0, 0}, ss[3] = {0, 0, 0};
    size_t nsteps = 0, nval = 0;
    for (int path = 0; path < paths; path++) {
        float a[3], b[3];
        int found = 0;
        for (int t = 0; t < TRIES && !found; t++) {
            found = pick_point(&res->model, &all, bvh, p.backface_limit, &r, a) &&
                    pick_point(&res->model, &all, bvh, p.backface_limit, &r, b) &&
                    !obs__bake_bvh_occluded(bvh, a, b);
            double len = 0.0;
            for (int c = 0; c < 3; c++)
                len += ((double)b[c] - a[c]) * ((double)b[c] - a[c]);
            found = found && sqrt(len) >= 0.1 * diag;
        }
        if (!found)
            break;
        double z = 2.0 * obs__bake_rng_unit(&r) - 1.0, ph = 2.0 * PI_D * obs__bake_rng_unit(&r);
        float nr[2][3] = {{0.0f, 1.0f, 0.0f},
                          {(float)(sqrt(1.0 - z * z) * cos(ph)),
                           (float)(sqrt(1.0 - z * z) * sin(ph)), (float)z}};
        out->paths++;
        for (int ni = 0; ni < 2; ni++) {
            obs_dyn_blender bl = {0};
            for (int k = 0; k < steps; k++) {
                float q[3], ao[3];
                for (int c = 0; c < 3; c++)
                    q[c] = a[c] + (b[c] - a[c]) * (float)k / (float)(steps - 1);
                double tr[2];
                obs__dyn_trace_eq1(bvh, q, nr[ni], rays, dist, (uint64_t)p.seed,
                                   ((uint64_t)path * 2 + ni) * 65536 + (uint64_t)k, tr);
                double truth = p.blend * tr[0] + (1.0 - p.blend) * tr[1];
                for (int o = 0; o < 2; o++) {
                    obs_dyn_eval(&res->model, q, nr[ni], o ? OBS_DYN_QUADRATIC : OBS_DYN_LINEAR,
                                 ao);
                    se[o] += (ao[2] - truth) * (ao[2] - truth);
                    sb[o] += ao[2] - truth;
                }
                /* the point's own SH (no eq 4): what the projection alone loses */
                double sh[OBS_DYN_CHANNELS];
                int dropped;
                if (obs__point_sh(bvh, q, &p, ((uint64_t)path * 2 + ni) * 65536 + (uint64_t)k,
                                      sh, &dropped)) {
                    double v = p.blend * fmin(fmax(obs__sh_eval(sh, nr[ni], 2), 0.0), 1.0) +
                               (1.0 - p.blend) *
                                   fmin(fmax(obs__sh_eval(sh + OBS_DYN_SH, nr[ni], 2), 0.0), 1.0);
                    se[2] += (v - truth) * (v - truth);
                }
                nval++;
                for (int v = 0; v < 2; v++) {
                    reg[k * 2 + v] = obs_dyn_eval(mods[v], q, nr[ni], OBS_DYN_QUADRATIC, ao);
                    val[k * 4 + v] = ao[2];
                }
                se[3] += (val[k * 4] - truth) * (val[k * 4] - truth);
                obs_dyn_blend_step(&bl, &res->model, q, nr[ni], OBS_DYN_QUADRATIC, 1.0f, tau, ao);
                val[k * 4 + 2] = ao[2];
            }
            for (int k = 0; k + 1 < steps; k++) {
                int cross = reg[k * 2 + 1] != reg[(k + 1) * 2 + 1];
                out->crossings += (size_t)cross;
                nsteps += (size_t)!cross;
                for (int v = 0; v < 3; v++) {
                    double d = fabs(val[(k + 1) * 4 + v] - val[k * 4 + v]);
                    if (cross) {
                        cs[v] += d;
                        out->cross_max[v] = fmax(out->cross_max[v], d);
                    } else {
                        ss[v] += d;
                    }
                }
            }
        }
        out->points += (size_t)steps;
    }
    for (int o = 0; o < 2; o++) {
        out->rms[o] = nval ? sqrt(se[o] / (double)nval) : 0.0;
        out->bias[o] = nval ? sb[o] / (double)nval : 0.0;
    }
    out->rms_unregularised = nval ? sqrt(se[3] / (double)nval) : 0.0;
    out->rms_point_sh = nval ? sqrt(se[2] / (double)nval) : 0.0;
    for (int v = 0; v < 3; v++) {
        out->cross_mean[v] = out->crossings ? cs[v] / (double)out->crossings : 0.0;
        out->step_mean[v] = nsteps ? ss[v] / (double)nsteps : 0.0;
    }
    if (!out->paths)
        st = obs__fail(err, OBS_INVALID_ARGUMENT,
                       "paths: no two regions with a model whose points see each other");
done:
    free(val);
    free(reg);
    obs__bake_bvh_free(bvh);
    obs__bake_decor_free(&dc);
    obs__bake_world_free(&w);
    return st;
}
