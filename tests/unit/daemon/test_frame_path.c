/* The frame path (daemon/frame_path.c) without GL: EXR bodies decoded
 * flat or deep (deep refused where asked), a job handed back by a
 * stand-in worker both ways (waited for, or a callback), a full queue
 * refused, the images picked for the outputs asked, and the encodings. */
#include <pthread.h>

#include "testutil.h"

#include "frame_path.h"

static void *worker(void *arg);

static void test_decode(void **state)
{
    (void)state;
    size_t len;
    char err[OBS_ERR_LEN] = "";
    obs_http_request hr;
    obsd_fp fp;
    obs_http_request_init(&hr);

    unsigned char *flat = obs_test_slurp(TESTDATA "/room_small.exr", &len);
    obsd_fp_init(&fp);
    assert_int_equal(obsd_fp_decode(&fp, flat, len, &hr, NULL, "no deep here", err), OBS_OK);
    assert_ptr_equal(fp.gb, &fp.gf.gb);
    assert_null(fp.deep);
    assert_true(fp.gb->width > 0 && fp.ms_decode >= 0.0);
    obsd_fp_free(&fp);

    /* strict=1: a sanity warning on the input fails the frame (world
     * normals read as camera-space disagree with the depth's); without
     * it the check waits for the queue, where it runs beside the chain */
    obsd_fp_init(&fp);
    assert_int_equal(obs_http_request_set(&hr, "normal_space", "camera", err), OBS_OK);
    assert_int_equal(obs_http_request_set(&hr, "fov_y", "50", err), OBS_OK);
    assert_int_equal(obsd_fp_decode(&fp, flat, len, &hr, NULL, NULL, err), OBS_OK);
    assert_int_equal(fp.gf.info.warning_count, 0);
    assert_ptr_equal(fp.sanity_params, &hr.params);
    obsd_queue q;
    pthread_t t;
    assert_int_equal(obsd_queue_init(&q, 1), 0);
    assert_int_equal(obsd_fp_queue(&fp, &q, &hr.params, OBS_OUTPUT_AO, NULL, NULL), 0);
    assert_true(fp.gf.info.warning_count >= 1); /* checked once queued */
    assert_null(fp.sanity_params);
    assert_int_equal(pthread_create(&t, NULL, worker, &q), 0);
    obsd_fp_wait(&fp);
    pthread_join(t, NULL);
    assert_int_equal(obsd_fp_finished(&fp), OBS_OK);
    assert_true(fp.gf.info.warning_count >= 1); /* the input's, with the answer */
    obsd_queue_destroy(&q);
    obsd_fp_free(&fp);
    obsd_fp_init(&fp);
    assert_int_equal(obs_http_request_set(&hr, "strict", "1", err), OBS_OK);
    assert_int_equal(obsd_fp_decode(&fp, flat, len, &hr, NULL, NULL, err), OBS_BAD_FILE);
    assert_non_null(strstr(err, "strict: "));
    obsd_fp_free(&fp);
    obs_http_request_init(&hr);
    free(flat);

    unsigned char *deep = obs_test_slurp(TESTDATA "/deep_small.exr", &len);
    obsd_fp_init(&fp);
    assert_int_equal(obsd_fp_decode(&fp, deep, len, &hr, NULL, "no deep here", err), OBS_UNSUPPORTED);
    assert_string_equal(err, "no deep here");
    assert_null(fp.gb);
    assert_null(fp.deep);
    obsd_fp_free(&fp);
    obsd_fp_init(&fp);
    assert_int_equal(obsd_fp_decode(&fp, deep, len, &hr, NULL, NULL, err), OBS_OK);
    assert_ptr_equal(fp.deep, &fp.deep_exr);
    assert_null(fp.gb);
    assert_int_equal(obsd_fp_camera(&fp) != NULL, fp.deep_exr.camera.has_projection);
    obsd_fp_free(&fp);
    free(deep);

    obsd_fp_init(&fp);
    assert_int_not_equal(obsd_fp_decode(&fp, (const unsigned char *)"not an EXR", 10, &hr, NULL, NULL, err),
                         OBS_OK);
    assert_true(err[0] != '\0');
    obsd_fp_free(&fp);
}

/* A stand-in GL worker: finishes one job with an AO image of w x 1. */
static void *worker(void *arg)
{
    obsd_queue *q = arg;
    obsd_job *job = obsd_queue_pop(q);
    if (!job)
        return NULL;
    job->t_started = job->t_queued + 2.0;
    job->result.ao = (obs_image){job->gb->width, 1, 1, calloc((size_t)job->gb->width, sizeof(float))};
    job->status = OBS_OK;
    job->t_finished = job->t_started + 3.0;
    obsd_queue_done(q);
    job->done(job, job->user);
    return NULL;
}

typedef struct called {
    pthread_mutex_t lock;
    pthread_cond_t cond;
    int n;
} called;

static void on_done(void *user)
{
    called *c = user;
    pthread_mutex_lock(&c->lock);
    c->n++;
    pthread_cond_signal(&c->cond);
    pthread_mutex_unlock(&c->lock);
}

