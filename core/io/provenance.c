/* Provenance of an output (obs_provenance, io.h): which obscura made it,
 * with which method and parameters, from which input and camera.  A TD
 * who finds an AO frame on disk can rerun it from obscura/params alone:
 * it lists only what differs from the defaults, so it stays short. */
#include <stdio.h>
#include <string.h>

#include "io/provenance.h"

/* "name=value ..." for every parameter of r (resolved) whose value
 * differs from d's (the defaults under the same method); `method`
 * itself against the table's default method. */
static void non_defaults(const obs_params *r, const obs_params *d, const obs_params *d0, char *buf,
                         size_t len)
{
    size_t off = 0;
    buf[0] = '\0';
    for (int i = 0; i < obs_param_count(); i++) {
        const obs_param_info *pi = obs_param_at(i);
        char v[OBS_SELECTOR_MAX + 32], dv[OBS_SELECTOR_MAX + 32], q[2 * OBS_SELECTOR_MAX + 64];
        obs_param_format(r, pi, v, sizeof v);
        obs_param_format(strcmp(pi->name, "method") ? d : d0, pi, dv, sizeof dv);
        if (!strcmp(v, dv))
            continue;
        /* a text value with a space or quote (a selector's names) in
         * double quotes, '"' and '\' escaped, so that the list splits */
        if (strpbrk(v, " \"\\")) {
            size_t k = 0;
            q[k++] = '"';
            for (const char *c = v; *c && k + 3 < sizeof q; c++) {
                if (*c == '"' || *c == '\\')
                    q[k++] = '\\';
                q[k++] = *c;
            }
            q[k++] = '"';
            q[k] = '\0';
        } else {
            snprintf(q, sizeof q, "%s", v);
        }
        int n = snprintf(buf + off, len - off, "%s%s=%s", off ? " " : "", pi->name, q);
        if (n < 0 || (size_t)n >= len - off) {
            buf[off] = '\0'; /* a whole entry or none */
            return;
        }
        off += (size_t)n;
    }
}

void obs__prov_build(const obs_provenance *p, obs__prov *out)
{
    out->count = 0;
    out->key[out->count] = "obscura/version";
    out->value[out->count++] = OBS_VERSION;
    if (!p)
        return;
    if (p->params) {
        obs_params r, d, d0;
        static const obs_params zero = {0};
        obs_params_resolve(p->params, &r);
        obs_params_resolve(&(obs_params){.method = r.method}, &d);
        obs_params_resolve(&zero, &d0);
        obs_param_format(&r, obs_param_find("method"), out->method, sizeof out->method);
        non_defaults(&r, &d, &d0, out->params, sizeof out->params);
        out->key[out->count] = "obscura/method";
        out->value[out->count++] = out->method;
        out->key[out->count] = "obscura/params";
        out->value[out->count++] = out->params;
    }
    if (p->input && *p->input) {
        out->key[out->count] = "obscura/input";
        out->value[out->count++] = p->input;
    }
    if (p->camera_source && *p->camera_source) {
        out->key[out->count] = "obscura/camera_source";
        out->value[out->count++] = p->camera_source;
    }
    for (int k = 0; p->attrs && p->attrs[k] && p->attrs[k + 1] && out->count < OBS__PROV_KEYS;
         k += 2) {
        out->key[out->count] = p->attrs[k];
        out->value[out->count++] = p->attrs[k + 1];
    }
}
