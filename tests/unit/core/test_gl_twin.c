/* The GL passes against their CPU twin on real input, resource reuse
 * across frames, shader failures, bad input.  (EGL against OSMesa:
 * test_backends.c.) */
#include "gl_testutil.h"

#include "context.h"
#include "chain/passes_gl.h"
#include "methods/methods.h"

/* GL and CPU do the same float arithmetic, but a sample that lands within
 * rounding of a pixel border may read the neighbouring pixel's depth on
 * one side and not the other, changing that pixel's AO by up to one
 * sample's weight (~1/n).  So: the mean difference is tiny and few pixels
 * differ at all (bounds: mean < 1e-3, fewer than 2 % of pixels > 1e-3). */
/* One frame through GL and through the CPU twin, compared as above. */
static void check_twin(obs_ctx *ctx, const obs_gbuffer *gb, const obs_params *p, const char *scene,
                       const char *label)
{
    unsigned out = OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE | OBS_OUTPUT_SAMPLE_COUNT |
                   OBS_OUTPUT_CULL_MASK | OBS_OUTPUT_BLEED;
    obs_result gl, cpu;
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_run(ctx, gb, p, out, &gl, err), OBS_OK);
    assert_int_equal(obs_run_cpu(gb, p, out, &cpu, err), OBS_OK);
    double mean, frac, cmean, cfrac, nmean, nfrac;
    diff(&gl.ao, &cpu.ao, &mean, &frac);
    diff(&gl.composite, &cpu.composite, &cmean, &cfrac);
    /* the sample count (section 4.1) compares the disk's area with powers
     * of two: only a pixel within rounding of one may differ */
    diff(&gl.sample_count, &cpu.sample_count, &nmean, &nfrac);
    /* the culling mask (section 4.2): the pre-pass is the same estimator at
     * the same pixels, and the C bilinear fetch reproduces llvmpipe's
     * GL_LINEAR bit for bit (fma form, see cull_cpu.c), so only a pre-pass
     * texel hit by the border rounding above could move a decision */
    double mmean, mfrac;
    diff(&gl.cull_mask, &cpu.cull_mask, &mmean, &mfrac);
    /* the bleed term (section 4.7): the same samples, so the same border
     * rounding as the AO */
    double bmean, bfrac;
    diff(&gl.bleed, &cpu.bleed, &bmean, &bfrac);
    print_message("%s (%s): GL vs CPU AO: mean |diff| %.2e, %.3f %% of pixels > 1e-3; "
                  "composite mean %.2e; sample counts differ at %.3f %% of pixels, "
                  "culling mask at %.3f %%; bleed mean %.2e, %.3f %% > 1e-3\n",
                  scene, label, mean, 100 * frac, cmean, 100 * nfrac, 100 * mfrac, bmean,
                  100 * bfrac);
    assert_true(mean < 1e-3);
    assert_true(frac < 0.02);
    assert_true(cmean < 1e-3);
    assert_true(nfrac < 1e-3);
    assert_true(mfrac < 1e-3);
    assert_true(bmean < 1e-3);
    assert_true(bfrac < 0.02);
    obs_result_free(&gl);
    obs_result_free(&cpu);
}

/* The depth modes other than planar (the prep pass has a program per
 * mode): the scene's planar depths rewritten as distances from the camera,
 * as OpenGL depth-buffer values, as 1/Z and normalized over the clip range
 * give GL = CPU, and the AO of the planar depths (the same points; ndc,
 * inverse and normalized within float rounding). */
