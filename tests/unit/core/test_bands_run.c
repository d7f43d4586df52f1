/* The CPU chain in bands of rows (core/chain/bands_run.c) gives the
 * whole frame's bytes: every method, the chain's variants (half
 * resolution, culling off and greedy, ao_definition volume, luminance
 * and bleeding, every output), bands forced small and chosen from a
 * memory budget, on room_small (and on a stretch of it nearer the camera,
 * whose halo is the whole frame). */
#include "testutil.h"
#include "methods/methods.h"
#include "obscura/io.h"
#include "obscura/obscura.h"
#include "room_fixture.h"


static const unsigned all_outputs = OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE |
                                    OBS_OUTPUT_SAMPLE_COUNT | OBS_OUTPUT_CULL_MASK |
                                    OBS_OUTPUT_BLEED | OBS_OUTPUT_LUMINANCE | OBS_OUTPUT_BENT |
                                    OBS_OUTPUT_MULTIBOUNCE;

static void same_image(const obs_image *a, const obs_image *b, const char *what, const char *how)
{
    assert_int_equal(a->data != NULL, b->data != NULL);
    if (!a->data)
        return;
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    size_t n = (size_t)a->width * (size_t)a->height * (size_t)a->channels;
    for (size_t i = 0; i < n; i++)
        if (memcmp(&a->data[i], &b->data[i], sizeof(float)) != 0)
            fail_msg("%s, %s: pixel %zu (row %zu) differs from the whole frame's: %.9g against %.9g",
                     what, how, i / (size_t)a->channels, i / (size_t)a->channels / (size_t)a->width,
                     (double)b->data[i], (double)a->data[i]);
}

static void count_band(void *user, obs_log_level level, const char *msg)
{
    (void)level;
    if (strncmp(msg, "band ", 5) == 0)
        (*(int *)user)++;
}

static void same_result(const obs_result *a, const obs_result *b, const char *what, const char *how)
{
    same_image(&a->ao, &b->ao, what, how);
    same_image(&a->composite, &b->composite, what, how);
    same_image(&a->sample_count, &b->sample_count, what, how);
    same_image(&a->cull_mask, &b->cull_mask, what, how);
    same_image(&a->bleed, &b->bleed, what, how);
    same_image(&a->luminance, &b->luminance, what, how);
    same_image(&a->bent, &b->bent, what, how);
    same_image(&a->multibounce, &b->multibounce, what, how);
}

/* The frame gb whole, then in bands of 16 and 37 rows and under a budget
 * of a third of its planes: the same bytes, and more than one band. */
static void check_gb(const obs_gbuffer *gb, const char *method, const char *const *set,
                     unsigned outputs)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(&p, "method", method, err), OBS_OK);
    for (int k = 0; set && set[k]; k += 2)
        if (obs_param_set(&p, set[k], set[k + 1], err) != OBS_OK)
            fail_msg("%s=%s: %s", set[k], set[k + 1], err);
    obs_result whole, banded;
    if (obs_run_cpu(gb, &p, outputs, &whole, err) != OBS_OK)
        fail_msg("%s: %s", method, err);
    /* about 56 bytes a pixel of planes: a third of them */
    const size_t third = (size_t)gb->width * (size_t)gb->height * 56 / 3;
    const obs_cpu_options opts[] = {{.band_rows = 16}, {.band_rows = 37}, {.max_memory = third}};
    const char *hows[] = {"bands of 16 rows", "bands of 37 rows", "bands in a budget"};
    for (int k = 0; k < 3; k++) {
        int bands = 0;
        obs_cpu_options o = opts[k];
        o.log = count_band;
        o.log_user = &bands;
        if (obs_run_cpu_opts(gb, &p, outputs, &banded, &o, err) != OBS_OK)
            fail_msg("%s, %s: %s", method, hows[k], err);
        if (bands < 2)
            fail_msg("%s, %s: %d band(s)", method, hows[k], bands);
        same_result(&banded, &whole, method, hows[k]);
        obs_result_free(&banded);
    }
    obs_result_free(&whole);
}

static void check(const char *method, const char *const *set, unsigned outputs)
{
    check_gb(&room.gb, method, set, outputs);
}

static void test_every_method(void **state)
{
    (void)state;
    for (int m = 0; m < obs__method_count(); m++)
        check(obs__method_at(m)->name, NULL, all_outputs);
}

