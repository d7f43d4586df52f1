/* The runtime of the dynamic-object model (section 2.3, section 3): the
 * region of a point, eq 4 evaluated there, the SH for a normal, the
 * temporal blender, and the JSON file an engine loads. */
#include <cjson/cJSON.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dynamic/dyn_internal.h"
#include "internal.h"
#include "io/out_file.h"

#define FORMAT_NAME "obscura-dynamic-ao"
#define FORMAT_VERSION 1

void obs_dyn_model_free(obs_dyn_model *m)
{
    if (!m)
        return;
    free(m->regions);
    free(m->models);
    free(m->edge);
    memset(m, 0, sizeof *m);
}

static int inside_box(const obs_dyn_box *b, const float p[3])
{
    for (int a = 0; a < 3; a++)
        if (p[a] < b->lo[a] || p[a] > b->hi[a])
            return 0;
    return 1;
}

int obs_dyn_model_region_at(const obs_dyn_model *m, const float p[3], float clamped[3])
{
    int best = -1;
    double bd = INFINITY;
    for (size_t i = 0; i < m->region_count; i++) {
        const obs_dyn_model_region *r = &m->regions[i];
        if (inside_box(&r->box, p) && r->model >= 0) {
            if (clamped)
                memcpy(clamped, p, 3 * sizeof *p);
            return (int)i;
        }
        if (r->model < 0)
            continue;
        double d = 0.0;
        for (int a = 0; a < 3; a++) {
            double e = p[a] < r->box.lo[a] ? r->box.lo[a] - p[a]
                       : p[a] > r->box.hi[a] ? p[a] - r->box.hi[a] : 0.0;
            d += e * e;
        }
        if (d < bd)
            bd = d, best = (int)i;
    }
    if (best >= 0 && clamped)
        for (int a = 0; a < 3; a++)
            clamped[a] = fminf(fmaxf(p[a], m->regions[best].box.lo[a]), m->regions[best].box.hi[a]);
    return best;
}

static float clamp01(double v) { return (float)(v < 0.0 ? 0.0 : v > 1.0 ? 1.0 : v); }

void obs_dyn_eval_fit(const obs_dyn_fit *f, const float p[3], const float n[3],
                      obs_dyn_sh_order order, float ao[3])
{
    float q[3] = {p[0] - f->c[0], p[1] - f->c[1], p[2] - f->c[2]};
    double row[OBS_DYN_TERMS], ch[OBS_DYN_CHANNELS];
    obs__dyn_eq4_row(q, row); /* eq 4 */
    for (int k = 0; k < OBS_DYN_CHANNELS; k++) {
        double s = 0.0;
        for (int t = 0; t < OBS_DYN_TERMS; t++)
            s += row[t] * f->coef[k][t];
        ch[k] = s;
    }
    float len = sqrtf(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    float u[3] = {0.0f, 1.0f, 0.0f};
    if (len > 0.0f)
        u[0] = n[0] / len, u[1] = n[1] / len, u[2] = n[2] / len;
    ao[0] = clamp01(obs__sh_eval(ch, u, (int)order));
    ao[1] = clamp01(obs__sh_eval(ch + OBS_DYN_SH, u, (int)order));
    ao[2] = 0.0f; /* blended by the caller, who knows the model's blend */
}

int obs_dyn_eval(const obs_dyn_model *m, const float p[3], const float n[3],
                 obs_dyn_sh_order order, float ao[3])
{
    float q[3];
    int r = obs_dyn_model_region_at(m, p, q);
    if (r < 0) {
        ao[0] = ao[1] = ao[2] = 1.0f;
        return -1;
    }
    obs_dyn_eval_fit(&m->models[m->regions[r].model], q, n, order, ao);
    ao[2] = clamp01(m->blend * ao[0] + (1.0f - m->blend) * ao[1]); /* section 3 */
    return r;
}

int obs_dyn_blend_step(obs_dyn_blender *b, const obs_dyn_model *m, const float p[3],
                       const float n[3], obs_dyn_sh_order order, float dt, float tau,
                       float ao[3])
{
    float target[3];
    int r = obs_dyn_eval(m, p, n, order, target);
    /* "the visibility model is blended with the model used in the
     * previous frame ... using exponential decay" (section 2.3) */
    float k = !b->primed || tau <= 0.0f ? 1.0f : 1.0f - expf(-dt / tau);
    for (int c = 0; c < 3; c++) {
        b->value[c] += (target[c] - b->value[c]) * k;
        ao[c] = b->value[c];
    }
    b->primed = 1;
    b->region = r;
    return r;
}

/* ---- the file ------------------------------------------------------------ */

static cJSON *vec(const float *v, int n)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < n; i++)
        cJSON_AddItemToArray(a, cJSON_CreateNumber((double)v[i]));
    return a;
}

