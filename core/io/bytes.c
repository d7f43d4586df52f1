/* A growable byte buffer for the in-memory encoders (EXR, PNG). */
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "obscura/io.h"

void obs_bytes_free(obs_bytes *b)
{
    if (!b)
        return;
    free(b->data);
    b->data = NULL;
    b->size = 0;
}

int obs__membuf_write(obs__membuf *m, uint64_t offset, const void *data, size_t len)
{
    size_t end;
    if (offset > SIZE_MAX - len)
        return -1;
    end = (size_t)offset + len;
    if (end > m->cap) {
        size_t cap = m->cap ? m->cap : 65536;
        while (cap < end) {
            if (cap > SIZE_MAX / 2)
                return -1;
            cap *= 2;
        }
        unsigned char *p = realloc(m->data, cap);
        if (!p)
            return -1;
        m->data = p;
        m->cap = cap;
    }
    /* A write past the end (a seek ahead) leaves a gap: zero it. */
    if (offset > m->size)
        memset(m->data + m->size, 0, (size_t)offset - m->size);
    memcpy(m->data + offset, data, len);
    if (end > m->size)
        m->size = end;
    return 0;
}

void obs__membuf_take(obs__membuf *m, obs_bytes *out)
{
    out->data = m->data;
    out->size = m->size;
    m->data = NULL;
    m->size = m->cap = 0;
}