static void test_chain_variants(void **state)
{
    static const char *const half[] = {"ao_resolution", "half", NULL};
    static const char *const half_gtao[] = {"ao_resolution", "half", "luminance", "value", NULL};
    static const char *const greedy[] = {"culling", "greedy", "ao_definition", "volume", NULL};
    static const char *const off[] = {"culling", "off", "adaptive", "off", "blur", "off", NULL};
    static const char *const colour[] = {"luminance", "lum", "bleeding", "half", NULL};
    static const char *const wide[] = {"blur_radius", "8", "radius", "2", NULL};
    (void)state;
    check("vaopp", half, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE | OBS_OUTPUT_LUMINANCE);
    check("gtao", half_gtao, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE);
    check("hbao", half, OBS_OUTPUT_AO);
    check("vaopp", greedy, all_outputs);
    check("vaopp", off, all_outputs);
    check("vaopp", colour, all_outputs);
    check("vaopp", wide, OBS_OUTPUT_AO);
}

/* Depth scaled towards the camera: the AO radius projects to more rows
 * than the frame has (the halo is the whole frame), and the bands still
 * give the whole frame's bytes. */
static void test_near_camera(void **state)
{
    (void)state;
    const size_t n = (size_t)room.gb.width * (size_t)room.gb.height;
    float *depth = malloc(n * sizeof(float));
    assert_non_null(depth);
    for (size_t i = 0; i < n; i++)
        depth[i] = room.gb.depth.data[i * (size_t)room.gb.depth.channels] * 0.25f;
    obs_gbuffer near = room.gb;
    near.depth = (obs_plane){depth, 1, 0};
    check_gb(&near, "vaopp", NULL, OBS_OUTPUT_AO);
    check_gb(&near, "hemisphere", NULL, OBS_OUTPUT_AO);
    free(depth);
}

/* Object masks (receivers, occluders, self_only's object IDs) read at the
 * samples, full and half resolution: the whole frame's bytes in bands. */
static void test_masks(void **state)
{
    static const char *const self[] = {"self_only", "on", NULL};
    static const char *const half[] = {"self_only", "on", "ao_resolution", "half", NULL};
    (void)state;
    const int w = room.gb.width, h = room.gb.height;
    float *planes = malloc(sizeof(float) * 3 * (size_t)w * (size_t)h);
    assert_non_null(planes);
    float *recv = planes, *occl = planes + (size_t)w * h, *id = planes + 2 * (size_t)w * h;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            size_t i = (size_t)y * w + x;
            recv[i] = x < w / 2 ? 1.0f : 0.5f;
            occl[i] = (x / 16 + y / 16) % 2 ? 1.0f : 0.25f;
            id[i] = (float)(x / 40 + 10 * (y / 50));
        }
    obs_gbuffer masked = room.gb;
    masked.receivers = (obs_plane){recv, 1, 0};
    masked.occluders = (obs_plane){occl, 1, 0};
    masked.object_id = (obs_plane){id, 1, 0};
    check_gb(&masked, "vaopp", self, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE);
    check_gb(&masked, "vaopp", half, OBS_OUTPUT_AO);
    check_gb(&masked, "hbao", NULL, OBS_OUTPUT_AO);
    free(planes);
}

/* A frame under OBS__BANDS_MIN_HEIGHT rows, or bands as tall as the
 * frame, run whole (no band said). */
static void test_whole_when_small(void **state)
{
    obs_result r;
    char err[OBS_ERR_LEN] = "";
    int bands = 0;
    (void)state;
    obs_cpu_options o = {.band_rows = room.gb.height, .log = count_band, .log_user = &bands};
    assert_int_equal(obs_run_cpu_opts(&room.gb, NULL, OBS_OUTPUT_AO, &r, &o, err), OBS_OK);
    assert_int_equal(bands, 0);
    obs_result_free(&r);
    obs_gbuffer strip = room.gb;
    strip.height = 40;
    o.band_rows = 16;
    assert_int_equal(obs_run_cpu_opts(&strip, NULL, OBS_OUTPUT_AO, &r, &o, err), OBS_OK);
    assert_int_equal(bands, 0);
    obs_result_free(&r);
}

/* ---- a frame by rows (obs_run_cpu_rows) ---------------------------------- */

typedef struct rows_job {
    const obs_gbuffer *gb; /* the source's frame */
    obs_result whole;      /* the rows handed out, gathered */
    int next;              /* the row the next hand-out must start at */
    int asked;             /* the source's calls */
} rows_job;

static obs_status give_rows(void *user, int y0, int y1, obs_gbuffer *rows, char err[OBS_ERR_LEN])
{
    rows_job *j = user;
    (void)err;
    assert_true(0 <= y0 && y0 < y1 && y1 <= j->gb->height);
    j->asked++;
    *rows = *j->gb;
    const size_t w = (size_t)rows->width;
    rows->depth.data += (size_t)y0 * w * (size_t)rows->depth.channels;
    if (rows->normal.data)
        rows->normal.data += (size_t)y0 * w * 3;
    if (rows->color.data)
        rows->color.data += (size_t)y0 * w * 4;
    return OBS_OK;
}

