/* One frame: decode, queue to the GL worker, wait, encode; each stage
 * timed and counted.  The HTTP and binary servers both go through here,
 * so a frame is read and written the same way whichever way it came. */
#include <stdio.h>
#include <string.h>

#include "frame_path.h"
#include "obscura/deep.h"
#include "obscura/mask.h"
#include "stats.h"

/* An EXR answer's compression when the request names none (compression
 * auto): chosen for the round trip's time, not the bytes (bench/RESULTS.md,
 * "daemon round trip": the encode of a 1080p half AO per compression). */
#define OBSD_ANSWER_COMPRESSION OBS_EXR_RLE

static obs_status fail_strict(char err[OBS_ERR_LEN], const obs_exr_info *info)
{
    snprintf(err, OBS_ERR_LEN, "strict: %d sanity warning%s: %s", info->warning_count,
             info->warning_count == 1 ? "" : "s", info->warnings[0]);
    return OBS_BAD_FILE;
}

void obsd_fp_init(obsd_fp *fp)
{
    memset(fp, 0, sizeof *fp);
    pthread_mutex_init(&fp->lock, NULL);
    pthread_cond_init(&fp->cond, NULL);
}

void obsd_fp_free(obsd_fp *fp)
{
    obs_result_free(&fp->job.result);
    obs_deep_result_free(&fp->job.deep_result);
    obs_deep_ao_free(&fp->job.deep_nodes);
    obs_gbuffer_free(&fp->gf);
    obs_deep_free(&fp->deep_exr);
    obs_image_free(&fp->baked);
    pthread_cond_destroy(&fp->cond);
    pthread_mutex_destroy(&fp->lock);
}

/* The baked AO channel of a flat EXR body (baked=CH, else _AO when the
 * body has one; baked=none: not looked for), the G-buffer's size; the
 * chain's AO is combined with it once the frame has run
 * (obsd_fp_finished, obs_result_combine_baked). */
static obs_status read_baked(obsd_fp *fp, const unsigned char *body, size_t len,
                             const obs_http_request *hr, const obs_limits *lim,
                             char err[OBS_ERR_LEN])
{
    const char *name = hr->baked ? hr->baked : "_AO";
    if (!strcmp(name, "none"))
        return OBS_OK;
    char sub[OBS_ERR_LEN];
    obs_status s = obs_exr_read_channel_mem(body, len, name, lim, &fp->baked, sub);
    if (s == OBS_MISSING_CHANNEL && !hr->baked)
        return OBS_OK; /* not a baked level's G-buffer */
    if (s == OBS_OK && (fp->baked.width != fp->gf.gb.width || fp->baked.height != fp->gf.gb.height)) {
        snprintf(sub, sizeof sub, "it is %dx%d, the G-buffer %dx%d", fp->baked.width,
                 fp->baked.height, fp->gf.gb.width, fp->gf.gb.height);
        s = OBS_INVALID_ARGUMENT;
    }
    if (s != OBS_OK) {
        obs_image_free(&fp->baked);
        snprintf(err, OBS_ERR_LEN, "baked channel %.64s: %.400s", name, sub);
    }
    return s;
}

