/* Server-Sent Events, the one way both event routes answer
 * (GET /v1/streams/NAME/events, GET /v1/bakes/ID/events): a 200 whose
 * body is the source's events, one at a time, with the headers a proxy
 * needs not to buffer them.
 *
 * An event stream is a suspended connection: the content reader parks it
 * when the source has nothing to send (the source calls
 * obsd__events_park) and the source wakes it (new event, keep-alive,
 * shutdown), so it holds no thread while it waits. */
#include <string.h>

#include "http_internal.h"

void obsd__events_park(void *arg)
{
    obsd__req *r = arg;
    MHD_suspend_connection(r->conn);
}

void obsd__events_wake(void *arg)
{
    obsd__req *r = arg;
    MHD_resume_connection(r->conn);
}

static ssize_t reader(void *cls, uint64_t pos, char *buf, size_t max)
{
    obsd__events *ev = cls;
    (void)pos;
    if (ev->r->cn && atomic_load(&ev->r->cn->cut))
        return MHD_CONTENT_READER_END_WITH_ERROR; /* the client left (or the drain): MHD closes it */
    if (ev->off >= ev->len) {
        int n = ev->next(ev->r, ev->buf, sizeof ev->buf);
        if (n < 0)
            return MHD_CONTENT_READER_END_OF_STREAM;
        if (n == 0)
            return 0; /* parked: the connection is suspended until woken */
        ev->len = n;
        ev->off = 0;
    }
    size_t k = (size_t)(ev->len - ev->off);
    if (k > max)
        k = max;
    memcpy(buf, ev->buf + ev->off, k);
    ev->off += (int)k;
    return (ssize_t)k;
}

static enum MHD_Result answer(obsd__req *r, obsd__events *ev)
{
    ev->r = r;
    struct MHD_Response *resp = MHD_create_response_from_callback(MHD_SIZE_UNKNOWN, 1024, reader, ev, NULL);
    if (!resp)
        return MHD_NO;
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, "text/event-stream");
    MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL, "no-cache");
    MHD_add_response_header(resp, "X-Accel-Buffering", "no");
    r->state = REQ_EVENTS;
    if (r->cn)
        atomic_store(&r->cn->events, 1);
    return obsd__answer(r, 200, resp, 0, "event stream opened");
}

enum MHD_Result obsd__events_open(obsd__req *r, obsd__events *ev,
                                  int (*join)(obsd__req *r, enum MHD_Result *rc),
                                  int (*next)(obsd__req *r, char *buf, size_t len),
                                  void (*leave)(obsd__req *r))
{
    enum MHD_Result rc;
    if (atomic_load(&r->srv->draining))
        return obsd__answer_shutting_down(r);
    if (!join(r, &rc))
        return rc;
    ev->leave = leave;
    ev->next = next;
    return answer(r, ev);
}

void obsd__events_close(obsd__req *r, obsd__events *ev)
{
    if (ev->leave)
        ev->leave(r);
    ev->leave = NULL;
}