static void check_depth_modes(obs_ctx *ctx, const obs_gbuffer *gb, const char *scene)
{
    char err[OBS_ERR_LEN] = "";
    obs_params planar = {0}, resolved;
    obs_params_resolve(&planar, &resolved);
    obs__frame f;
    assert_int_equal(obs__frame_setup(NULL, gb, &resolved, &f, err), OBS_OK);
    const float *P = f.proj;
    float *radial = malloc((size_t)gb->width * gb->height * sizeof *radial);
    float *ndc = malloc((size_t)gb->width * gb->height * sizeof *ndc);
    float *inv = malloc((size_t)gb->width * gb->height * sizeof *inv);
    float *nrm = malloc((size_t)gb->width * gb->height * sizeof *nrm);
    assert_non_null(radial);
    assert_non_null(ndc);
    assert_non_null(inv);
    assert_non_null(nrm);
    /* the clip range of the projection's z row (normalized depth's) */
    double cn = (P[15] + P[11]) / (P[10] + P[14]), cf = (P[11] - P[15]) / (P[10] - P[14]);
    for (int y = 0; y < gb->height; y++)
        for (int x = 0; x < gb->width; x++) {
            float v[4];
            obs__prep_position(&f, *obs__plane_px(&gb->depth, gb->width, x, y), x, y, v);
            size_t i = (size_t)y * gb->width + x;
            radial[i] = sqrtf(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            float zn = (P[10] * v[2] + P[11]) / (P[14] * v[2] + P[15]);
            ndc[i] = v[3] > 0.0f ? 0.5f * zn + 0.5f : 1.0f; /* background: far plane */
            inv[i] = v[3] > 0.0f ? 1.0f / v[3] : 0.0f;        /* background: 1/inf */
            nrm[i] = v[3] > 0.0f ? (float)((v[3] - cn) / (cf - cn)) : 1.0f;
        }
    obs_result ref;
    assert_int_equal(obs_run(ctx, gb, &planar, OBS_OUTPUT_AO, &ref, err), OBS_OK);
    static const char *const modes[] = {"radial", "ndc", "inverse", "normalized"};
    float *const planes[] = {radial, ndc, inv, nrm};
    for (int m = 0; m < 4; m++) {
        obs_gbuffer g = *gb;
        g.depth.data = planes[m];
        g.depth.channels = 1;
        g.depth.row_stride = (size_t)gb->width * sizeof(float);
        obs_params p = {0};
        assert_int_equal(obs_param_set(&p, "depth_mode", modes[m], err), OBS_OK);
        char label[32];
        snprintf(label, sizeof label, "depth_mode %s", modes[m]);
        check_twin(ctx, &g, &p, scene, label);
        obs_result r;
        double mean, frac;
        assert_int_equal(obs_run(ctx, &g, &p, OBS_OUTPUT_AO, &r, err), OBS_OK);
        diff(&r.ao, &ref.ao, &mean, &frac);
        print_message("%s: depth_mode %s vs planar: mean |diff| %.2e, %.3f %% > 1e-3\n", scene,
                      modes[m], mean, 100 * frac);
        assert_true(mean < 1e-3);
        assert_true(frac < 0.02);
        obs_result_free(&r);
    }
    obs_result_free(&ref);
    free(radial);
    free(ndc);
    free(inv);
    free(nrm);
}

static void test_gl_matches_cpu(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_EGL_SURFACELESS);
    (void)state;
    for (size_t s = 0; s < sizeof scenes / sizeof scenes[0]; s++) {
        obs_gbuffer_file gf = {0};
        char err[OBS_ERR_LEN] = "";
        load(scenes[s], &gf);
        /* the defaults (range check, 5-tap blur, adaptive sampling on,
         * ao_definition rays), then the paper's volume fraction without
         * and with luminance sensitivity, then a wide blur with the range check off, then no blur, then
         * adaptive sampling with a diameter that spreads the counts over
         * 2..32, then a fixed count, then the greedy culling pre-pass
         * (section 4.2; the defaults use careful) and none, then
         * luminance sensitivity (section 4.3) with luminance and with
         * HSV V, then colour bleeding (section 4.7) with every sample and
         * every fourth, the latter with luminance sensitivity too */
        static const char *const variants[][2][2] = {
            {{NULL, NULL}, {NULL, NULL}},
            {{"ao_definition", "volume"}, {NULL, NULL}},
            {{"ao_definition", "volume"}, {"luminance", "lum"}},
            {{"blur", "off"}, {"luminance", "value"}},
            {{"blur_radius", "7"}, {"range_check", "off"}},
            {{"range_distance", "view"}, {"blur", "off"}},
            {{"blur", "off"}, {NULL, NULL}},
            {{"adaptive_diameter", "0.04"}, {"samples", "32"}},
            {{"adaptive", "off"}, {NULL, NULL}},
            {{"culling", "greedy"}, {"blur", "off"}},
            {{"culling", "off"}, {NULL, NULL}},
            {{"luminance", "lum"}, {"lum_sigma", "2"}},
            {{"luminance", "value"}, {"lum_threshold", "0.3"}},
            {{"bleeding", "full"}, {NULL, NULL}},
            {{"bleeding", "quarter"}, {"luminance", "lum"}},
        };
        for (size_t v = 0; v < sizeof variants / sizeof variants[0]; v++) {
            obs_params p = {0};
            char label[64];
            for (int k = 0; k < 2; k++)
                if (variants[v][k][0])
                    assert_int_equal(obs_param_set(&p, variants[v][k][0], variants[v][k][1], err),
                                     OBS_OK);
            snprintf(label, sizeof label, "%s %s",
                     variants[v][0][0] ? variants[v][0][0] : "defaults",
                     variants[v][0][1] ? variants[v][0][1] : "");
            check_twin(ctx, &gf.gb, &p, scenes[s], label);
        }
        /* without a normal plane: normals derived from depth (the prep
         * pass's other program) */
        obs_gbuffer nonormals = gf.gb;
        nonormals.normal.data = NULL;
        obs_params p = {0};
        check_twin(ctx, &nonormals, &p, scenes[s], "normals from depth");
        check_depth_modes(ctx, &gf.gb, scenes[s]);
        obs_gbuffer_free(&gf);
    }
    obs_ctx_destroy(ctx);
}