obs_status obsd_fp_decode(obsd_fp *fp, const unsigned char *body, size_t len,
                          const obs_http_request *hr, const obs_limits *lim, const char *no_deep,
                          char err[OBS_ERR_LEN])
{
    const obs_channel_map *map = &hr->map;
    double t0 = obsd_now_ms();
    /* A deep EXR runs the multi-layer chain (include/obscura/deep.h). */
    int deep = 0;
    obs_status s = obs_exr_is_deep_mem(body, len, &deep, err);
    if (s == OBS_OK && deep && no_deep)
        s = OBS_UNSUPPORTED, snprintf(err, OBS_ERR_LEN, "%s", no_deep);
    else if (s == OBS_OK && deep)
        s = obs_deep_read_exr_mem(body, len, lim, &fp->deep_exr, err);
    else if (s == OBS_OK)
        s = obs_gbuffer_read_exr_mem(body, len, map, lim, &fp->gf, err);
    /* object masks (receivers, occluders, self_only) from the same body */
    if (s == OBS_OK)
        s = deep ? obs_deep_read_masks(&fp->deep_exr, NULL, body, len, &hr->params, lim, err)
                 : obs_gbuffer_read_masks(&fp->gf, NULL, body, len, &hr->params, lim, err);
    if (s == OBS_OK && !deep)
        s = read_baked(fp, body, len, hr, lim, err);
    if (s == OBS_OK && !deep && hr->solve_camera && fp->gf.gb.position.data)
        s = obs_gbuffer_solve_camera(&fp->gf, &hr->params, err);
    /* strict: a sanity warning on the input fails the frame (HTTP 422),
     * so it is checked before the frame runs; else the check only adds
     * warnings to the answer, and runs while the chain does (obsd_fp_queue) */
    if (s == OBS_OK && !deep && hr->strict && obs_gbuffer_sanity(&fp->gf.gb, &hr->params, &fp->gf.info) > 0)
        s = fail_strict(err, &fp->gf.info);
    else if (s == OBS_OK && !deep)
        fp->sanity_params = &hr->params;
    fp->ms_decode = obsd_now_ms() - t0;
    obsd_stats_stage(OBSD_STAGE_DECODE, fp->ms_decode);
    if (s == OBS_OK)
        obsd_fp_use(fp, deep ? NULL : &fp->gf.gb, deep ? &fp->deep_exr : NULL);
    return s;
}

void obsd_fp_keep_source(obsd_fp *fp, const unsigned char *body, size_t len, int part)
{
    fp->src = body;
    fp->src_len = len;
    fp->src_part = part;
}

int obsd_fp_part(const obsd_fp *fp)
{
    return fp->deep == &fp->deep_exr ? fp->deep_exr.part : fp->gb == &fp->gf.gb ? fp->gf.info.part : 0;
}

obs_status obsd_fp_check_output(const obsd_fp *fp, const obs_http_request *hr, char err[OBS_ERR_LEN])
{
    if ((hr->outputs & OBS_OUTPUT_DEEP) && !fp->deep) {
        snprintf(err, OBS_ERR_LEN, "output=deep: the input is not a deep EXR (the deep AO is of deep input's nodes)");
        return OBS_INVALID_ARGUMENT;
    }
    if (!hr->append)
        return OBS_OK;
    if (!fp->src) {
        snprintf(err, OBS_ERR_LEN, "append=1 writes the input EXR back with the AO added: it needs the frame as an "
                 "EXR body (raw planes have no input file to write back)");
        return OBS_INVALID_ARGUMENT;
    }
    if (fp->deep) {
        snprintf(err, OBS_ERR_LEN, "append=1: the input is a deep EXR; appending the AO to a deep file is not "
                 "supported (ask without append)");
        return OBS_UNSUPPORTED;
    }
    return OBS_OK;
}

void obsd_fp_use(obsd_fp *fp, const obs_gbuffer *gb, const obs_deep_image *deep)
{
    fp->gb = deep ? NULL : gb;
    fp->deep = deep;
}

/* Called on the GL worker thread.  The frame may be gone once the caller
 * is told, so nothing of it is touched after that. */
static void job_done(obsd_job *job, void *user)
{
    (void)job;
    obsd_fp *fp = user;
    if (fp->on_done) {
        fp->on_done(fp->user);
        return;
    }
    pthread_mutex_lock(&fp->lock);
    fp->done = 1;
    pthread_cond_signal(&fp->cond);
    pthread_mutex_unlock(&fp->lock);
}

int obsd_fp_queue(obsd_fp *fp, obsd_queue *q, const obs_params *params, unsigned outputs,
                  void (*on_done)(void *user), void *user)
{
    if (fp->baked.data && !fp->deep)
        outputs |= OBS_OUTPUT_AO; /* the combination needs the chain's AO */
    fp->job = (obsd_job){.gb = fp->gb, .deep = fp->deep, .params = params, .outputs = outputs,
                         .done = job_done, .user = fp};
    fp->on_done = on_done;
    fp->user = user;
    fp->done = 0;
    if (obsd_queue_push(q, &fp->job) != 0)
        return -1;
    /* The input's sanity check beside the chain: both only read the
     * G-buffer, the check writes fp->gf.info, which the worker leaves
     * alone, and the caller reads the result only after this returns
     * (HTTP resumes the connection on this thread, once this callback has
     * returned; the binary server waits after). */
    if (fp->sanity_params) {
        double t0 = obsd_now_ms();
        obs_gbuffer_sanity(&fp->gf.gb, fp->sanity_params, &fp->gf.info);
        fp->ms_sanity = obsd_now_ms() - t0;
        fp->sanity_params = NULL;
    }
    return 0;
}