obs_status obs_dyn_model_write(const char *path, const obs_dyn_model *m, char err[OBS_ERR_LEN])
{
    cJSON *d = cJSON_CreateObject();
    cJSON_AddStringToObject(d, "format", FORMAT_NAME);
    cJSON_AddNumberToObject(d, "version", FORMAT_VERSION);
    if (m->level.triangles) {
        cJSON *lv = cJSON_AddObjectToObject(d, "level");
        char fp[32];
        snprintf(fp, sizeof fp, "%016llx", (unsigned long long)m->level.fingerprint);
        cJSON_AddStringToObject(lv, "fingerprint", fp);
        cJSON_AddNumberToObject(lv, "triangles", (double)m->level.triangles);
        cJSON_AddItemToObject(lv, "min", vec(m->level.lo, 3));
        cJSON_AddItemToObject(lv, "max", vec(m->level.hi, 3));
    }
    cJSON_AddItemToObject(d, "distances", vec(m->distance, 2));
    cJSON_AddNumberToObject(d, "blend", m->blend);
    cJSON_AddStringToObject(d, "sh", "real SH bands 0-2, index l(l+1)+m, convolved with the "
                                     "clamped cosine and divided by pi: AO(n) = sum c_k Y_k(n)");
    cJSON_AddStringToObject(d, "terms", "v_mean, +x, -x, +y, -y, +z, -z (eq 4)");
    cJSON *regs = cJSON_AddArrayToObject(d, "regions");
    for (size_t i = 0; i < m->region_count; i++) {
        const obs_dyn_model_region *r = &m->regions[i];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToObject(o, "min", vec(r->box.lo, 3));
        cJSON_AddItemToObject(o, "max", vec(r->box.hi, 3));
        cJSON_AddNumberToObject(o, "model", r->model);
        cJSON_AddBoolToObject(o, "absorbed", r->absorbed);
        cJSON_AddNumberToObject(o, "points", r->points);
        cJSON_AddItemToArray(regs, o);
    }
    cJSON *adj = cJSON_AddArrayToObject(d, "adjacency");
    for (size_t k = 0; k < m->edge_count; k++) {
        cJSON *e = cJSON_CreateArray();
        cJSON_AddItemToArray(e, cJSON_CreateNumber(m->edge[2 * k]));
        cJSON_AddItemToArray(e, cJSON_CreateNumber(m->edge[2 * k + 1]));
        cJSON_AddItemToArray(adj, e);
    }
    cJSON *mods = cJSON_AddArrayToObject(d, "models");
    for (size_t i = 0; i < m->model_count; i++) {
        const obs_dyn_fit *f = &m->models[i];
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToObject(o, "center", vec(f->c, 3));
        cJSON *co = cJSON_AddArrayToObject(o, "coefficients");
        for (int k = 0; k < OBS_DYN_CHANNELS; k++)
            cJSON_AddItemToArray(co, vec(f->coef[k], OBS_DYN_TERMS));
        cJSON_AddItemToArray(mods, o);
    }
    char *txt = cJSON_PrintUnformatted(d);
    cJSON_Delete(d);
    if (!txt)
        return obs__fail(err, OBS_NO_MEMORY, "model JSON");
    /* under a hidden temporary name, renamed when whole (io/out_file.h):
     * a cancelled farm task leaves no half model under the final name */
    obs__out_file out;
    FILE *f = fopen(obs__out_begin(&out, path), "w");
    int ok = f && fputs(txt, f) >= 0 && fputc('\n', f) != EOF;
    if (f && fclose(f) != 0)
        ok = 0;
    free(txt);
    return obs__out_end(&out, ok ? OBS_OK : obs__fail(err, OBS_IO, "%s: cannot write: %s", path,
                                                      strerror(errno)), err);
}