/* Frames of one size reuse textures and framebuffers; a new size
 * allocates once more; results do not depend on what ran before. */
static void test_resources_reused(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    obs_gbuffer_file room = {0}, yard = {0};
    obs_result a, b;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    load(scenes[0], &room);
    load(scenes[1], &yard);
    assert_int_equal(obs_run(ctx, &room.gb, NULL, OBS_OUTPUT_AO, &a, err), OBS_OK);
    unsigned long after_first = ctx->gl_objects_created;
    assert_true(after_first > 0);
    obs_result_free(&a);
    assert_int_equal(obs_run(ctx, &yard.gb, NULL, OBS_OUTPUT_AO, &a, err), OBS_OK);
    assert_int_equal(ctx->gl_objects_created, after_first); /* same size: nothing new */
    assert_int_equal(obs_run(ctx, &room.gb, NULL, OBS_OUTPUT_AO, &b, err), OBS_OK);
    obs_result_free(&b);

    /* a smaller frame: one new set of targets */
    obs_gbuffer half = room.gb;
    half.width = room.gb.width / 2;
    half.height = room.gb.height / 2;
    half.display_width = room.gb.width;
    half.display_height = room.gb.height;
    half.depth.row_stride = (size_t)room.gb.width * sizeof(float);
    half.normal.row_stride = (size_t)room.gb.width * 3 * sizeof(float);
    half.color.row_stride = (size_t)room.gb.width * 4 * sizeof(float);
    assert_int_equal(obs_run(ctx, &half, NULL, OBS_OUTPUT_AO, &b, err), OBS_OK);
    assert_int_equal(ctx->gl_objects_created, 2 * after_first);
    /* the top-left quarter as a sub-window gives the same AO as the CPU
     * twin on the same sub-window (strides and display offsets honoured) */
    obs_result c;
    assert_int_equal(obs_run_cpu(&half, NULL, OBS_OUTPUT_AO, &c, err), OBS_OK);
    double mean, frac;
    diff(&b.ao, &c.ao, &mean, &frac);
    assert_true(mean < 1e-3);
    obs_result_free(&b);
    obs_result_free(&c);

    /* the yard frame again: identical to its first run */
    assert_int_equal(obs_run(ctx, &yard.gb, NULL, OBS_OUTPUT_AO, &b, err), OBS_OK);
    assert_memory_equal(a.ao.data, b.ao.data, sizeof(float) * a.ao.width * a.ao.height);
    obs_result_free(&a);
    obs_result_free(&b);
    obs_gbuffer_free(&room);
    obs_gbuffer_free(&yard);
    obs_ctx_destroy(ctx);
}