void obsd_fp_wait(obsd_fp *fp)
{
    pthread_mutex_lock(&fp->lock);
    while (!fp->done)
        pthread_cond_wait(&fp->cond, &fp->lock);
    pthread_mutex_unlock(&fp->lock);
}

obs_status obsd_fp_finished(obsd_fp *fp)
{
    const obsd_job *job = &fp->job;
    fp->ms_queue = job->t_started - job->t_queued;
    fp->ms_gl = job->t_finished - job->t_started;
    obsd_stats_stage(OBSD_STAGE_QUEUE, fp->ms_queue);
    obsd_stats_stage(OBSD_STAGE_GL, fp->ms_gl);
    if (job->status == OBS_OK && job->deep)
        obsd_stats_frame(job->deep->width, job->deep->height);
    else if (job->status == OBS_OK)
        obsd_stats_frame(job->gb->width, job->gb->height);
    if (job->status == OBS_OK && !job->deep)
        fp->has_cam = obs_camera_of_run(job->gb, job->params, &fp->cam);
    /* the result's own check (AO near 1 everywhere: a radius out of scale,
     * a wrong depth mode), a warning beside the input's */
    if (job->status == OBS_OK && job->deep)
        obs_result_sanity(&fp->job.deep_result.ao_front, NULL, job->deep, job->params, &fp->gf.info);
    else if (job->status == OBS_OK)
        obs_result_sanity(&fp->job.result.ao, job->gb, NULL, job->params, &fp->gf.info);
    if (job->status == OBS_OK && fp->baked.data && !job->deep)
        return obs_result_combine_baked(&fp->job.result, &fp->baked, job->params, fp->job.err);
    return job->status;
}

void obsd_fp_images_of(const obsd_fp *fp, unsigned outputs, obsd_fp_images *im)
{
    const obs_result *res = &fp->job.result;
    const obs_deep_result *dr = &fp->job.deep_result;
    *im = (obsd_fp_images){0};
    if (fp->job.deep) {
        /* the deep chain fills every image; the request picks */
        im->deep = 1;
        if (outputs & OBS_OUTPUT_AO) {
            im->ao = &dr->ao_blend;
            im->ao_front = &dr->ao_front;
        }
        if (outputs & OBS_OUTPUT_COMPOSITE)
            im->composite = &dr->composite;
        return;
    }
    /* the flat chain fills what was asked for (and the AO for a baked
     * channel's combination: answered only when asked for) */
    const int ao = (outputs & OBS_OUTPUT_AO) && res->ao.data;
    im->ao = ao ? &res->ao : NULL;
    im->ao_screen = ao && res->ao_screen.data ? &res->ao_screen : NULL;
    im->ao_baked = ao && res->ao_baked.data ? &res->ao_baked : NULL;
    im->composite = res->composite.data ? &res->composite : NULL;
    im->multibounce = res->multibounce.data ? &res->multibounce : NULL;
    im->samples = res->sample_count.data ? &res->sample_count : NULL;
    im->bent = res->bent.data ? &res->bent : NULL;
}

const obs_camera *obsd_fp_camera(const obsd_fp *fp)
{
    if (!fp->deep)
        return fp->has_cam ? &fp->cam : NULL;
    return fp->deep->camera.has_projection ? &fp->deep->camera : NULL;
}

const obs_image *obsd_fp_png_image(const obsd_fp_images *im)
{
    return im->ao ? im->ao : im->composite ? im->composite : im->multibounce ? im->multibounce : im->bent;
}

/* An image of the answer and its place in the result whose EXR layers
 * name it. */
typedef struct image_into {
    const obs_image *from;
    obs_image *to;
} image_into;

