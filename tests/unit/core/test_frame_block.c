/* The frame's uniform block: the C mirror (obs__frame_block, frame.h)
 * places every member where GL's std140 layout of common.glsl's Frame
 * block puts it (offsets, array and matrix strides, row-major matrices,
 * the block's size, as the program reports them), and obs__frame_block_fill
 * copies each value of the frame. */
#include "gl_testutil.h"

#include "chain/frame_gl.h"
#include "methods/methods.h"
#include "obs_shaders.h"

static const struct member {
    const char *name; /* as GL names it: arrays by their first element */
    size_t offset;
    int array_stride, matrix_stride, row_major;
} members[] = {
#define M(name, field, as, ms, rm) {name, offsetof(obs__frame_block, field), as, ms, rm}
    M("u_proj", proj, 0, 16, 1),
    M("u_viewport", viewport, 0, 0, 0),
    M("u_normal_matrix", normal_matrix, 0, 16, 1),
    M("u_size", size, 0, 0, 0),
    M("u_cull_size", cull_size, 0, 0, 0),
    M("u_radius", radius, 0, 0, 0),
    M("u_range_u", range_u, 0, 0, 0),
    M("u_range_normal", range_normal, 0, 0, 0),
    M("u_count", count, 0, 0, 0),
    M("u_adaptive_k", adaptive_k, 0, 0, 0),
    M("u_culling", culling, 0, 0, 0),
    M("u_cull_threshold", cull_threshold, 0, 0, 0),
    M("u_bleed_step", bleed_step, 0, 0, 0),
    M("u_luminance", luminance, 0, 0, 0),
    M("u_lum_threshold", lum_threshold, 0, 0, 0),
    M("u_lum_width", lum_width, 0, 0, 0),
    M("u_lum_sigma", lum_sigma, 0, 0, 0),
    M("u_rot[0]", rot, 16, 0, 0),
    M("u_samples[0]", samples, 16, 0, 0),
    M("u_blur_w[0]", blur_w, 16, 0, 0),
#undef M
};

static void test_layout_matches_gl(void **state)
{
    (void)state;
    obs_ctx *ctx = make_ctx(OBS_BACKEND_AUTO);
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs__ctx_bind(ctx, err), OBS_OK);
    static const char main_src[] = "out vec4 o;\nvoid main() { o = vec4(u_proj[0][0]); }\n";
    const char *frag[] = {"#version 430 core\n", obs__shader_common, main_src};
    GLuint prog = 0;
    if (obs__gl_program("frame block", obs__shader_fullscreen_vert, frag, 3, &prog, err) != OBS_OK)
        fail_msg("%s", err);

    int checked = 0;
    for (size_t i = 0; i < sizeof members / sizeof members[0]; i++) {
        const struct member *m = &members[i];
        GLuint idx = glGetProgramResourceIndex(prog, GL_UNIFORM, m->name);
        if (idx == GL_INVALID_INDEX)
            fail_msg("%s is not a member of the Frame block", m->name);
        const GLenum props[] = {GL_OFFSET, GL_ARRAY_STRIDE, GL_MATRIX_STRIDE, GL_IS_ROW_MAJOR,
                                GL_BLOCK_INDEX};
        GLint v[5] = {0};
        glGetProgramResourceiv(prog, GL_UNIFORM, idx, 5, props, 5, NULL, v);
        if ((size_t)v[0] != m->offset)
            fail_msg("%s: GL offset %d, C offset %zu", m->name, v[0], m->offset);
        assert_int_equal(v[1], m->array_stride);
        assert_int_equal(v[2], m->matrix_stride);
        assert_int_equal(v[3], m->row_major);
        assert_true(v[4] >= 0); /* in a block, not a plain uniform */
        checked++;
    }
    /* every member of the block is in the table above */
    GLuint block = glGetProgramResourceIndex(prog, GL_UNIFORM_BLOCK, "Frame");
    assert_int_not_equal(block, GL_INVALID_INDEX);
    const GLenum bprops[] = {GL_NUM_ACTIVE_VARIABLES, GL_BUFFER_DATA_SIZE, GL_BUFFER_BINDING};
    GLint bv[3] = {0};
    glGetProgramResourceiv(prog, GL_UNIFORM_BLOCK, block, 3, bprops, 3, NULL, bv);
    assert_int_equal(bv[0], checked);
    assert_int_equal((size_t)bv[1], sizeof(obs__frame_block));
    assert_int_equal(bv[2], OBS__FRAME_BINDING);
    print_message("Frame block: %d members, %d bytes, offsets as in obs__frame_block\n", bv[0],
                  bv[1]);
    glDeleteProgram(prog);
    obs_ctx_destroy(ctx);
}

static void test_fill_copies_the_frame(void **state)
{
    (void)state;
    obs_gbuffer_file gf;
    load(scenes[0], &gf);
    obs_params p = {0};
    char err[OBS_ERR_LEN] = "";
    assert_int_equal(obs_param_set(&p, "luminance", "lum", err), OBS_OK);
    obs_params r;
    obs_params_resolve(&p, &r);
    obs__frame f;
    assert_int_equal(obs__frame_setup(NULL, &gf.gb, &r, &f, err), OBS_OK);
    obs__frame_block b;
    obs__frame_block_fill(&f, &b);
    assert_memory_equal(b.proj, f.proj, sizeof b.proj);
    assert_memory_equal(b.viewport, f.viewport, sizeof b.viewport);
    for (int k = 0; k < 9; k++)
        assert_true(b.normal_matrix[k / 3][k % 3] == f.normal_matrix[k]);
    assert_int_equal(b.size[0], f.width);
    assert_int_equal(b.size[1], f.height);
    assert_int_equal(b.cull_size[0], f.cull_w);
    assert_int_equal(b.count, f.samples);
    assert_true(b.radius == f.radius && b.range_u == f.range_u && b.adaptive_k == f.adaptive_k);
    assert_true(b.cull_threshold == f.cull_threshold && b.lum_sigma == f.lum_sigma);
    assert_int_equal(b.luminance, f.luminance);
    for (int k = 0; k < OBS_SAMPLE_TABLE_LEN; k++)
        assert_true(b.samples[k][0] == f.sample_table[2 * k] &&
                    b.samples[k][1] == f.sample_table[2 * k + 1]);
    for (int k = 0; k <= f.blur_radius; k++)
        assert_true(b.blur_w[k][0] == f.blur_w[k]);
    assert_true(b.rot[8][1] == f.rot[8][1]);
    obs_gbuffer_free(&gf);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_layout_matches_gl),
        cmocka_unit_test(test_fill_copies_the_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