/* n numbers of a JSON array, each finite as a float (a double past
 * FLT_MAX would be read as an infinity). */
static int get_vec(const cJSON *a, float *v, int n)
{
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n)
        return 0;
    for (int i = 0; i < n; i++) {
        const cJSON *e = cJSON_GetArrayItem(a, i);
        if (!cJSON_IsNumber(e) || !(fabs(e->valuedouble) <= FLT_MAX))
            return 0;
        v[i] = (float)e->valuedouble;
    }
    return 1;
}

/* A JSON number that is an integer in lo .. hi, into *out. */
static int get_int(const cJSON *v, double lo, double hi, double *out)
{
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= lo && v->valuedouble <= hi) ||
        v->valuedouble != floor(v->valuedouble))
        return 0;
    *out = v->valuedouble;
    return 1;
}

obs_status obs_dyn_model_read(const char *path, obs_dyn_model *out, char err[OBS_ERR_LEN])
{
    memset(out, 0, sizeof *out);
    FILE *f = fopen(path, "rb");
    if (!f)
        return obs__fail(err, OBS_IO, "%s: %s", path, strerror(errno));
    long len = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    char *buf = len >= 0 && len <= (256L << 20) ? malloc((size_t)len + 1) : NULL;
    if (!buf || fseek(f, 0, SEEK_SET) != 0 || fread(buf, 1, (size_t)len, f) != (size_t)len) {
        fclose(f);
        free(buf);
        return obs__fail(err, OBS_IO, "%s: cannot read (at most 256 MiB)", path);
    }
    fclose(f);
    buf[len] = '\0';
    cJSON *d = cJSON_Parse(buf);
    free(buf);
    obs_status st = OBS_OK;
    const cJSON *fmt = cJSON_GetObjectItemCaseSensitive(d, "format");
    const cJSON *regs = cJSON_GetObjectItemCaseSensitive(d, "regions");
    const cJSON *mods = cJSON_GetObjectItemCaseSensitive(d, "models");
    const cJSON *adj = cJSON_GetObjectItemCaseSensitive(d, "adjacency");
    const cJSON *bl = cJSON_GetObjectItemCaseSensitive(d, "blend");
    if (!d || !cJSON_IsString(fmt) || strcmp(fmt->valuestring, FORMAT_NAME) ||
        !cJSON_IsArray(regs) || !cJSON_IsArray(mods) || !cJSON_IsNumber(bl) ||
        !get_vec(cJSON_GetObjectItemCaseSensitive(d, "distances"), out->distance, 2)) {
        st = obs__fail(err, OBS_BAD_FILE, "%s: not an %s model (format, distances, blend, "
                                          "regions, models)", path, FORMAT_NAME);
        goto done;
    }
    if (!(bl->valuedouble >= 0.0 && bl->valuedouble <= 1.0) ||
        !(out->distance[0] > 0.0f && out->distance[1] > 0.0f)) {
        st = obs__fail(err, OBS_BAD_FILE, "%s: blend %g (a weight in 0 .. 1), distances %g, %g "
                       "(positive)", path, bl->valuedouble, (double)out->distance[0],
                       (double)out->distance[1]);
        goto done;
    }
    out->blend = (float)bl->valuedouble;
    const cJSON *lv = cJSON_GetObjectItemCaseSensitive(d, "level");
    if (lv) {
        const cJSON *fp = cJSON_GetObjectItemCaseSensitive(lv, "fingerprint");
        const cJSON *nt = cJSON_GetObjectItemCaseSensitive(lv, "triangles");
        char *end = NULL;
        unsigned long long v = cJSON_IsString(fp) ? strtoull(fp->valuestring, &end, 16) : 0;
        if (!cJSON_IsString(fp) || strlen(fp->valuestring) != 16 || *end || !cJSON_IsNumber(nt) ||
            !(nt->valuedouble >= 1.0) || nt->valuedouble > 9e15 ||
            !get_vec(cJSON_GetObjectItemCaseSensitive(lv, "min"), out->level.lo, 3) ||
            !get_vec(cJSON_GetObjectItemCaseSensitive(lv, "max"), out->level.hi, 3)) {
            st = obs__fail(err, OBS_BAD_FILE, "%s: level: a fingerprint (16 hex digits), "
                                              "triangles, min and max", path);
            goto done;
        }
        out->level.fingerprint = v;
        out->level.triangles = (uint64_t)nt->valuedouble;
    }
    out->region_count = (size_t)cJSON_GetArraySize(regs);
    out->model_count = (size_t)cJSON_GetArraySize(mods);
    out->edge_count = cJSON_IsArray(adj) ? (size_t)cJSON_GetArraySize(adj) : 0;
    out->regions = calloc(out->region_count + 1, sizeof *out->regions);
    out->models = calloc(out->model_count + 1, sizeof *out->models);
    out->edge = calloc(2 * out->edge_count + 1, sizeof *out->edge);
    if (!out->regions || !out->models || !out->edge) {
        st = obs__fail(err, OBS_NO_MEMORY, "%s", path);
        goto done;
    }
    size_t i = 0;
    const cJSON *it;
    cJSON_ArrayForEach(it, regs)
    {
        obs_dyn_model_region *r = &out->regions[i];
        const cJSON *pn = cJSON_GetObjectItemCaseSensitive(it, "points");
        double mi, points = 0;
        if (!get_vec(cJSON_GetObjectItemCaseSensitive(it, "min"), r->box.lo, 3) ||
            !get_vec(cJSON_GetObjectItemCaseSensitive(it, "max"), r->box.hi, 3) ||
            !(r->box.lo[0] <= r->box.hi[0] && r->box.lo[1] <= r->box.hi[1] &&
              r->box.lo[2] <= r->box.hi[2]) ||
            !get_int(cJSON_GetObjectItemCaseSensitive(it, "model"), -1,
                     (double)out->model_count - 1, &mi) ||
            (pn && !get_int(pn, 0, UINT32_MAX, &points))) {
            st = obs__fail(err, OBS_BAD_FILE, "%s: region %zu: min <= max, a model index in "
                                              "-1 .. %lld and a count of points", path, i,
                           (long long)out->model_count - 1);
            goto done;
        }
        r->model = (int32_t)mi;
        r->absorbed = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(it, "absorbed"));
        r->points = (uint32_t)points;
        i++;
    }
    i = 0;
    cJSON_ArrayForEach(it, mods)
    {
        obs_dyn_fit *m = &out->models[i];
        const cJSON *co = cJSON_GetObjectItemCaseSensitive(it, "coefficients");
        int ok = get_vec(cJSON_GetObjectItemCaseSensitive(it, "center"), m->c, 3) &&
                 cJSON_IsArray(co) && cJSON_GetArraySize(co) == OBS_DYN_CHANNELS;
        for (int k = 0; ok && k < OBS_DYN_CHANNELS; k++)
            ok = get_vec(cJSON_GetArrayItem(co, k), m->coef[k], OBS_DYN_TERMS);
        if (!ok) {
            st = obs__fail(err, OBS_BAD_FILE, "%s: model %zu: a center and %d x %d coefficients",
                           path, i, OBS_DYN_CHANNELS, OBS_DYN_TERMS);
            goto done;
        }
        i++;
    }
    i = 0;
    cJSON_ArrayForEach(it, adj)
    {
        double e[2];
        double last = (double)out->region_count - 1;
        if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != 2 ||
            !get_int(cJSON_GetArrayItem(it, 0), 0, last, &e[0]) ||
            !get_int(cJSON_GetArrayItem(it, 1), 0, last, &e[1])) {
            st = obs__fail(err, OBS_BAD_FILE, "%s: adjacency %zu: two region indices in 0 .. "
                           "%lld", path, i, (long long)last);
            goto done;
        }
        out->edge[2 * i] = (uint32_t)e[0];
        out->edge[2 * i + 1] = (uint32_t)e[1];
        i++;
    }
done:
    cJSON_Delete(d);
    if (st != OBS_OK)
        obs_dyn_model_free(out);
    return st;
}