/* The images present copied into their places (the others stay empty). */
static void copy_present(const image_into *c, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (c[i].from)
            *c[i].to = *c[i].from;
}

/* The EXR layers of `im`, named by core's own tables. */
static int exr_layers(const obsd_fp_images *im, obs_result *flat, obs_deep_result *deep,
                      obs_exr_layer layers[OBS_RESULT_LAYERS])
{
    if (im->deep) {
        const image_into c[] = {{im->ao, &deep->ao_blend}, {im->ao_front, &deep->ao_front},
                                {im->composite, &deep->composite}};
        copy_present(c, sizeof c / sizeof c[0]);
        return obs_deep_result_exr_layers(deep, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE, layers);
    }
    const image_into c[] = {{im->ao, &flat->ao},
                            {im->composite, &flat->composite},
                            {im->ao_screen, &flat->ao_screen},
                            {im->ao_baked, &flat->ao_baked},
                            {im->multibounce, &flat->multibounce},
                            {im->samples, &flat->sample_count},
                            {im->bent, &flat->bent}};
    copy_present(c, sizeof c / sizeof c[0]);
    return obs_result_exr_layers(flat, layers);
}

obs_status obsd_fp_encode(obsd_fp *fp, const obsd_fp_images *im, const obs_http_request *hr, int raw,
                          const obs_camera *cam, obs_bytes *out, char err[OBS_ERR_LEN])
{
    double t0 = obsd_now_ms();
    obs_status s = OBS_OK;
    *out = (obs_bytes){0};
    if (raw) {
        /* nothing to write: the protocol sends the planes */
    } else if (hr->outputs & OBS_OUTPUT_DEEP) {
        /* every kept node's AO: the GL pass's (obs_deep_run_nodes), or on
         * the CPU device the CPU twin's, computed here; a file written as
         * it comes (obscura ao --server --output deep), so auto keeps the
         * file's compressions, as obscura ao writes them */
        obs_deep_ao computed = {0};
        const obs_deep_ao *nodes = &fp->job.deep_nodes;
        if (!nodes->offset) {
            s = obs_deep_ao_nodes(fp->deep, fp->job.params, &computed, err);
            nodes = &computed;
        }
        if (s == OBS_OK)
            s = obs_deep_ao_write_exr_mem(nodes, &fp->job.deep_result.ao_blend, &fp->job.deep_result.ao_front,
                                          (obs_exr_compression)hr->compression, out, err);
        obs_deep_ao_free(&computed);
    } else if (hr->format == OBS_HTTP_EXR) {
        /* copies of the image headers only: the pixels stay where they are */
        obs_result flat = {0};
        obs_deep_result deep = {0};
        obs_exr_layer layers[OBS_RESULT_LAYERS];
        obs_exr_names names;
        int n = exr_layers(im, &flat, &deep, layers);
        obs_exr_source src = {.buf = fp->src, .len = fp->src_len, .part = fp->src_part};
        obs_provenance prov = {.params = &hr->params}; /* the CLI's keys: clients/obscura.c provenance_of */
        obs_exr_options o = {.pixel = hr->float_exr ? OBS_EXR_FLOAT : OBS_EXR_HALF, .cam = cam,
                             .src = fp->src ? &src : NULL, .append = hr->append, .prov = &prov,
                             .compression = hr->compression ? (obs_exr_compression)hr->compression
                                                            : OBSD_ANSWER_COMPRESSION};
        if (hr->layer)
            s = obs_exr_layers_rename(layers, n, hr->layer, &names, err);
        if (s == OBS_OK)
            s = obs_exr_write_ex_mem(layers, n, &o, out, err);
    } else {
        const obs_image *img = obsd_fp_png_image(im);
        obs_provenance prov = {.params = &hr->params}; /* the CLI's keys: clients/obscura.c provenance_of */
        obs_png_options po = {.bits = hr->png_bits, .transfer = (obs_png_transfer)hr->png_transfer,
                              .display = img != im->ao, .prov = &prov};
        s = obs_png_write_ex_mem(img, &po, out, err);
    }
    fp->ms_encode = obsd_now_ms() - t0;
    obsd_stats_stage(OBSD_STAGE_ENCODE, fp->ms_encode);
    return s;
}
