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

obs_status obs__cpu_planes_take(obs__cpu_run *c, char err[OBS_ERR_LEN])
{
    const obs__frame *f = &c->pl->f, *af = c->pl->af;
    const size_t n = c->npx, an = (size_t)af->width * (size_t)af->height;
    /* colour, packed RGBA, for sections 4.3 and 4.7 */
    const int col = f->luminance || f->bleed_step;
    /* the bleed term (4.7) only where the composite or the output reads
     * it (the AO pass writes it nowhere else): 12 bytes a pixel */
    const int bleed = f->bleed_step || (c->pl->outputs & OBS_OUTPUT_BLEED);
    const size_t sizes[] = {
        lines(n * 4), lines(n * 3), lines(n), lines(n), lines((size_t)f->cull_w * (size_t)f->cull_h),
        bleed ? lines(n * 3) : 0, col ? lines(n * 4) : 0,
        f->half ? lines(an * 4) : 0, f->half ? lines(an * 3) : 0, f->half ? lines(an) : 0,
        f->half ? lines(an) : 0, f->half && bleed ? lines(an * 3) : 0, lines(an * 2),
        f->half && f->mask_occl ? lines(an) : 0, f->half && f->mask_id ? lines(an) : 0,
    };
    float **planes[] = {&c->pos,  &c->nrm,  &c->ao,   &c->tmp,  &c->est,    &c->bleed,
                        &c->col,  &c->hpos, &c->hnrm, &c->hao,  &c->htmp,   &c->hbleed,
                        &c->dnz,  &c->hmask_w, &c->hmask_id};
    size_t need = 0;
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++)
        need += sizes[i];
    unsigned char *b = take(need, &c->block_size);
    if (!b)
        return obs__fail(err, OBS_NO_MEMORY, "out of memory for a %dx%d frame", f->width,
                         f->height);
    c->block = b;
    for (size_t i = 0; i < sizeof sizes / sizeof sizes[0]; i++) {
        *planes[i] = sizes[i] ? (float *)(void *)b : NULL;
        b += sizes[i];
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
