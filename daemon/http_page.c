/* The preview page: static files under daemon/preview, embedded into the
 * daemon at build time (tools/embed_files.sh), so that it works offline
 * and needs no install step.  GET / is index.html; the rest is under
 * /preview/.  No token: the page holds no data (its API calls carry the
 * token the user types in). */
#include <string.h>

#include "http_internal.h"
#include "obsd_page.h"

typedef obsd__req req;

enum MHD_Result obsd__page(req *r, const char *url)
{
    if (strcmp(r->method, "GET") != 0 && strcmp(r->method, "HEAD") != 0)
        return obsd__answer_error(r, 405, "method_not_allowed", "the page takes GET", MHD_HTTP_HEADER_ALLOW,
                                  "GET");
    const char *path = !strcmp(url, "/") ? "/preview/index.html" : url;
    for (const struct obsd__page_file *f = obsd__page_files; f->path; f++) {
        if (strcmp(f->path, path) != 0)
            continue;
        struct MHD_Response *resp =
            MHD_create_response_from_buffer(f->size, (void *)f->data, MHD_RESPMEM_PERSISTENT);
        if (!resp)
            return MHD_NO;
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, f->type);
        MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
        MHD_add_response_header(resp, "X-Content-Type-Options", "nosniff");
        return obsd__answer(r, 200, resp, f->size, NULL);
    }
    return obsd__answer_error(r, 404, "not_found", "no such file of the preview page", NULL, NULL);
}