/* Per-pass timings: each pass that ran has a time, the others -1; no
 * times before a timed frame or with timing off.  (Times are read, never
 * bounded: speed is measured by make bench.) */
static void test_pass_times(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    obs_gbuffer_file gf = {0};
    obs_pass_times t;
    obs_result r;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    load(scenes[0], &gf);
    assert_int_equal(obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &r, err), OBS_OK);
    obs_result_free(&r);
    assert_false(obs_ctx_last_times(ctx, &t));
    assert_int_equal(obs_ctx_set_timing(ctx, 1, err), OBS_OK);
    obs_params p = {0};
    assert_int_equal(obs_param_set(&p, "culling", "off", err), OBS_OK);
    assert_int_equal(obs_param_set(&p, "ao_definition", "volume", err), OBS_OK);
    assert_int_equal(obs_run(ctx, &gf.gb, &p, OBS_OUTPUT_AO | OBS_OUTPUT_COMPOSITE, &r, err),
                     OBS_OK);
    obs_result_free(&r);
    assert_true(obs_ctx_last_times(ctx, &t));
    double sum = 0.0;
    for (int k = 0; k < OBS_PASS_COUNT; k++) {
        print_message("%-10s %8.3f ms\n", obs_pass_name((obs_pass)k), t.ms[k]);
        if (t.ms[k] >= 0.0)
            sum += t.ms[k];
    }
    assert_true(t.ms[OBS_PASS_CULL] == -1.0);      /* culling off */
    assert_true(t.ms[OBS_PASS_FINISH] == -1.0); /* no conversion, luminance off */
    assert_true(t.ms[OBS_PASS_AO] > 0.0);
    assert_true(t.ms[OBS_PASS_PREP] >= 0.0 && t.ms[OBS_PASS_BLUR] >= 0.0 &&
                t.ms[OBS_PASS_COMPOSITE] >= 0.0 && t.ms[OBS_PASS_READBACK] >= 0.0);
    assert_true(fabs(sum - t.total_ms) < 1e-9);
    /* the default chain runs the culling pre-pass */
    assert_int_equal(obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &r, err), OBS_OK);
    obs_result_free(&r);
    assert_true(obs_ctx_last_times(ctx, &t));
    assert_true(t.ms[OBS_PASS_CULL] >= 0.0 && t.ms[OBS_PASS_COMPOSITE] == -1.0);
    /* ao_definition rays' conversion is done by the blur's vertical pass */
    assert_true(t.ms[OBS_PASS_FINISH] == -1.0);
    /* without the blur, by the finishing pass */
    p = (obs_params){0};
    assert_int_equal(obs_param_set(&p, "blur", "off", err), OBS_OK);
    assert_int_equal(obs_run(ctx, &gf.gb, &p, OBS_OUTPUT_AO, &r, err), OBS_OK);
    obs_result_free(&r);
    assert_true(obs_ctx_last_times(ctx, &t));
    assert_true(t.ms[OBS_PASS_FINISH] >= 0.0 && t.ms[OBS_PASS_BLUR] == -1.0);
    assert_int_equal(obs_ctx_set_timing(ctx, 0, err), OBS_OK);
    assert_false(obs_ctx_last_times(ctx, &t));
    assert_string_equal(obs_pass_name(OBS_PASS_COUNT), "unknown");
    obs_gbuffer_free(&gf);
    obs_ctx_destroy(ctx);
}

