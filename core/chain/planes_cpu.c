/* The CPU device's planes (passes_cpu.h): one block per frame, carved
 * into the planes, and kept for the next frame, as the GL device keeps
 * its textures per size.  A fresh block costs a page fault per 4 KiB
 * touched, which at 1920x1080 (about 100 MB of planes) took longer than
 * the prep pass itself. */
#include <pthread.h>
#include <stdlib.h>

#include "chain/passes_cpu.h"

/* The block the last frame gave back (NULL: none); one frame takes it
 * at a time, a frame that finds it taken allocates its own. */
static pthread_mutex_t kept_lock = PTHREAD_MUTEX_INITIALIZER;
static void *kept;
static size_t kept_size;

/* Planes start on a cache line. */
static size_t lines(size_t floats) { return (floats * sizeof(float) + 63) / 64 * 64; }

/* The block for `need` bytes: the kept one when it is large enough and
 * not more than twice that (so a frame of another size does not hold on
 * to a much larger one), else a new one. */
static void *take(size_t need, size_t *size)
{
    void *b = NULL, *drop = NULL;
    pthread_mutex_lock(&kept_lock);
    if (kept && kept_size >= need && kept_size / 2 <= need) {
        b = kept;
        *size = kept_size;
        kept = NULL;
    } else if (kept) {
        drop = kept;
        kept = NULL;
    }
    pthread_mutex_unlock(&kept_lock);
    free(drop);
    if (!b && (b = aligned_alloc(64, need)))
        *size = need;
    return b;
}

/* The bytes of each plane of c's frame (or band), in planes' order. */
#define PLANES 15
static size_t plane_sizes(const obs__cpu_run *c, size_t sizes[PLANES])
{
    const obs__frame *f = &c->pl->f, *af = c->pl->af;
    const int banded = c->row1 > 0; /* the rows of a band (passes_cpu.h) */
    const size_t n = banded ? (size_t)f->width * (size_t)(c->row1 - c->row0) : c->npx;
    const size_t an = (size_t)af->width *
                      (size_t)(!banded ? af->height : f->half ? c->hrow1 - c->hrow0 : c->row1 - c->row0);
    const size_t cn = (size_t)f->cull_w * (size_t)(banded ? c->crow1 - c->crow0 : f->cull_h);
    /* the AO's planes: a band's AO rows only */
    const size_t nao = banded ? (size_t)f->width * (size_t)(c->arow1 - c->arow0) : n;
    const size_t anao = banded && f->half ? (size_t)af->width * (size_t)(c->harow1 - c->harow0) : an;
    /* colour, packed RGBA, for sections 4.3 and 4.7 */
    const int col = f->luminance || f->bleed_step;
    /* the bleed term (4.7) only where the composite or the output reads
     * it (the AO pass writes it nowhere else): 12 bytes a pixel */
    const int bleed = f->bleed_step || (c->pl->outputs & OBS_OUTPUT_BLEED);
    const size_t s[PLANES] = {
        lines(n * 4), lines(n * 3), lines(nao), lines(nao), lines(cn),
        bleed ? lines(nao * 3) : 0, col ? lines(n * 4) : 0,
        f->half ? lines(an * 4) : 0, f->half ? lines(an * 3) : 0, f->half ? lines(anao) : 0,
        f->half ? lines(anao) : 0, f->half && bleed ? lines(anao * 3) : 0, lines(an * 2),
        f->half && f->mask_occl ? lines(an) : 0, f->half && f->mask_id ? lines(an) : 0,
    };
    size_t need = 0;
    for (int i = 0; i < PLANES; i++)
        need += sizes[i] = s[i];
    return need;
}

size_t obs__cpu_planes_need(const obs__cpu_run *c)
{
    size_t sizes[PLANES];
    return plane_sizes(c, sizes);
}

obs_status obs__cpu_planes_take(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    const obs__frame *f = &c->pl->f, *af = c->pl->af;
    size_t sizes[PLANES];
    const size_t need = plane_sizes(c, sizes);
    float **planes[PLANES] = {&c->pos,  &c->nrm,  &c->ao,   &c->tmp,  &c->est,    &c->bleed,
                              &c->col,  &c->hpos, &c->hnrm, &c->hao,  &c->htmp,   &c->hbleed,
                              &c->dnz,  &c->hmask_w, &c->hmask_id};
    unsigned char *b = take(need, &c->block_size);
    if (!b)
        return obs__fail(err, OBS_NO_MEMORY, "out of memory for a %dx%d frame", f->width,
                         f->height);
    c->block = b;
    for (int i = 0; i < PLANES; i++) {
        *planes[i] = sizes[i] ? (float *)(void *)b : NULL;
        b += sizes[i];
    }
    if (c->row1 > 0) { /* a band: each plane's pointer at the frame's row 0 */
        const size_t fw = (size_t)f->width * (size_t)c->row0, hw = (size_t)af->width * (size_t)c->hrow0;
        const size_t faw = (size_t)f->width * (size_t)c->arow0, haw = (size_t)af->width * (size_t)c->harow0;
        const int per_px[PLANES] = {4, 3, 1, 1, 0, 3, 4, 4, 3, 1, 1, 3, 2, 1, 1};
        /* the first row each plane holds: 0 its band's rows, 1 its AO rows; full or half size */
        const int ao_rows[PLANES] = {0, 0, 1, 1, 0, 1, 0, 0, 0, 1, 1, 1, 0, 0, 0};
        for (int i = 0; i < PLANES; i++) {
            if (!*planes[i] || i == 4)
                continue;
            const int half = i >= 7 && (f->half || i != 12); /* dnz (12) at the AO's size */
            *planes[i] -= (size_t)per_px[i] * (half ? (ao_rows[i] ? haw : hw) : ao_rows[i] ? faw : fw);
        }
        if (c->est)
            c->est -= (size_t)f->cull_w * (size_t)c->crow0;
    }
    c->apos = f->half ? c->hpos : c->pos;
    c->anrm = f->half ? c->hnrm : c->nrm;
    c->aao = f->half ? c->hao : c->ao;
    c->atmp = f->half ? c->htmp : c->tmp;
    c->ableed = f->half ? c->hbleed : c->bleed;
    return OBS_OK;
}

void obs__cpu_planes_give(obs__cpu_run *c)
{
    void *drop = c->block;
    if (!drop)
        return;
    pthread_mutex_lock(&kept_lock);
    if (!kept || kept_size < c->block_size) { /* keep the larger */
        void *older = kept;
        kept = c->block;
        kept_size = c->block_size;
        drop = older;
    }
    pthread_mutex_unlock(&kept_lock);
    free(drop);
    c->block = NULL;
}

unsigned long long obs_cpu_kept_bytes(void)
{
    pthread_mutex_lock(&kept_lock);
    unsigned long long n = kept ? kept_size : 0;
    pthread_mutex_unlock(&kept_lock);
    return n;
}

void obs_cpu_trim(unsigned long long budget)
{
    void *drop = NULL;
    pthread_mutex_lock(&kept_lock);
    if (kept && (budget == 0 || kept_size > budget)) {
        drop = kept;
        kept = NULL;
        kept_size = 0;
    }
    pthread_mutex_unlock(&kept_lock);
    free(drop);
}
