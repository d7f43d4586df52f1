/* The one path of a frame through the daemon, shared by the HTTP server
 * and the binary-protocol server:
 *
 *   decode     an EXR body (flat or deep) into the frame's G-buffer, on
 *              the network thread; or planes the protocol decoded itself
 *   queue      the job to the GL worker (a full queue is refused); the
 *              input's sanity check then runs on the network thread while
 *              the worker runs the chain (before it, under strict)
 *   wait       obsd_fp_wait(), or a callback on the GL worker thread for a
 *              caller that must not block (HTTP resumes its connection)
 *   finished   the job's queue and GL times, the frame's size class
 *   encode     the images asked for as EXR or PNG (or none: raw planes)
 *
 * Each step counts its stage in the metrics (stats.h): decode (EXR bodies
 * only), queue, gl, the frame class (frames that ran), encode.  Answering
 * and counting the request itself stay with the transport. */
#ifndef OBSD_FRAME_PATH_H
#define OBSD_FRAME_PATH_H

#include "http.h"
#include "job.h"
#include "obscura/io.h"

typedef struct obsd_fp {
    /* the input the job runs: one of them, pointing into gf / deep_exr
     * after obsd_fp_decode(), or the caller's (obsd_fp_use()) */
    const obs_gbuffer *gb;
    const obs_deep_image *deep;
    obs_gbuffer_file gf;      /* a decoded flat EXR (owned) */
    obs_deep_image deep_exr;  /* a decoded deep EXR (owned) */
    obs_image baked;          /* the input's baked AO channel (baked=, default _AO), or none */
    /* the EXR body the input came from (the caller's, kept until the
     * encode: obsd_fp_keep_source()), or NULL */
    const unsigned char *src;
    size_t src_len;
    int src_part;             /* its part the input was read from */
    obsd_job job;             /* its result is owned until obsd_fp_free() */
    obs_camera cam;           /* flat: the camera the job ran with (obsd_fp_finished) */
    int has_cam;
    double ms_decode, ms_queue, ms_gl, ms_encode;
    double ms_receive;        /* the transport's: the body's arrival (HTTP), else 0 */
    /* the input's sanity check, run beside the chain once queued (not
     * strict: its warnings go with the answer), and its time */
    const obs_params *sanity_params;
    double ms_sanity;
    /* the way back from the GL worker */
    void (*on_done)(void *user);
    void *user;
    pthread_mutex_t lock;
    pthread_cond_t cond;
    int done;
} obsd_fp;

/* The images an answer holds; NULL for those not asked for.  `composite`
 * also carries a plain colour image (HTTP's kept frames), written the
 * same way.  `deep` names the EXR layers as the deep chain does. */
typedef struct obsd_fp_images {
    const obs_image *ao;       /* AO.Y (deep: the blended AO) */
    const obs_image *ao_front; /* deep: AOFront.Y */
    const obs_image *composite;
    const obs_image *ao_screen, *ao_baked; /* with a baked channel: AOScreen.Y, AOBaked.Y */
    const obs_image *multibounce, *samples; /* AOMultiBounce.R,G,B; Samples.Y (output aovs) */
    const obs_image *bent;                  /* BentNormal.X,Y,Z */
    int deep;
} obsd_fp_images;

/* An empty frame; free it with obsd_fp_free(). */
void obsd_fp_init(obsd_fp *fp);
/* Frees what the frame holds: the decoded input, the result. */
void obsd_fp_free(obsd_fp *fp);

/* Reads an EXR body: a deep one into fp->deep_exr (refused with OBS_UNSUPPORTED
 * and the message `no_deep` when that is set), else a G-buffer with
 * hr->map, checked for sanity under hr->params: here with hr->strict (a
 * warning fails it: OBS_BAD_FILE), else in obsd_fp_queue, beside the
 * chain (hr must live until then).  Sizes are checked against lim.  Sets
 * ms_decode either way. */
obs_status obsd_fp_decode(obsd_fp *fp, const unsigned char *body, size_t len,
                          const obs_http_request *hr, const obs_limits *lim, const char *no_deep,
                          char err[OBS_ERR_LEN]);
/* The EXR body the input was decoded from (its part `part`), which the
 * caller keeps until the encode: the answer takes its windows and header
 * attributes, and append=1 writes it back with the AO added. */
void obsd_fp_keep_source(obsd_fp *fp, const unsigned char *body, size_t len, int part);
/* The part of the decoded EXR the input was read from (0 for planes). */
int obsd_fp_part(const obsd_fp *fp);
/* Refuses, before the frame runs, what the encode could not do for hr:
 * append=1 without an EXR body kept, or with deep input. */
obs_status obsd_fp_check_output(const obsd_fp *fp, const obs_http_request *hr, char err[OBS_ERR_LEN]);
/* Runs planes decoded elsewhere (gb or deep); they must outlive the frame. */
void obsd_fp_use(obsd_fp *fp, const obs_gbuffer *gb, const obs_deep_image *deep);

/* Queues the input with params and outputs (which must outlive the job).
 * With on_done, it is called on the GL worker thread when the job is
 * finished (it must not block); without, obsd_fp_wait() waits for that.
 * 0: queued; -1: the queue is full or closed. */
int obsd_fp_queue(obsd_fp *fp, obsd_queue *q, const obs_params *params, unsigned outputs,
                  void (*on_done)(void *user), void *user);
/* Waits for a job queued without on_done. */
void obsd_fp_wait(obsd_fp *fp);
/* The job is back: its times and the frame into the metrics.  Returns its
 * status (the message is in fp->job.err). */
obs_status obsd_fp_finished(obsd_fp *fp);

/* The images of the finished job for `outputs` (OBS_OUTPUT_AO and/or
 * OBS_OUTPUT_COMPOSITE), and the camera to write with them: the one the
 * job ran with, the parameters' over the input's, as obscura ao writes
 * it (NULL when there is no projection). */
void obsd_fp_images_of(const obsd_fp *fp, unsigned outputs, obsd_fp_images *im);
const obs_camera *obsd_fp_camera(const obsd_fp *fp);
/* The one image a PNG of `im` shows: the AO, else the composite, else the
 * multi-bounce AO. */
const obs_image *obsd_fp_png_image(const obsd_fp_images *im);

/* Writes `im` as hr asks (format exr|png, float, png_bits, layer,
 * append; the kept source's windows and attributes) into *out
 * (caller frees with obs_bytes_free()); with `raw`, writes nothing (the
 * caller sends the images as they are).  Sets ms_encode and counts it,
 * failed or not. */
obs_status obsd_fp_encode(obsd_fp *fp, const obsd_fp_images *im, const obs_http_request *hr, int raw,
                          const obs_camera *cam, obs_bytes *out, char err[OBS_ERR_LEN]);

#endif