static obs_status take_rows(void *user, int y0, int y1, const obs_result *rows, char err[OBS_ERR_LEN])
{
    rows_job *j = user;
    (void)err;
    assert_int_equal(y0, j->next);
    j->next = y1;
    const obs_image *from[] = {&rows->ao, &rows->composite, &rows->bent, &rows->multibounce, &rows->luminance};
    obs_image *to[] = {&j->whole.ao, &j->whole.composite, &j->whole.bent, &j->whole.multibounce,
                       &j->whole.luminance};
    for (int i = 0; i < 5; i++) {
        if (!from[i]->data)
            continue;
        assert_int_equal(from[i]->height, y1 - y0);
        size_t row = (size_t)from[i]->width * (size_t)from[i]->channels;
        if (!to[i]->data) {
            *to[i] = *from[i];
            to[i]->height = j->gb->height;
            to[i]->data = calloc(row * (size_t)j->gb->height, sizeof(float));
        }
        memcpy(to[i]->data + (size_t)y0 * row, from[i]->data, (size_t)(y1 - y0) * row * sizeof(float));
    }
    return OBS_OK;
}

/* The frame by rows from memory: the whole frame's bytes, in bands of 16
 * and 37 rows and in a budget, the source asked band by band. */
static void check_rows(const char *method, const char *const *set, unsigned outputs)
{
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(&p, "method", method, err), OBS_OK);
    for (int k = 0; set && set[k]; k += 2)
        assert_int_equal(obs_param_set(&p, set[k], set[k + 1], err), OBS_OK);
    obs_result whole;
    assert_int_equal(obs_run_cpu(&room.gb, &p, outputs, &whole, err), OBS_OK);
    obs_gbuffer frame = room.gb;
    frame.depth.data = frame.normal.data = frame.color.data = NULL; /* the header only */
    const size_t third = (size_t)room.gb.width * (size_t)room.gb.height * 56 / 3;
    const obs_cpu_options opts[] = {{.band_rows = 16}, {.band_rows = 37}, {.max_memory = third}};
    for (int k = 0; k < 3; k++) {
        rows_job j = {&room.gb};
        if (obs_run_cpu_rows(&frame, give_rows, take_rows, &j, &p, outputs, &opts[k], err) != OBS_OK)
            fail_msg("%s by rows: %s", method, err);
        assert_int_equal(j.next, room.gb.height);
        assert_true(j.asked >= 3); /* the depth once, then band by band */
        same_image(&j.whole.ao, &whole.ao, method, "by rows");
        same_image(&j.whole.composite, &whole.composite, method, "by rows");
        same_image(&j.whole.bent, &whole.bent, method, "by rows");
        same_image(&j.whole.multibounce, &whole.multibounce, method, "by rows");
        same_image(&j.whole.luminance, &whole.luminance, method, "by rows");
        obs_result_free(&j.whole);
    }
    obs_result_free(&whole);
}

static void test_by_rows(void **state)
{
    static const char *const half[] = {"ao_resolution", "half", "luminance", "lum", NULL};
    static const char *const mb[] = {"multibounce", "on", NULL};
    (void)state;
    for (int m = 0; m < obs__method_count(); m++)
        check_rows(obs__method_at(m)->name, NULL, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE | OBS_OUTPUT_BENT);
    check_rows("vaopp", half, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE | OBS_OUTPUT_LUMINANCE);
    check_rows("vaopp", mb, OBS_OUTPUT_COMPOSITE | OBS_OUTPUT_MULTIBOUNCE);
}

/* A failing source or sink stops the run with its status; masks are
 * refused. */
static obs_status no_rows(void *user, int y0, int y1, obs_gbuffer *rows, char err[OBS_ERR_LEN])
{
    (void)user, (void)y0, (void)y1, (void)rows;
    return obs_status_fail(err, OBS_IO, "the disk went away");
}

static void test_by_rows_failures(void **state)
{
    char err[OBS_ERR_LEN] = "";
    (void)state;
    obs_gbuffer frame = room.gb;
    frame.depth.data = frame.normal.data = frame.color.data = NULL;
    rows_job j = {&room.gb};
    obs_cpu_options o = {.band_rows = 32};
    assert_int_equal(obs_run_cpu_rows(&frame, no_rows, take_rows, &j, NULL, OBS_OUTPUT_AO, &o, err), OBS_IO);
    assert_non_null(strstr(err, "went away"));
    float w = 1.0f;
    frame.receivers = (obs_plane){&w, 1, 0};
    assert_int_equal(obs_run_cpu_rows(&frame, give_rows, take_rows, &j, NULL, OBS_OUTPUT_AO, &o, err),
                     OBS_UNSUPPORTED);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_method),
        cmocka_unit_test(test_chain_variants),
        cmocka_unit_test(test_near_camera),
        cmocka_unit_test(test_masks),
        cmocka_unit_test(test_whole_when_small),
        cmocka_unit_test(test_by_rows),
        cmocka_unit_test(test_by_rows_failures),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