static void test_queue_wait_and_callback(void **state)
{
    (void)state;
    obsd_queue q;
    obs_params params = {0};
    obs_gbuffer gb = {.width = 8, .height = 4};
    assert_int_equal(obsd_queue_init(&q, 1), 0);

    for (int cb = 0; cb < 2; cb++) {
        called c = {PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, 0};
        obsd_fp fp;
        pthread_t t;
        obsd_fp_init(&fp);
        obsd_fp_use(&fp, &gb, NULL);
        assert_int_equal(obsd_fp_queue(&fp, &q, &params, OBS_OUTPUT_AO, cb ? on_done : NULL, &c), 0);
        assert_ptr_equal(fp.job.gb, &gb);
        assert_ptr_equal(fp.job.params, &params);
        assert_int_equal(pthread_create(&t, NULL, worker, &q), 0);
        if (cb) {
            pthread_mutex_lock(&c.lock);
            while (!c.n)
                pthread_cond_wait(&c.cond, &c.lock);
            pthread_mutex_unlock(&c.lock);
        } else {
            obsd_fp_wait(&fp);
        }
        pthread_join(t, NULL);
        assert_int_equal(c.n, cb);
        assert_int_equal(obsd_fp_finished(&fp), OBS_OK);
        assert_float_equal(fp.ms_queue, 2.0, 1e-9);
        assert_float_equal(fp.ms_gl, 3.0, 1e-9);
        obsd_fp_images im;
        obsd_fp_images_of(&fp, OBS_OUTPUT_AO, &im);
        assert_ptr_equal(im.ao, &fp.job.result.ao);
        assert_null(im.composite);
        assert_false(im.deep);
        obsd_fp_free(&fp);
    }

    /* a full queue is refused, not waited on */
    obsd_fp a, b;
    obsd_fp_init(&a);
    obsd_fp_init(&b);
    obsd_fp_use(&a, &gb, NULL);
    obsd_fp_use(&b, &gb, NULL);
    assert_int_equal(obsd_fp_queue(&a, &q, &params, OBS_OUTPUT_AO, NULL, NULL), 0);
    assert_int_equal(obsd_fp_queue(&b, &q, &params, OBS_OUTPUT_AO, NULL, NULL), -1);
    obsd_fp_free(&b);
    obsd_fp_free(&a);
    obsd_queue_destroy(&q);
}

static void test_images_of_deep(void **state)
{
    (void)state;
    obs_deep_image deep = {.width = 2, .height = 2};
    obsd_fp fp;
    obsd_fp_images im;
    obsd_fp_init(&fp);
    obsd_fp_use(&fp, NULL, &deep);
    fp.job.deep = &deep;
    obsd_fp_images_of(&fp, OBS_OUTPUT_AO, &im);
    assert_true(im.deep);
    assert_ptr_equal(im.ao, &fp.job.deep_result.ao_blend);
    assert_ptr_equal(im.ao_front, &fp.job.deep_result.ao_front);
    assert_null(im.composite);
    assert_ptr_equal(obsd_fp_png_image(&im), im.ao);
    obsd_fp_images_of(&fp, OBS_OUTPUT_COMPOSITE, &im);
    assert_null(im.ao);
    assert_null(im.ao_front);
    assert_ptr_equal(im.composite, &fp.job.deep_result.composite);
    assert_ptr_equal(obsd_fp_png_image(&im), im.composite);
    obsd_fp_free(&fp);
}

static void test_encode(void **state)
{
    (void)state;
    float ao_px[4] = {0, 0.25f, 0.5f, 1}, rgba_px[16] = {0};
    obs_image ao = {2, 2, 1, ao_px}, rgba = {2, 2, 4, rgba_px};
    obsd_fp_images im = {.ao = &ao, .composite = &rgba};
    obs_http_request hr;
    obs_bytes out;
    char err[OBS_ERR_LEN] = "";
    obsd_fp fp;
    obsd_fp_init(&fp);
    obs_http_request_init(&hr);

    assert_int_equal(obsd_fp_encode(&fp, &im, &hr, 0, NULL, &out, err), OBS_OK);
    assert_true(out.size > 4 && !memcmp(out.data, "\x76\x2f\x31\x01", 4)); /* EXR magic */
    assert_true(fp.ms_encode >= 0.0);
    obs_bytes_free(&out);

    hr.format = OBS_HTTP_PNG;
    im.ao = NULL;
    assert_int_equal(obsd_fp_encode(&fp, &im, &hr, 0, NULL, &out, err), OBS_OK);
    assert_true(out.size > 8 && !memcmp(out.data, "\x89PNG", 4));
    obs_bytes_free(&out);

    assert_int_equal(obsd_fp_encode(&fp, &im, &hr, 1, NULL, &out, err), OBS_OK); /* raw: nothing written */
    assert_null(out.data);
    assert_int_equal(out.size, 0);
    obsd_fp_free(&fp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_decode),
        cmocka_unit_test(test_queue_wait_and_callback),
        cmocka_unit_test(test_images_of_deep),
        cmocka_unit_test(test_encode),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
