/* The baked level as binary PLY for MeshLab: every instance in world space
 * (node transforms applied), per vertex x y z, quality (= _AO, MeshLab's
 * per-vertex quality), ao_short, ao_long; triangles as vertex_indices. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "io/out_file.h"
#include "obscura/bake.h"

obs_status obs_bake_write_ply(const char *path, const obs_bake_scene *scene,
                              const obs_bake_result *r, char err[OBS_ERR_LEN])
{
    size_t nv = 0, nt = 0;
    for (size_t i = 0; i < r->instance_count; i++) {
        if (r->instances[i].mesh >= scene->mesh_count || r->instances[i].node >= scene->node_count)
            return obs__fail(err, OBS_INVALID_ARGUMENT, "%s: the bake result does not belong to this scene", path);
        nv += scene->meshes[r->instances[i].mesh].vertex_count;
        nt += scene->meshes[r->instances[i].mesh].triangle_count;
    }
    if (nv > UINT32_MAX)
        return obs__fail(err, OBS_TOO_LARGE, "%s: %zu vertices do not fit PLY's 32-bit indices",
                         path, nv);
    /* under a hidden temporary name, renamed when whole (io/out_file.h) */
    obs__out_file out;
    FILE *f = fopen(obs__out_begin(&out, path), "wb");
    if (!f)
        return obs__out_end(&out, obs__fail(err, OBS_IO, "%s: cannot write: %s", path,
                                             strerror(errno)), err);
    int ok = fprintf(f,
                     "ply\nformat binary_little_endian 1.0\ncomment obscura bake %s\n"
                     "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n"
                     "property float quality\nproperty float ao_short\nproperty float ao_long\n"
                     "element face %zu\nproperty list uchar uint vertex_indices\nend_header\n",
                     OBS_VERSION, nv, nt) > 0;
    for (size_t i = 0; ok && i < r->instance_count; i++) {
        const obs_bake_instance *in = &r->instances[i];
        const obs_bake_mesh *m = &scene->meshes[in->mesh];
        const float *w = scene->nodes[in->node].world;
        for (size_t v = 0; ok && v < m->vertex_count; v++) {
            const float *p = m->positions + 3 * v;
            float rec[6];
            for (int k = 0; k < 3; k++)
                rec[k] = w[4 * k] * p[0] + w[4 * k + 1] * p[1] + w[4 * k + 2] * p[2] + w[4 * k + 3];
            rec[3] = in->ao[v];
            rec[4] = in->ao_short[v];
            rec[5] = in->ao_long[v];
            ok = fwrite(rec, sizeof rec, 1, f) == 1;
        }
    }
    uint32_t base = 0;
    for (size_t i = 0; ok && i < r->instance_count; i++) {
        const obs_bake_mesh *m = &scene->meshes[r->instances[i].mesh];
        for (size_t t = 0; ok && t < m->triangle_count; t++) {
            unsigned char rec[13];
            rec[0] = 3;
            for (int k = 0; k < 3; k++) {
                uint32_t ix = base + m->indices[3 * t + k];
                memcpy(rec + 1 + 4 * k, &ix, 4);
            }
            ok = fwrite(rec, sizeof rec, 1, f) == 1;
        }
        base += (uint32_t)m->vertex_count;
    }
    if (fclose(f) != 0)
        ok = 0;
    return obs__out_end(&out, ok ? OBS_OK : obs__fail(err, OBS_IO, "%s: write failed: %s", path,
                                                      strerror(errno)), err);
}