/* A shader that does not compile is a status carrying the info log. */
static void test_shader_failure_is_a_status(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    char err[OBS_ERR_LEN] = "";
    GLuint prog = 0;
    (void)state;
    assert_int_equal(obs__ctx_bind(ctx, err), OBS_OK);
    const char *vert = "#version 430 core\nvoid main() { gl_Position = vec4(0.0); }\n";
    const char *frag[] = {"#version 430 core\nout vec4 o;\nvoid main() { o = undefined_thing; }\n"};
    assert_int_equal(obs__gl_program("broken", vert, frag, 1, &prog, err), OBS_GL_SHADER);
    print_message("shader failure: %s\n", err);
    assert_non_null(strstr(err, "broken"));
    assert_non_null(strstr(err, "undefined_thing"));
    assert_int_equal(prog, 0);
    obs_ctx_destroy(ctx);
}

/* Bad G-buffers and parameters are refused before any GL work. */
static void test_bad_input(void **state)
{
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    obs_gbuffer_file gf = {0};
    obs_result r;
    char err[OBS_ERR_LEN] = "";
    (void)state;
    load(scenes[0], &gf);

    obs_gbuffer g = gf.gb;
    g.depth.data = NULL;
    assert_int_equal(obs_run(ctx, &g, NULL, OBS_OUTPUT_AO, &r, err), OBS_MISSING_CHANNEL);
    assert_non_null(strstr(err, "depth"));
    g = gf.gb;
    g.normal.channels = 4;
    assert_int_equal(obs_run(ctx, &g, NULL, OBS_OUTPUT_AO, &r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "normal"));
    g = gf.gb;
    g.width = 0;
    assert_int_equal(obs_run(ctx, &g, NULL, OBS_OUTPUT_AO, &r, err), OBS_BAD_FILE);
    g = gf.gb;
    g.width = 20000;
    assert_int_equal(obs_run(ctx, &g, NULL, OBS_OUTPUT_AO, &r, err), OBS_TOO_LARGE);
    g = gf.gb;
    g.depth.row_stride = 4;
    assert_int_equal(obs_run(ctx, &g, NULL, OBS_OUTPUT_AO, &r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "stride"));
    g = gf.gb;
    memset(&g.camera, 0, sizeof g.camera);
    assert_int_equal(obs_run(ctx, &g, NULL, OBS_OUTPUT_AO, &r, err), OBS_NO_CAMERA);
    assert_non_null(strstr(err, "--fov-y"));

    obs_params p;
    obs_params_resolve(NULL, &p);
    p.samples = 33;
    assert_int_equal(obs_run(ctx, &gf.gb, &p, OBS_OUTPUT_AO, &r, err), OBS_INVALID_ARGUMENT);
    assert_non_null(strstr(err, "samples"));
    assert_int_equal(obs_run(ctx, &gf.gb, NULL, 0, &r, err), OBS_INVALID_ARGUMENT);

    /* and the context still works afterwards */
    assert_int_equal(obs_run(ctx, &gf.gb, NULL, OBS_OUTPUT_AO, &r, err), OBS_OK);
    obs_result_free(&r);
    obs_gbuffer_free(&gf);
    obs_ctx_destroy(ctx);
}

/* The GL column has a kernel for every row of the pass table. */
static void test_gl_column(void **state)
{
    (void)state;
    for (int i = 0; i < OBS_PASS_COUNT; i++)
        assert_non_null(obs__gl_kernels[i].run);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gl_matches_cpu),
        cmocka_unit_test(test_resources_reused),
        cmocka_unit_test(test_pass_times),
        cmocka_unit_test(test_shader_failure_is_a_status),
        cmocka_unit_test(test_bad_input),
        cmocka_unit_test(test_gl_column),
    };
    return cmocka_run_group_tests_name("gl_twin", tests, NULL, NULL);
}
