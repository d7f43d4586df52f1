/* A request's query arguments, walked for the route that reads them
 * (http_frames.c, http_bakes.c): each one checked for a NUL byte (%00
 * would end the C string: 'radius=0.5%00x' would read 0.5), then given to
 * the route's function, up to the first error. */
#include "http_internal.h"

typedef struct walk {
    obsd__req *r;
    obsd__arg_fn fn;
    obs_status status;
    char *err;
} walk;

static enum MHD_Result on_arg(void *cls, enum MHD_ValueKind kind, const char *key, size_t key_size,
                              const char *value, size_t value_size)
{
    walk *w = cls;
    (void)kind;
    if (w->status != OBS_OK)
        return MHD_NO;
    if ((w->status = obs_http_value_check(key, key_size, value, value_size, w->err)) != OBS_OK)
        return MHD_NO;
    w->status = w->fn(w->r, key, value ? value : "", w->err);
    return w->status == OBS_OK ? MHD_YES : MHD_NO;
}

obs_status obsd__query_args(obsd__req *r, obsd__arg_fn fn, char err[OBS_ERR_LEN])
{
    walk w = {r, fn, OBS_OK, err};
    err[0] = '\0';
    MHD_get_connection_values_n(r->conn, MHD_GET_ARGUMENT_KIND, on_arg, &w);
    return w.status;
}
